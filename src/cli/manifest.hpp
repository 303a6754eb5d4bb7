// `covrast test`: the golden manifest (docs/ci.md): which scenes to render, how, and which
// golden image each must match within which tolerance.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace covrast::cli {

/// How far a render may be from its golden; all zero (the default) means identical pixels.
/// The measures are those of `covrast compare`.
struct Tolerance {
  int max_diff = 0;         ///< largest channel difference [8-bit sRGB units]
  double max_pixels = 0.0;  ///< share of pixels off by more than 1/255, 0..1
  double max_rmse = 0.0;    ///< RMSE in linear light
};

struct TestCase {
  std::string name;             ///< unique in the manifest
  std::filesystem::path scene;  ///< resolved against the manifest's folder
  std::filesystem::path golden;
  std::string mode = "coverage";
  int width = 0;  ///< 0: the scene's size
  int height = 0;
  Tolerance tolerance;
  std::optional<std::string> skip;  ///< the reason, when the case is skipped
};

struct Manifest {
  std::filesystem::path path;
  std::vector<TestCase> cases;  ///< in file order
};

/// Reads and checks a manifest. Throws InputError naming the file, the case (by name or
/// index) and the field for anything malformed: a missing or mistyped field, an unknown key
/// (a typo would otherwise be ignored), a bad mode or size, a tolerance out of range, or a
/// duplicate name.
Manifest load_manifest(const std::filesystem::path& path);

/// Whether `name` matches the shell-style pattern `glob` (*, ?, [...]).
bool name_matches(const std::string& name, const std::string& glob);

/// The cases of shard `index` (1-based) of `count`: the cases sorted by name, every
/// count-th from the index-th, so that the shards together hold every case exactly once,
/// whatever order the manifest lists them in.
std::vector<const TestCase*> shard_cases(const std::vector<const TestCase*>& cases, int index,
                                         int count);

}  // namespace covrast::cli
