// The transparent composite of every mode (docs/transparency.md): the BLEND layers over one
// point (a sample, or a pixel), nearest first, each "over" what lies behind it. The one home
// of its order and its arithmetic; the aliased, sample, reference and coverage modes each
// gather their layers and call these.
//
//   order:  nearer first; at equal depth the lower primitive index (the triangle drawn first)
//           in front: a total order, so the result does not depend on arrival order
//   over:   a = clamp(alpha, 0, 1);  light += T a rgb;  T *= (1 - a) + a filter   (T from 1)
//   result: light + T behind
// per channel: a transmissive layer (KHR_materials_transmission) passes `filter` of what is
// behind its covered part; every other layer's filter is 0, and T stays grey. Behind a
// transmissive layer (alpha > 0) only the opaque scene shows: the layers after it are skipped,
// as the glTF Sample Viewer shows transmission (its transmitted image holds the opaque scene;
// the nearest transmissive surface hides the others), so a double-sided glass shell shows one
// wall, not two.
//
// Double precision, no contraction (docs/numerics.md): the same bits in every mode and build.
#pragma once

#include "core/triangle_setup.hpp"
#include "shading/shading.hpp"

#include <glm/glm.hpp>

#include <algorithm>

namespace covrast::detail {

/// What a layer of alpha `alpha` (in [0, 1]) and filter `filter` passes of what lies behind it:
/// (1 - alpha) + alpha filter, per channel ((1 - alpha) exactly where filter is 0).
inline glm::dvec3 passes(double alpha, const glm::vec3& filter) {
  return glm::dvec3(1.0 - alpha) + alpha * glm::dvec3(filter);
}

/// Whether only the opaque scene shows behind a layer of alpha `alpha` (in [0, 1]).
inline bool ends_layers(const ShadedColor& layer, double alpha) {
  return layer.transmissive && alpha > 0.0;
}

/// The composite's order: whether layer a (depth za) lies in front of layer b (depth zb).
template <class Depth>
inline bool nearer_first(Depth za, const TriangleSetup& a, Depth zb, const TriangleSetup& b) {
  return za < zb || (za == zb && a.primitive < b.primitive);
}

/// Front-to-back "over" of the layers, added nearest first.
struct FrontToBack {
  glm::dvec3 light{0.0};     ///< what the layers added so far show
  glm::dvec3 transmit{1.0};  ///< T: the share of what lies behind them that shows through
  bool opaque_only = false;  ///< a transmissive layer was added: the rest are behind it

  void add(const ShadedColor& layer) {
    if (opaque_only) return;
    const double alpha = std::clamp(layer.alpha, 0.0, 1.0);
    light += transmit * alpha * glm::dvec3(layer.rgb);
    transmit *= passes(alpha, layer.filter);
    opaque_only = ends_layers(layer, alpha);
  }
  /// The layers over `behind`.
  glm::dvec3 over(const glm::dvec3& behind) const { return light + transmit * behind; }
};

}  // namespace covrast::detail
