// Fuzz target: environment map decoding (covrast::decode_environment: Radiance .hdr, OpenEXR,
// PNG/JPEG). The input is a file's bytes. Any answer but a map or an InputError is a finding;
// a map must have sides in 1..kMaxEnvironmentSide, width x height texels, each finite and >= 0.
#include "fuzz_support.hpp"

#include <covrast/environment.hpp>

#include <cmath>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  covrast::fuzz::expect_input_error_only([&] {
    std::vector<std::string> warnings;
    const covrast::EnvironmentMap map =
        covrast::decode_environment(data, size, "environment", &warnings);
    bool good = map.width >= 1 && map.height >= 1 && map.width <= covrast::kMaxEnvironmentSide &&
                map.height <= covrast::kMaxEnvironmentSide &&
                map.radiance_linear.size() == std::size_t(map.width) * std::size_t(map.height);
    for (const glm::vec3& t : map.radiance_linear) {
      for (int c = 0; c < 3; ++c) good = good && std::isfinite(t[c]) && t[c] >= 0.0f;
    }
    if (!good) {
      std::fprintf(stderr, "covrast fuzz: decode_environment returned a bad %dx%d map\n", map.width,
                   map.height);
      std::abort();
    }
  });
  return 0;
}
