// The transparent composite of every mode (docs/transparency.md): the BLEND layers over one
// point (a sample, or a pixel), nearest first, each "over" what lies behind it. The one home
// of its order and its arithmetic; the aliased, sample, reference and coverage modes each
// gather their layers and call these.
//
//   order:  nearer first; at equal depth the lower primitive index (the triangle drawn first)
//           in front: a total order, so the result does not depend on arrival order
//   over:   a = clamp(alpha, 0, 1);  light += T a rgb;  T *= 1 - a   (T from 1)
//   result: light + T behind
//
// Double precision, no contraction (docs/numerics.md): the same bits in every mode and build.
#pragma once

#include "core/triangle_setup.hpp"
#include "shading/shading.hpp"

#include <glm/glm.hpp>

#include <algorithm>

namespace covrast::detail {

/// The composite's order: whether layer a (depth za) lies in front of layer b (depth zb).
template <class Depth>
inline bool nearer_first(Depth za, const TriangleSetup& a, Depth zb, const TriangleSetup& b) {
  return za < zb || (za == zb && a.primitive < b.primitive);
}

/// Front-to-back "over" of the layers, added nearest first.
struct FrontToBack {
  glm::dvec3 light{0.0};  ///< what the layers added so far show
  double transmit = 1.0;  ///< T: the share of what lies behind them that shows through

  void add(const ShadedColor& layer) {
    const double alpha = std::clamp(layer.alpha, 0.0, 1.0);
    light += transmit * alpha * glm::dvec3(layer.rgb);
    transmit *= 1.0 - alpha;
  }
  /// The layers over `behind`.
  glm::dvec3 over(const glm::dvec3& behind) const { return light + transmit * behind; }
};

}  // namespace covrast::detail
