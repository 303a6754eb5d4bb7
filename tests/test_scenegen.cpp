// Tests for covrast-scenegen (scenes/generate.cpp): the committed scenes in scenes/ are exactly
// the generator's output, and the meshes have the properties the scenes rely on (sphere5k.obj
// has 5,000 triangles; the spheres and the box are closed and consistently wound outwards).
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "test_tempdir.hpp"

namespace {

namespace fs = std::filesystem;

const fs::path kScenesDir = fs::path(COVRAST_SOURCE_DIR) / "scenes";

/// Every file the generator writes with no --only.
const std::set<std::string> kGeneratedFiles = {
    "default.json",     "sphere_closed.json", "boxes.json", "slivers.json", "near_plane.json",
    "sphere_grid.json", "overlap.json",       "sphere.obj", "sphere5k.obj", "fan.obj",
    "box.obj",          "big_tri.obj",        "tri.obj",    "sphere_uv.obj"};

/// A temporary directory of this file's tests.
class TempDir : public covrast::test::TempDir {
 public:
  TempDir() : covrast::test::TempDir("covrast-test-scenegen") {}
};

/// Runs the generator with the given arguments after OUT_DIR; returns std::system's status.
int run_scenegen(const fs::path& out_dir, const std::string& extra_args = "") {
  const std::string command = std::string("\"") + COVRAST_SCENEGEN_PATH + "\" \"" +
                              out_dir.string() + "\" " + extra_args + " >/dev/null 2>&1";
  return std::system(command.c_str());
}

std::set<std::string> file_names_in(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.insert(entry.path().filename());
  return names;
}

std::string read_bytes(const fs::path& path) {
  std::ifstream stream(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>()};
}

struct ObjMesh {
  std::vector<std::array<double, 3>> positions;
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< 0-based
};

/// Minimal OBJ reader for the generator's output: "v x y z [r g b]" and "f a b c" (1-based).
/// Throws std::runtime_error naming the file and line on anything else, which fails the test.
ObjMesh parse_obj(const fs::path& path) {
  ObjMesh mesh;
  std::istringstream lines(read_bytes(path));
  std::string line;
  int line_number = 0;
  const auto malformed = [&path, &line_number](const char* problem) {
    return std::runtime_error(path.string() + ":" + std::to_string(line_number) + ": " + problem);
  };
  while (std::getline(lines, line)) {
    ++line_number;
    std::istringstream fields(line);
    std::string tag;
    fields >> tag;
    if (tag == "v") {
      std::array<double, 3> p{};
      if (!(fields >> p[0] >> p[1] >> p[2])) throw malformed("bad vertex");
      mesh.positions.push_back(p);
    } else if (tag == "f") {
      std::array<std::uint32_t, 3> t{};
      std::string extra;
      if (!(fields >> t[0] >> t[1] >> t[2]) || fields >> extra) throw malformed("not a triangle");
      for (auto& index : t) {
        if (index < 1 || index > mesh.positions.size()) throw malformed("index out of range");
        --index;
      }
      mesh.triangles.push_back(t);
    }
  }
  return mesh;
}

/// True iff every undirected edge is used by exactly two triangles, once in each direction
/// (a closed, consistently wound, manifold-edged mesh), and no triangle repeats a vertex.
bool is_closed_and_consistently_wound(const ObjMesh& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed_uses;
  for (const auto& t : mesh.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) return false;
    for (int k = 0; k < 3; ++k) ++directed_uses[{t[k], t[(k + 1) % 3]}];
  }
  for (const auto& [edge, uses] : directed_uses) {
    if (uses != 1) return false;
    const auto reverse = directed_uses.find({edge.second, edge.first});
    if (reverse == directed_uses.end() || reverse->second != 1) return false;
  }
  return true;
}

