// Tests of EXT_meshopt_compression (src/scene/gltf_meshopt.cpp): files whose buffer views are
// compressed with libmeshoptimizer's encoders here load to exactly what the same data
// uncompressed loads to, with a fallback buffer that holds no bytes; a filtered attribute
// decodes within its quantisation; every malformed field is an error naming it.
#include <covrast/error.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <meshoptimizer.h>
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "test_gltf_files.hpp"
#include "test_tempdir.hpp"

using Catch::Matchers::Contains;

namespace {

/// A 4x4 grid of vertices on z = sin(x) cos(y) (18 triangles), its indices and unit normals.
struct Grid {
  std::vector<float> positions;
  std::vector<std::uint16_t> indices;
  std::vector<float> normals;  // 4 floats per vertex for the octahedral encoder (w unused)
};

Grid make_grid() {
  Grid g;
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) {
      const float x = float(i) / 3.0f, y = float(j) / 3.0f;
      g.positions.insert(g.positions.end(), {x, y, 0.3f * std::sin(3 * x) * std::cos(2 * y)});
      const float nx = -0.9f * std::cos(3 * x) * std::cos(2 * y);
      const float ny = 0.6f * std::sin(3 * x) * std::sin(2 * y);
      const float length = std::sqrt(nx * nx + ny * ny + 1.0f);
      g.normals.insert(g.normals.end(), {nx / length, ny / length, 1.0f / length, 0.0f});
    }
  }
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      const auto v = std::uint16_t(j * 4 + i);
      g.indices.insert(g.indices.end(), {v, std::uint16_t(v + 1), std::uint16_t(v + 5), v,
                                         std::uint16_t(v + 5), std::uint16_t(v + 4)});
    }
  }
  return g;
}

std::string raw(const void* data, std::size_t size) {
  return std::string(static_cast<const char*>(data), size);
}

/// The grid as a .glb whose three buffer views (positions, normals as octahedral int8,
/// indices in `index_mode`) are compressed into buffer 0, their fallback buffer 1 holding no
/// bytes. `edit` may change the document before it is written.
std::string compressed_grid(const Grid& g, const std::string& index_mode,
                            const std::function<void(nlohmann::json&)>& edit = {}) {
  const std::size_t vertices = g.positions.size() / 3;
  std::vector<unsigned char> out(meshopt_encodeVertexBufferBound(vertices, 12));
  const std::string positions =
      raw(out.data(),
          meshopt_encodeVertexBuffer(out.data(), out.size(), g.positions.data(), vertices, 12));
  std::vector<std::int8_t> oct(vertices * 4);
  meshopt_encodeFilterOct(oct.data(), vertices, 4, 8, g.normals.data());
  out.assign(meshopt_encodeVertexBufferBound(vertices, 4), 0);
  const std::string normals =
      raw(out.data(), meshopt_encodeVertexBuffer(out.data(), out.size(), oct.data(), vertices, 4));
  const std::size_t index_count = g.indices.size();
  std::string indices;
  if (index_mode == "TRIANGLES") {
    out.assign(meshopt_encodeIndexBufferBound(index_count, vertices), 0);
    indices = raw(out.data(),
                  meshopt_encodeIndexBuffer(out.data(), out.size(), g.indices.data(), index_count));
  } else {
    out.assign(meshopt_encodeIndexSequenceBound(index_count, vertices), 0);
    indices = raw(out.data(), meshopt_encodeIndexSequence(out.data(), out.size(), g.indices.data(),
                                                          index_count));
  }
  std::string bin;
  nlohmann::json views = nlohmann::json::array();
  std::size_t fallback_offset = 0;
  const auto add = [&](const std::string& bytes, std::size_t stride, std::size_t count,
                       const std::string& mode, const std::string& filter, bool vertex) {
    while (bin.size() % 4 != 0) bin += '\0';
    nlohmann::json ext = {
        {"buffer", 0},          {"byteOffset", bin.size()}, {"byteLength", bytes.size()},
        {"byteStride", stride}, {"count", count},           {"mode", mode}};
    if (!filter.empty()) ext["filter"] = filter;
    nlohmann::json view = {{"buffer", 1},
                           {"byteOffset", fallback_offset},
                           {"byteLength", stride * count},
                           {"extensions", {{"EXT_meshopt_compression", ext}}}};
    if (vertex) view["byteStride"] = stride;
    views.push_back(view);
    bin += bytes;
    fallback_offset += (stride * count + 3) / 4 * 4;
  };
  add(positions, 12, vertices, "ATTRIBUTES", "", true);
  add(normals, 4, vertices, "ATTRIBUTES", "OCTAHEDRAL", true);
  add(indices, 2, index_count, index_mode, "", false);
  nlohmann::json doc = {
      {"asset", {{"version", "2.0"}}},
      {"extensionsUsed", {"EXT_meshopt_compression", "KHR_mesh_quantization"}},
      {"extensionsRequired", {"EXT_meshopt_compression", "KHR_mesh_quantization"}},
      {"buffers",
       {{{"byteLength", bin.size() + (4 - bin.size() % 4) % 4}},
        {{"byteLength", fallback_offset},
         {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}}},
      {"bufferViews", views},
      {"accessors",
       {{{"bufferView", 0},
         {"componentType", 5126},
         {"count", vertices},
         {"type", "VEC3"},
         {"min", {0, 0, -0.3}},
         {"max", {1, 1, 0.3}}},
        {{"bufferView", 1},
         {"componentType", 5120},
         {"normalized", true},
         {"count", vertices},
         {"type", "VEC3"}},
        {{"bufferView", 2}, {"componentType", 5123}, {"count", index_count}, {"type", "SCALAR"}}}},
      {"meshes",
       {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 2}}}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"scenes", {{{"nodes", {0}}}}},
      {"scene", 0}};
  if (edit) edit(doc);
  return covrast::test::make_glb(doc.dump(), bin);
}

