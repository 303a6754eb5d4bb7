// Fuzz target: the golden manifest of `covrast test` (cli::load_manifest, src/cli/manifest.cpp).
// The input is a manifest file's bytes. Any answer but a manifest or an InputError is a
// finding; a manifest's cases must have unique, non-empty names and tolerances in range.
#include "fuzz_support.hpp"

#include "cli/manifest.hpp"

#include <set>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path =
      covrast::fuzz::write_scratch("manifest.json", covrast::fuzz::as_text(data, size));
  covrast::fuzz::expect_input_error_only([&] {
    const covrast::cli::Manifest manifest = covrast::cli::load_manifest(path);
    std::set<std::string> names;
    for (const covrast::cli::TestCase& c : manifest.cases) {
      const covrast::cli::Tolerance& t = c.tolerance;
      if (c.name.empty() || !names.insert(c.name).second || t.max_diff < 0 || t.max_diff > 255 ||
          !(t.max_pixels >= 0 && t.max_pixels <= 1) || !(t.max_rmse >= 0 && t.max_rmse <= 1) ||
          c.width < 0 || c.height < 0) {
        std::fprintf(stderr, "covrast fuzz: manifest case '%s' accepted with bad fields\n",
                     c.name.c_str());
        std::abort();
      }
    }
  });
  return 0;
}
