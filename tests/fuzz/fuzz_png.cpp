// Fuzz target: the PNG reader (read_png through libspng, and read_png_text) and the texture
// decoder (decode_image: PNG, JPEG and WebP by content). The input is a file's bytes. Any
// answer but an image or an InputError is a finding; an image must have sides in
// 1..kMaxPngSide and exactly 3 (read_png) or 4 (decode_image) bytes per pixel.
#include "fuzz_support.hpp"

#include <covrast/image.hpp>
#include <covrast/tools.hpp>

namespace {

/// Aborts (a finding) unless `what` returned sides in 1..kMaxPngSide and `bytes` bytes of
/// `channels` per pixel.
void check_image(const char* what, int width, int height, std::size_t bytes, int channels) {
  if (width < 1 || height < 1 || width > covrast::kMaxPngSide || height > covrast::kMaxPngSide ||
      bytes != std::size_t(width) * std::size_t(height) * std::size_t(channels)) {
    std::fprintf(stderr, "covrast fuzz: %s returned a %dx%d image of %zu bytes\n", what, width,
                 height, bytes);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path =
      covrast::fuzz::write_scratch("image.png", covrast::fuzz::as_text(data, size));
  covrast::fuzz::expect_input_error_only([&] {
    const covrast::Image image = covrast::read_png(path);
    check_image("read_png", image.width, image.height, image.rgb.size(), 3);
  });
  covrast::fuzz::expect_input_error_only([&] { (void)covrast::read_png_text(path); });
  covrast::fuzz::expect_input_error_only([&] {
    const covrast::RgbaImage image = covrast::decode_image(data, size, "fuzz");
    check_image("decode_image", image.width, image.height, image.rgba.size(), 4);
  });
  return 0;
}