/// Signed volume sum(det(a, b, c)) / 6: positive iff a closed mesh is wound counter-clockwise
/// seen from outside (outward normals).
double signed_volume(const ObjMesh& mesh) {
  double six_volume = 0.0;
  for (const auto& t : mesh.triangles) {
    const auto& a = mesh.positions[t[0]];
    const auto& b = mesh.positions[t[1]];
    const auto& c = mesh.positions[t[2]];
    six_volume += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                  a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return six_volume / 6.0;
}

int count_f_lines(const fs::path& path) {
  std::istringstream lines(read_bytes(path));
  std::string line;
  int count = 0;
  while (std::getline(lines, line)) count += line.rfind("f ", 0) == 0 ? 1 : 0;
  return count;
}

}  // namespace

TEST_CASE("scenegen output is byte-identical to the committed scenes", "[scenegen]") {
  TempDir out;
  REQUIRE(run_scenegen(out.path()) == 0);
  REQUIRE(file_names_in(out.path()) == kGeneratedFiles);
  for (const std::string& name : kGeneratedFiles) {
    INFO("scenes/" << name
                   << " differs from the generator's output; regenerate with "
                      "build/release/covrast-scenegen scenes");
    const fs::path committed = kScenesDir / name;
    REQUIRE(fs::exists(committed));
    const std::string generated_bytes = read_bytes(out.path() / name);
    CHECK(generated_bytes.size() > 0);
    CHECK(generated_bytes == read_bytes(committed));
  }
}

TEST_CASE("scenegen --only writes just the named scene with its meshes", "[scenegen]") {
  TempDir out;
  REQUIRE(run_scenegen(out.path(), "--only sphere_grid --only box.obj") == 0);
  CHECK(file_names_in(out.path()) ==
        std::set<std::string>{"sphere_grid.json", "sphere5k.obj", "box.obj"});

  TempDir refused;
  CHECK(run_scenegen(refused.path(), "--only no_such_scene") != 0);
  CHECK(file_names_in(refused.path()).empty());
}

TEST_CASE("sphere5k.obj has exactly 5000 triangles and is closed", "[scenegen]") {
  const fs::path path = kScenesDir / "sphere5k.obj";
  CHECK(count_f_lines(path) == 5000);
  const ObjMesh mesh = parse_obj(path);
  CHECK(mesh.triangles.size() == 5000);
  CHECK(mesh.positions.size() == 2 + 50 * 50);  // 2 poles + 50 segments x 50 inner rings
  CHECK(is_closed_and_consistently_wound(mesh));
  CHECK(signed_volume(mesh) > 0.0);
}

TEST_CASE("sphere.obj is a closed, consistently and outwards wound unit sphere", "[scenegen]") {
  const ObjMesh mesh = parse_obj(kScenesDir / "sphere.obj");
  REQUIRE(mesh.triangles.size() == 2 * 48 * 23);  // 48 segments, 24 rings, fan poles
  CHECK(mesh.positions.size() == 2 + 48 * 23);
  CHECK(is_closed_and_consistently_wound(mesh));
  double max_radius_error = 0.0;
  for (const auto& p : mesh.positions) {
    const double radius = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    max_radius_error = std::max(max_radius_error, std::fabs(radius - 1.0));
  }
  CHECK(max_radius_error < 1e-8);  // 9 significant digits
  // An inscribed polyhedron: a little less than the ball's 4/3 pi, and positive (outwards).
  const double ball_volume = 4.0 / 3.0 * 3.14159265358979323846;
  const double volume = signed_volume(mesh);
  CHECK(volume < ball_volume);
  CHECK(volume > 0.98 * ball_volume);
}

TEST_CASE("box.obj is a closed outwards-wound unit cube, fan.obj is an open soup", "[scenegen]") {
  const ObjMesh box = parse_obj(kScenesDir / "box.obj");
  CHECK(box.triangles.size() == 12);
  CHECK(is_closed_and_consistently_wound(box));
  CHECK(signed_volume(box) == Approx(1.0).margin(1e-12));

  // The checker rejects open meshes: the fan's slivers share no edges.
  const ObjMesh fan = parse_obj(kScenesDir / "fan.obj");
  CHECK(fan.triangles.size() == 32);
  CHECK_FALSE(is_closed_and_consistently_wound(fan));
}
