// Shared layer: the render modes' names (include/covrast/options.hpp), parsed and printed
// here so that every stage that knows a mode can use them without the pipeline.
#include <covrast/error.hpp>
#include <covrast/options.hpp>

#include <charconv>
#include <string>

namespace covrast {

RenderMode parse_render_mode(std::string_view text) {
  auto fail = [&]() -> RenderMode {
    throw InputError("unknown mode '" + std::string(text) +
                     "': expected aliased, coverage, coverage-blend, ssaa:N, ssaa-grid:N or "
                     "ssaa-cmj:N (N = 1.." +
                     std::to_string(kMaxSsaaSide) +
                     "), msaa:K (K = 2, 4, 8, 16), reference or fxaa");
  };
  if (text == "aliased") return {ModeKind::Aliased, 1};
  if (text == "fxaa") return {ModeKind::Fxaa, 1};
  if (text == "coverage") return {ModeKind::Coverage, 1};
  if (text == "coverage-blend") return {ModeKind::CoverageBlend, 1};
  if (text == "reference") return {ModeKind::Reference, 64};
  auto colon = text.find(':');
  if (colon == std::string_view::npos) return fail();
  std::string_view name = text.substr(0, colon), number = text.substr(colon + 1);
  int n = 0;
  auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), n);
  if (ec != std::errc() || end != number.data() + number.size()) return fail();
  if (name == "ssaa" || name == "ssaa-grid" || name == "ssaa-cmj") {
    if (n < 1 || n > kMaxSsaaSide) return fail();
    const ModeKind kind = name == "ssaa"        ? ModeKind::Ssaa
                          : name == "ssaa-grid" ? ModeKind::SsaaGrid
                                                : ModeKind::SsaaCmj;
    return {kind, n};
  }
  if (name == "msaa") {
    if (n != 2 && n != 4 && n != 8 && n != 16) return fail();
    return {ModeKind::Msaa, n};
  }
  return fail();
}

std::string tile_px_rule() {
  return "an integer in " + std::to_string(kMinTilePx) + ".." + std::to_string(kMaxTilePx) +
         " and a multiple of " + std::to_string(kTileStepPx);
}

std::string to_string(const RenderMode& mode) {
  switch (mode.kind) {
    case ModeKind::Aliased:
      return "aliased";
    case ModeKind::Coverage:
      return "coverage";
    case ModeKind::CoverageBlend:
      return "coverage-blend";
    case ModeKind::Ssaa:
      return "ssaa:" + std::to_string(mode.samples);
    case ModeKind::SsaaGrid:
      return "ssaa-grid:" + std::to_string(mode.samples);
    case ModeKind::SsaaCmj:
      return "ssaa-cmj:" + std::to_string(mode.samples);
    case ModeKind::Msaa:
      return "msaa:" + std::to_string(mode.samples);
    case ModeKind::Reference:
      return "reference";
    case ModeKind::Fxaa:
      return "fxaa";
  }
  return "?";
}

}  // namespace covrast
