// Tests: the pictures in docs/images that scripts/make-doc-images.sh renders show what this
// build renders, pixel for pixel (a stale picture in the docs misleads the reader). The
// enlarged crops are checked against the same renders: each crop pixel, enlarged k times
// with nearest-neighbour filtering, is the rendered pixel it came from.
#include <catch2/catch.hpp>

#include <covrast/image.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <cstdint>
#include <filesystem>
#include <string>

namespace {

const std::filesystem::path kSource = COVRAST_SOURCE_DIR;

covrast::Image render_scene(const std::string& scene, const char* mode) {
  covrast::RenderOptions options;
  options.mode = covrast::parse_render_mode(mode);
  return covrast::render(covrast::load_scene(kSource / scene), options).color;
}

/// How many pixels of `crop` differ from `image`'s pixel (x0 + i / k, y0 + j / k).
int crop_mismatches(const covrast::Image& crop, const covrast::Image& image, int x0, int y0,
                    int k) {
  int differ = 0;
  for (int j = 0; j < crop.height; ++j) {
    for (int i = 0; i < crop.width; ++i) {
      const std::uint8_t* a = crop.pixel(i, j);
      const std::uint8_t* b = image.pixel(x0 + i / k, y0 + j / k);
      differ += a[0] != b[0] || a[1] != b[1] || a[2] != b[2];
    }
  }
  return differ;
}

const char* const kRegenerate = "stale: run scripts/make-doc-images.sh";

}  // namespace

TEST_CASE("docs: the pictures show what this build renders", "[docs]") {
  const std::filesystem::path images = kSource / "docs" / "images";
  for (const char* mode : {"aliased", "coverage-blend", "coverage"}) {
    INFO("mode " << mode << " (" << kRegenerate << ")");
    const covrast::Image frame = render_scene("scenes/default.json", mode);
    if (std::string(mode) == "coverage") {
      CHECK(covrast::read_png(images / "default-coverage.png").rgb == frame.rgb);
    }
    // make-doc-images.sh: a 40x30 crop at (196, 236), enlarged 8 times; seams 60x45 at
    // (130, 60), enlarged 6 times.
    const covrast::Image edge = covrast::read_png(images / ("edge-" + std::string(mode) + ".png"));
    REQUIRE(edge.width == 40 * 8);
    REQUIRE(edge.height == 30 * 8);
    CHECK(crop_mismatches(edge, frame, 196, 236, 8) == 0);
    const covrast::Image seams_frame = render_scene("docs/scenes/seams.json", mode);
    const covrast::Image seams =
        covrast::read_png(images / ("seams-" + std::string(mode) + ".png"));
    REQUIRE(seams.width == 60 * 6);
    REQUIRE(seams.height == 45 * 6);
    CHECK(crop_mismatches(seams, seams_frame, 130, 60, 6) == 0);
  }
  INFO(kRegenerate);
  CHECK(covrast::read_png(images / "lit.png").rgb ==
        render_scene("scenes/lit.json", "coverage").rgb);
  CHECK(covrast::read_png(images / "clearcoat.png").rgb ==
        render_scene("docs/scenes/clearcoat.json", "coverage").rgb);
  CHECK(covrast::read_png(images / "sheen.png").rgb ==
        render_scene("docs/scenes/sheen.json", "coverage").rgb);
  CHECK(covrast::read_png(images / "iridescence.png").rgb ==
        render_scene("docs/scenes/iridescence.json", "coverage").rgb);
  CHECK(covrast::read_png(images / "anisotropy.png").rgb ==
        render_scene("docs/scenes/anisotropy.json", "coverage").rgb);
  CHECK(covrast::read_png(images / "transmission.png").rgb ==
        render_scene("docs/scenes/transmission.json", "coverage").rgb);
}