void write(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

}  // namespace

TEST_CASE("meshopt: compressed views load to the uncompressed data, fallback buffer empty",
          "[gltf][meshopt]") {
  const Grid g = make_grid();
  covrast::test::TempDir dir("covrast-meshopt");
  // The same positions and indices uncompressed.
  covrast::test::GltfBuilder plain;
  const int pos = plain.add_floats(g.positions, "VEC3");
  const int idx = plain.add_u16(g.indices, "SCALAR");
  plain.single_mesh({{{"attributes", {{"POSITION", pos}}}, {"indices", idx}}});
  write(dir / "plain.glb", plain.glb());
  const auto reference = covrast::load_mesh(dir / "plain.glb");
  for (const std::string mode : {"TRIANGLES", "INDICES"}) {
    INFO(mode);
    write(dir / "c.glb", compressed_grid(g, mode));
    const auto mesh = covrast::load_mesh(dir / "c.glb");
    CHECK(mesh->positions == reference->positions);
    // The index codec keeps the triangles and their order, but may start a triangle at
    // another of its corners (the same orientation): compare each from its smallest index.
    const auto canonical = [](std::vector<std::uint32_t> indices) {
      for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
        while (indices[t] > indices[t + 1] || indices[t] > indices[t + 2]) {
          std::rotate(indices.begin() + std::ptrdiff_t(t), indices.begin() + std::ptrdiff_t(t + 1),
                      indices.begin() + std::ptrdiff_t(t + 3));
        }
      }
      return indices;
    };
    CHECK(canonical(mesh->indices) == canonical(reference->indices));
    // Normals: 8-bit octahedral, so within the quantisation of one step in 127.
    REQUIRE(mesh->corner_normals.size() == g.indices.size());
    double worst = 0;
    for (std::size_t c = 0; c < g.indices.size(); ++c) {
      const std::size_t v = mesh->indices[c];
      const glm::vec3 n = mesh->corner_normals[c];
      const glm::vec3 expected(g.normals[4 * v], g.normals[4 * v + 1], g.normals[4 * v + 2]);
      worst = std::max(worst, double(glm::length(glm::normalize(n) - expected)));
    }
    CHECK(worst < 0.03);
    const covrast::Scene scene = covrast::load_mesh_scene(dir / "c.glb", 16, 16);
    for (const std::string& warning : scene.warnings) {
      CHECK(warning.find("EXT_meshopt_compression") == std::string::npos);  // honoured
    }
  }
}

TEST_CASE("meshopt: malformed extension fields are errors naming the field", "[gltf][meshopt]") {
  const Grid g = make_grid();
  covrast::test::TempDir dir("covrast-meshopt");
  const std::string field = "bufferViews[0].extensions.EXT_meshopt_compression";
  const auto expect_error = [&](const std::function<void(nlohmann::json&)>& edit,
                                const std::string& message) {
    write(dir / "bad.glb", compressed_grid(g, "TRIANGLES", edit));
    CHECK_THROWS_WITH(covrast::load_mesh(dir / "bad.glb"), Contains(message));
  };
  const auto ext = [](nlohmann::json& doc, int view) -> nlohmann::json& {
    return doc["bufferViews"][view]["extensions"]["EXT_meshopt_compression"];
  };
  expect_error([&](nlohmann::json& d) { ext(d, 0)["mode"] = "STRIPS"; },
               field + ".mode: expected ATTRIBUTES, TRIANGLES or INDICES, not 'STRIPS'");
  expect_error([&](nlohmann::json& d) { ext(d, 0)["byteStride"] = 6; },
               field + ".byteStride: must be a multiple of 4 for ATTRIBUTES");
  expect_error([&](nlohmann::json& d) { ext(d, 0)["byteStride"] = 300; },
               field + ".byteStride: expected a whole number in [1, 256]");
  expect_error([&](nlohmann::json& d) { ext(d, 0)["buffer"] = 7; },
               field + ".buffer: expected a whole number in [0, 1]");
  expect_error([&](nlohmann::json& d) { ext(d, 0)["count"] = "16"; },
               field + ".count: expected a whole number");
  expect_error([&](nlohmann::json& d) { ext(d, 0)["byteLength"] = 100000; },
               field + ".byteLength: the compressed bytes");
  expect_error([&](nlohmann::json& d) { ext(d, 0)["byteLength"] = 5; },
               field + ": cannot decode the compressed data");
  expect_error([&](nlohmann::json& d) { ext(d, 0)["count"] = 15; },
               field + ": count x byteStride = 180 bytes, but the view's byteLength is 192");
  expect_error([&](nlohmann::json& d) { ext(d, 0)["filter"] = "QUATERNION"; },
               field + ".byteStride: must be 8 for QUATERNION");
  expect_error(
      [&](nlohmann::json& d) { ext(d, 2)["filter"] = "OCTAHEDRAL"; },
      "bufferViews[2].extensions.EXT_meshopt_compression.filter: only ATTRIBUTES take a filter");
  expect_error([&](nlohmann::json& d) { ext(d, 2)["count"] = 53; },
               "bufferViews[2].extensions.EXT_meshopt_compression.count: must be a multiple of 3");
}
