// Fuzz target: the PNG reader (read_png through libspng, and read_png_text) and the texture
// decoder (decode_image: PNG, JPEG and WebP by content). The input is a file's bytes. Any
// answer but an image or an InputError is a finding; an image must have sides in
// 1..kMaxPngSide and exactly 3 (read_png) or 4 (decode_image) bytes per pixel.
#include "fuzz_support.hpp"

#include <covrast/image.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path =
      covrast::fuzz::write_scratch("image.png", covrast::fuzz::as_text(data, size));
  covrast::fuzz::expect_input_error_only([&] {
    const covrast::Image image = covrast::read_png(path);
    if (image.width < 1 || image.height < 1 || image.width > covrast::kMaxPngSide ||
        image.height > covrast::kMaxPngSide ||
        image.rgb.size() != std::size_t(image.width) * std::size_t(image.height) * 3) {
      std::fprintf(stderr, "covrast fuzz: read_png returned a %dx%d image of %zu bytes\n",
                   image.width, image.height, image.rgb.size());
      std::abort();
    }
  });
  covrast::fuzz::expect_input_error_only([&] { (void)covrast::read_png_text(path); });
  covrast::fuzz::expect_input_error_only([&] {
    const covrast::RgbaImage image = covrast::decode_image(data, size, "fuzz");
    if (image.width < 1 || image.height < 1 || image.width > covrast::kMaxPngSide ||
        image.height > covrast::kMaxPngSide ||
        image.rgba.size() != std::size_t(image.width) * std::size_t(image.height) * 4) {
      std::fprintf(stderr, "covrast fuzz: decode_image returned a %dx%d image of %zu bytes\n",
                   image.width, image.height, image.rgba.size());
      std::abort();
    }
  });
  return 0;
}
