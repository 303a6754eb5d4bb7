// Fuzz target: the renderer on an arbitrary triangle list built in memory, in any mode, with
// the determinism promise (docs/numerics.md) checked inside: the input's mode renders twice,
// with 8-pixel tiles on 1 thread and with 24-pixel tiles on 2 threads, and the bytes must be
// equal. One mode per input (the input chooses it) rather than all nine: nine times as many
// inputs per second, and the fuzzer still reaches every mode (the seeds hold one of each).
//
// Input layout (all little-endian; missing bytes read as 0):
//   byte 0, 1   width, height: 1 + byte % 24 [pixels]
//   byte 2      flags: 1 lit (a directional and an ambient light), 2 per-triangle colours,
//               4 vertex colours, 8 smooth normals, 16 a model matrix follows, 32 a camera
//               follows, 64 no hidden back-face culling, 128 depth output
//   byte 3      N of the ssaa modes: 1 + bits 0..1; K of msaa: 2, 4, 8, 16 from bits 2..3;
//               the mode: bits 4..7 % 9, in the order of `modes` below
//   then        12 floats: the model matrix's top three rows (flag 16), 6 floats: the eye
//               and the target (flag 32), then 9 floats per triangle, as raw bits: NaN, Inf,
//               1e30, denormals, degenerate and behind-the-eye triangles all come from here.
// The mesh is built directly as MeshData (make_mesh would refuse non-finite positions; a file's
// are dropped at load time, but the renderer must not depend on that), and the scene must pass
// check_scene, as a program's scene would (a non-finite matrix or a bad camera is skipped).
#include "fuzz_support.hpp"
#include "render_splits.hpp"

#include <covrast/renderer.hpp>

#include <array>
#include <cstring>
#include <memory>

namespace {

class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t byte() { return at_ < size_ ? data_[at_++] : 0; }
  float real() {
    std::uint32_t bits = 0;
    for (int i = 0; i < 4; ++i) bits |= std::uint32_t(byte()) << (8 * i);
    float x;
    std::memcpy(&x, &bits, sizeof x);
    return x;
  }
  std::size_t left() const { return size_ - at_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

enum Flags : std::uint8_t {
  kLit = 1,
  kPerTriangle = 2,
  kVertexColors = 4,
  kSmooth = 8,
  kModel = 16,
  kCamera = 32,
  kNoCull = 64,
  kDepth = 128,
};

void fail(const char* what, const std::string& mode) {
  std::fprintf(stderr,
               "covrast fuzz: %s differ between tile 8 / 1 thread and tile 24 / 2 "
               "threads in mode %s\n",
               what, mode.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Reader in(data, size);
  covrast::Scene scene;
  scene.width = 1 + in.byte() % 24;
  scene.height = 1 + in.byte() % 24;
  scene.background_linear = glm::vec3(0.02f, 0.05f, 0.1f);
  const std::uint8_t flags = in.byte();
  const std::uint8_t samples = in.byte();
  const int ssaa_side = 1 + samples % 4;
  const int msaa_count = 2 << ((samples >> 2) & 3);

  covrast::InstanceDesc desc;
  if (flags & kModel) {
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 4; ++col) desc.model[col][row] = in.real();  // column-major
    }
  }
  if (flags & kCamera) {
    scene.camera.eye = {in.real(), in.real(), in.real()};
    scene.camera.target = {in.real(), in.real(), in.real()};
  }
  auto mesh = std::make_shared<covrast::MeshData>();
  mesh->source = "fuzz";
  while (in.left() >= 9 * sizeof(float)) {
    for (int corner = 0; corner < 3; ++corner) {
      mesh->indices.push_back(std::uint32_t(mesh->positions.size()));
      mesh->positions.push_back({in.real(), in.real(), in.real()});
    }
  }
  if (flags & kVertexColors) {
    for (std::size_t i = 0; i < mesh->positions.size(); ++i) {
      mesh->colors_linear.push_back({float(i % 3) / 2.0f, float(i % 5) / 4.0f, 0.5f});
    }
  }
  covrast::analyze_mesh_topology(*mesh);
  if (flags & kPerTriangle) desc.per_triangle_colors = true;
  if (flags & kSmooth) desc.normals = covrast::NormalSource::Smooth;
  if (flags & kLit) {
    covrast::add_light(scene, {.type = covrast::LightType::Directional,
                               .direction = {-0.3, -0.5, -1.0},
                               .intensity = 2.0});
    covrast::add_light(scene, {.type = covrast::LightType::Ambient, .intensity = 0.2});
  }
  try {
    covrast::add_instance(scene, mesh, desc);
    covrast::check_scene(scene);
  } catch (const covrast::InputError&) {
    return 0;  // refused up front, as a program's scene would be
  }

  const std::size_t work = std::size_t(scene.width) * scene.height * mesh->triangle_count();
  const std::array<std::string, 9> modes = {"aliased",
                                            "coverage",
                                            "coverage-blend",
                                            "ssaa:" + std::to_string(ssaa_side),
                                            "ssaa-grid:" + std::to_string(ssaa_side),
                                            "ssaa-cmj:" + std::to_string(ssaa_side),
                                            "msaa:" + std::to_string(msaa_count),
                                            "fxaa",
                                            "reference"};
  const std::string& mode = modes[std::size_t(samples >> 4) % modes.size()];
  // The reference mode takes 4096 samples per pixel: only for small inputs.
  if (mode == "reference" && work > 256) return 0;
  covrast::RenderOptions options;
  options.mode = covrast::parse_render_mode(mode);
  options.cull_hidden_backfaces = (flags & kNoCull) == 0;
  options.want_depth = (flags & kDepth) != 0;
  const auto [a, b] = covrast::fuzz::render_two_splits(scene, options);
  if (a.color.width != scene.width || a.color.height != scene.height ||
      a.color.rgb.size() != std::size_t(scene.width) * scene.height * 3) {
    std::fprintf(stderr, "covrast fuzz: %dx%d image for a %dx%d scene in mode %s\n", a.color.width,
                 a.color.height, scene.width, scene.height, mode.c_str());
    std::abort();
  }
  if (a.color.rgb != b.color.rgb) fail("colours", mode);
  // Depth compared as bits (a NaN depth must be the same NaN).
  if (a.depth.depth.size() != b.depth.depth.size() ||
      (!a.depth.depth.empty() && std::memcmp(a.depth.depth.data(), b.depth.depth.data(),
                                             a.depth.depth.size() * sizeof(float)) != 0)) {
    fail("depths", mode);
  }
  return 0;
}
