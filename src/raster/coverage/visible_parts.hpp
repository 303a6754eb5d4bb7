// Raster stage, coverage mode: the exact visible area of each fragment of one pixel, by
// polygon clipping, for the list's `clipped` resolve (abuffer_resolve.cpp).
//
// Fragment i's visible part is its part of the pixel square less, for every other fragment j
// (and the opaque surface, which covers the whole pixel), the part of j that lies in front of
// i: H_ij = (j's part) ∩ {z_j < z_i}. Both planes are affine, so {z_j < z_i} is a half-plane
// and H_ij is convex (at most four lines: j's three edges and the line where the planes
// meet). Removing a convex set from a convex piece leaves at most one convex piece outside
// each of its lines: cut the piece along each line in turn, keep what lies outside, go on
// with what lies inside, and drop the rest at the end (the hidden part). This is Catmull's
// per-pixel hidden-surface clipping ("A hidden-surface algorithm with anti-aliasing",
// SIGGRAPH 1978) on convex pieces. Equal depth keeps the earlier primitive, as everywhere
// else: identical planes give the whole overlap to the earlier one; planes that meet only
// on a line split there, and the line has no area.
//
// Contract: the areas are the exact areas of the visible parts up to double rounding
// (relative 1e-12); their sum is at most the pixel, plus that rounding. The plane
// difference z_i - z_j is evaluated in pixel-local coordinates from coefficients that are
// exact negations of those of z_j - z_i, so two fragments never both claim a point of
// their overlap that is off the line where they meet. A pixel whose pieces would exceed
// kMaxVisiblePieces per fragment, or a piece 16 vertices, returns false: the caller resolves it
// by samples instead, as does a pixel with a plane that is not finite.
#pragma once

#include "core/triangle_setup.hpp"

namespace covrast::detail {

/// Pieces a fragment's visible part may be cut into before the caller falls back to samples.
inline constexpr int kMaxVisiblePieces = 24;
/// The most fragments a pixel resolved this way may have (the pixel log's limit).
inline constexpr int kMaxVisibleFragments = 64;

/// area[i] = the area [pixels] of the part of fragment tri[i] in pixel (x, y) that no other
/// fragment of the pixel and not the opaque surface (null: none) lies in front of; n <=
/// kMaxVisibleFragments. False when the pixel is too complex for the bounds above or a plane is
/// not finite (area is then unspecified).
bool visible_areas(int n, const TriangleSetup* const* tri, const TriangleSetup* opaque, int x,
                   int y, double* area);

}  // namespace covrast::detail
