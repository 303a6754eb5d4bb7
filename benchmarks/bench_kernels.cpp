// Stage benchmarks below the frame level:
//   kernel/coverage/scalar/<size>          coverage_rows_scalar, the reference twin
//   kernel/coverage/simd:<target>/<size>   coverage_rows_simd forced to each Highway target
//                                          compiled in and supported by this CPU
//   kernel/coverage_group/<impl>/<size>    CoverGroupFn, the coverage mode's whole per-group
//                                          step (set-up and rows): cover_group_scalar, or
//                                          cover_group_simd forced to each target
//   kernel/sample/<mode>/<impl>            SampleGroupFn, the per-group inner loop of the
//                                          sample modes (<mode> msaa:4, msaa:16, ssaa:4,
//                                          ssaa:16; <impl> scalar or simd:<target>)
//   kernel/sample_raster/<mode>/<impl>/<size>  RasterTriangleFn, the whole per-triangle loop
//   kernel/sample_resolve/<mode>/<impl>    ResolvePixelsFn, the box-filter sums of a band
//   stage/transform, stage/setup_chunk, stage/bin_chunk   on sphere_grid at 1920x1080, each
//                                          as the pipeline calls it (setup_chunk into
//                                          ChunkSetups slices of one huge-page buffer plus
//                                          pixel bounds, bin_chunk from those)
//   stage/fxaa/<impl>                      the FXAA post-process of sphere_grid's aliased
//                                          frame (1920x1080) on one thread: the luma rows,
//                                          then the filter rows into a copy of the frame;
//                                          <impl> scalar (the twins) or simd:<target>. The
//                                          SIMD output is checked against the scalar first
//
// The coverage kernel runs on realistic inputs: random triangles inside a 64 x 64 tile, set
// up group by group of kColumnGroup columns exactly as the coverage rasterizer does, and the
// kernel is called for the top and bottom partial runs of each group (the interior run needs
// no kernel). kernel/coverage_group runs the same groups from their triangles, set-up
// included, as the rasterizer calls it. <size> is "small" (1-8 px, like sphere_grid) or
// "large" (8-60 px).
//
// The sample kernels run on the product's patterns (msaa_pattern, ssaa_pattern), group
// layout and bands (SampleRasterizer, 64 px tile, default band budget): 128 random
// triangles of 2-24 px over the tile (a third vertex-coloured, i.e. shaded through
// ShadeWrittenFn, here a stand-in that only stores a colour), called per group as
// RasterTriangleFn calls SampleGroupFn (f = nullptr for groups inside all three edges,
// counter full_groups = their share). kernel/sample_raster draws 256 triangles of 4 px, 16
// of 32 px or 2 of 256 px (in a 256 px tile) per iteration; its samples/s counts samples
// inside the triangles. Each band starts with cleared depth as in the product; the clear is
// not timed (manual time). kernel/sample_resolve resolves the first band of the mixed
// workload (the whole tile, ssaa:16: 64 x 8 px). Before timing, every sample benchmark runs
// the scalar and the SIMD kernels (the best target for the scalar benchmark) on the same
// inputs and fails if any output differs.
#include "binning/tile_bins.hpp"
#include "core/edge_function.hpp"
#include "core/testing_hooks.hpp"
#include "geometry/frontend.hpp"
#include "post/fxaa.hpp"
#include "raster/coverage/coverage_kernel.hpp"
#include "raster/samples/sample_kernel.hpp"
#include "raster/samples/sample_pattern.hpp"
#include "raster/samples/sample_raster.hpp"

#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <benchmark/benchmark.h>
#include <hwy/aligned_allocator.h>
#include <hwy/targets.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <climits>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace covrast::detail;

constexpr int kTilePx = 64;

/// One kernel call site: a column group with its partial-run rows.
struct KernelJob {
  std::unique_ptr<CoverageColumns> columns;
  int sign = 1;
  int lanes = 0;  ///< columns of the group the triangle spans
  int first = 0, interior_begin = 0, interior_end = 0, end = 0;
  CoverageTriangle tri{};  ///< the group's triangle, column and clip rows, for CoverGroupFn
  int col = 0, row_min = 0, row_max = 0;
};

std::vector<KernelJob> make_kernel_jobs(double min_px, double max_px, std::uint32_t seed) {
  std::vector<KernelJob> jobs;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(0.0, kTilePx), size(min_px, max_px), unit(-1.0, 1.0);
  const PixelRect tile{0, 0, kTilePx, kTilePx};
  while (jobs.size() < 256) {
    TriangleSetup t{};
    const double cx = pos(rng), cy = pos(rng), s = size(rng);
    for (int k = 0; k < 3; ++k) {
      t.x_fx8[k] = std::int32_t(std::lround((cx + s * unit(rng)) * kSubpixelOne));
      t.y_fx8[k] = std::int32_t(std::lround((cy + s * unit(rng)) * kSubpixelOne));
    }
    const PixelRect r = intersect(touched_pixels(t), tile);
    if (r.empty()) continue;
    const CoverageTriangle tri = make_coverage_triangle(t);
    // The same per-group set-up as raster/coverage.cpp.
    for (int g = r.x0; g < r.x1 && jobs.size() < 256; g += kColumnGroup) {
      KernelJob job;
      job.columns = std::make_unique<CoverageColumns>();
      job.sign = tri.sign;
      job.lanes = std::min(kColumnGroup, r.x1 - g);
      job.tri = tri;
      job.col = g;
      job.row_min = r.y0;
      job.row_max = r.y1;
      const GroupRows rows = setup_column_group(tri, g, job.lanes, r.y0, r.y1, *job.columns);
      if (rows.empty()) continue;
      job.first = rows.first;
      job.end = rows.end;
      job.interior_begin = rows.interior_begin;
      job.interior_end = rows.interior_end;
      jobs.push_back(std::move(job));
    }
  }
  return jobs;
}

/// Output row stride of the coverage-kernel benchmarks [pixels].
constexpr std::size_t kStride = kColumnGroup * 2;

/// Starts a coverage-kernel benchmark: forces `target` (0: scalar), labels the run with it,
/// and makes the fixed set of triangle groups it runs over.
std::vector<KernelJob> start_kernel_run(benchmark::State& state, std::int64_t target, double min_px,
                                        double max_px) {
  if (target != 0) testing::force_simd_target(target);
  state.SetLabel(target != 0 ? testing::simd_target_name() : "scalar");
  return make_kernel_jobs(min_px, max_px, 1234);
}

/// Ends a coverage-kernel benchmark: the forced target back to the best one, and the rate
/// counters from what one iteration computed.
void finish_kernel_run(benchmark::State& state, std::int64_t target, std::uint64_t columns,
                       std::uint64_t pixels) {
  if (target != 0) testing::force_simd_target(0);
  const double n = double(state.iterations());
  state.counters["columns/s"] =
      benchmark::Counter(n * double(columns), benchmark::Counter::kIsRate);
  state.counters["pixels/s"] = benchmark::Counter(n * double(pixels), benchmark::Counter::kIsRate);
}

void run_kernel(benchmark::State& state, CoverageRowsFn kernel, std::int64_t target, double min_px,
                double max_px) {
  const std::vector<KernelJob> jobs = start_kernel_run(state, target, min_px, max_px);
  std::vector<std::uint16_t> plane(std::size_t(kTilePx) * kStride);
  std::uint64_t columns = 0, pixels = 0;
  for (const KernelJob& job : jobs) {
    const int partial_rows = (job.interior_begin - job.first) + (job.end - job.interior_end);
    columns += std::uint64_t(job.lanes);
    pixels += std::uint64_t(job.lanes) * std::uint64_t(partial_rows);
  }
  for (auto _ : state) {
    for (const KernelJob& job : jobs) {
      kernel(*job.columns, 0, job.first, job.interior_begin, job.sign,
             plane.data() + std::size_t(job.first) * kStride, kStride);
      kernel(*job.columns, 0, job.interior_end, job.end, job.sign,
             plane.data() + std::size_t(job.interior_end) * kStride, kStride);
    }
    benchmark::DoNotOptimize(plane.data());
    benchmark::ClobberMemory();
  }
  finish_kernel_run(state, target, columns, pixels);
}

void run_cover_group(benchmark::State& state, CoverGroupFn fn, std::int64_t target, double min_px,
                     double max_px) {
  const std::vector<KernelJob> jobs = start_kernel_run(state, target, min_px, max_px);
  std::vector<std::uint16_t> plane(std::size_t(kTilePx) * kStride);
  std::uint64_t columns = 0, pixels = 0;
  for (const KernelJob& job : jobs) {
    columns += std::uint64_t(job.lanes);
    pixels += std::uint64_t(job.lanes) * std::uint64_t(job.end - job.first);
  }
  for (auto _ : state) {
    for (const KernelJob& job : jobs) {
      fn(job.tri, job.col, job.lanes, job.row_min, job.row_max,
         plane.data() + std::size_t(job.row_min) * kStride, kStride);
    }
    benchmark::DoNotOptimize(plane.data());
    benchmark::ClobberMemory();
  }
  finish_kernel_run(state, target, columns, pixels);
}

// ---------------------------------------------------------------------------------------
// Sample-mode kernels (raster/sample_kernel.hpp).

/// The product's sample modes: the patterns of raster/msaa.cpp and raster/ssaa.cpp.
struct SampleMode {
  const char* name;
  SamplePattern (*pattern)();
  ShadingRate rate;
};
const SampleMode kSampleModes[] = {
    {"msaa:4", [] { return msaa_pattern(4); }, ShadingRate::PerPixel},
    {"msaa:16", [] { return msaa_pattern(16); }, ShadingRate::PerPixel},
    {"ssaa:4", [] { return ssaa_pattern(4); }, ShadingRate::PerSample},
    {"ssaa:16", [] { return ssaa_pattern(16); }, ShadingRate::PerSample},
};

/// The product's group layout for a pixel pattern (sample_raster.hpp).
std::unique_ptr<GroupPattern> make_group_pattern(const SamplePattern& pattern) {
  auto gp = std::make_unique<GroupPattern>();
  covrast::detail::make_group_pattern(pattern, *gp);
  return gp;
}

/// One band's sample buffers (depth and fixed-point colour, pixel-major as in
/// SampleRasterizer).
struct BandBuffers {
  hwy::AlignedFreeUniquePtr<float[]> depth;
  hwy::AlignedFreeUniquePtr<std::uint32_t[]> r, g, b;
  std::size_t lanes;
  explicit BandBuffers(std::size_t n)
      : depth(hwy::AllocateAligned<float>(n)),
        r(hwy::AllocateAligned<std::uint32_t>(n)),
        g(hwy::AllocateAligned<std::uint32_t>(n)),
        b(hwy::AllocateAligned<std::uint32_t>(n)),
        lanes(n) {
    reset(n);
  }
  /// Depth +infinity and colour 0 in the first n lanes (the check compares colours too).
  void reset(std::size_t n) {
    std::fill(depth.get(), depth.get() + n, std::numeric_limits<float>::infinity());
    std::fill(r.get(), r.get() + n, 0u);
    std::fill(g.get(), g.get() + n, 0u);
    std::fill(b.get(), b.get() + n, 0u);
  }
  GroupSamples at(std::size_t lane) const {
    return GroupSamples{depth.get() + lane, r.get() + lane, g.get() + lane, b.get() + lane};
  }
};

/// A triangle of the workload with its kernel constants.
struct BenchTriangle {
  TriangleSetup setup;
  std::uint32_t rgb[3];  ///< quantized colour: the flat colour, or what shade_constant stores
  std::int32_t dx[3], dy[3];
};

/// One SampleGroupFn call as RasterTriangleFn makes it.
struct GroupCall {
  std::uint32_t triangle;
  bool test_edges;    ///< false: every lane inside, f = nullptr
  std::int32_t f[3];  ///< min(F, kEdgeClamp)
  float z_base;
  std::size_t lane;  ///< the group's first lane in the band buffers
};

struct Band {
  int y0 = 0, y1 = 0;
  std::vector<RasterJob> jobs;  ///< into SampleWorkload::buffers, in draw order
  std::vector<GroupCall> calls;
};

/// Triangles drawn into one tile at (0, 0), split into the product's bands.
struct SampleWorkload {
  std::unique_ptr<GroupPattern> pattern;
  int tile_px = 0;
  int band_rows = 0;
  int buffer_px = 0;  ///< pixels per buffer row, a multiple of G
  std::size_t row_lanes = 0;
  std::unique_ptr<BandBuffers> buffers;
  std::vector<BenchTriangle> triangles;  ///< never resized once jobs point into it
  std::vector<Band> bands;
  std::uint64_t calls = 0, full_calls = 0;
  std::uint64_t inside_samples = 0;  ///< samples inside some triangle, summed over triangles
  std::size_t band_lanes(const Band& band) const {
    return std::size_t(band.y1 - band.y0) * row_lanes;
  }
};

/// ShadeWrittenFn stand-in: stores the triangle's colour in the lanes it won, i.e. the
/// stores of SampleRasterizer::shade_written without the shading arithmetic.
void shade_constant(void* context, int, int, const std::uint64_t* written,
                    const GroupSamples& group) {
  const BenchTriangle& t = *static_cast<const BenchTriangle*>(context);
  for (int w = 0; w < kMaxGroupLanes / 64; ++w) {
    for (std::uint64_t bits = written[w]; bits != 0; bits &= bits - 1) {
      const int l = w * 64 + std::countr_zero(bits);
      group.r[l] = t.rgb[0];
      group.g[l] = t.rgb[1];
      group.b[l] = t.rgb[2];
    }
  }
}

/// A random triangle with vertices in the size_px square at (x_px, y_px), area at least
/// size_px^2 / 8, clockwise (positive doubled area, as the setup orders it), depth plane
/// z0 in [0.1, 0.9] at vertex 0 changing by at most 0.5 across the square; every third
/// one is vertex-coloured (shaded through ShadeWrittenFn), the others flat.
TriangleSetup random_triangle(std::mt19937& rng, double x_px, double y_px, double size_px,
                              std::uint32_t index) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  TriangleSetup t{};
  for (;;) {
    for (int k = 0; k < 3; ++k) {
      t.x_fx8[k] = std::int32_t(std::lround((x_px + size_px * unit(rng)) * kSubpixelOne));
      t.y_fx8[k] = std::int32_t(std::lround((y_px + size_px * unit(rng)) * kSubpixelOne));
    }
    const std::int64_t area2 = std::int64_t(t.x_fx8[1] - t.x_fx8[0]) * (t.y_fx8[2] - t.y_fx8[0]) -
                               std::int64_t(t.x_fx8[2] - t.x_fx8[0]) * (t.y_fx8[1] - t.y_fx8[0]);
    const double min_area2 = size_px * size_px / 4.0 * kSubpixelOne * kSubpixelOne;
    if (double(std::abs(area2)) < min_area2) continue;
    if (area2 < 0) {
      std::swap(t.x_fx8[1], t.x_fx8[2]);
      std::swap(t.y_fx8[1], t.y_fx8[2]);
    }
    break;
  }
  t.z0 = 0.1 + 0.8 * unit(rng);
  t.dzdx = (unit(rng) - 0.5) * 0.5 / size_px;
  t.dzdy = (unit(rng) - 0.5) * 0.5 / size_px;
  t.flat_color = index % 3 != 0;
  const glm::vec3 c(float(unit(rng)), float(unit(rng)), float(unit(rng)));
  for (glm::vec3& v : t.color) v = c;
  t.primitive = index;
  return t;
}

/// The product's RasterJob (sample_raster.hpp) for triangle t over rect r of the band
/// starting at row band_y0 (buffer column 0 = pixel 0), with this benchmark's colour, shading
/// stand-in and buffers. False when an edge is too long for the int32 path (never for the
/// triangles made here).
bool make_raster_job(const SampleWorkload& w, BenchTriangle& bt, const PixelRect& r, int band_y0,
                     RasterJob& job) {
  const GroupPattern& gp = *w.pattern;
  if (!covrast::detail::make_raster_job(gp, bt.setup, r, job)) return false;
  for (int e = 0; e < 3; ++e) {
    bt.dx[e] = job.dx[e];
    bt.dy[e] = job.dy[e];
  }
  job.rgb = bt.setup.flat_color ? bt.rgb : nullptr;
  job.shade_fn = shade_constant;
  job.shade_context = &bt;
  const std::size_t lane =
      (std::size_t(r.y0 - band_y0) * std::size_t(w.buffer_px) + std::size_t(job.gx0)) *
      std::size_t(gp.stride);
  job.first = w.buffers->at(lane);
  job.row_lanes = w.row_lanes;
  return true;
}

/// The SampleGroupFn calls that RasterTriangleFn makes for `job` (same classification and
/// z_base expression as raster_triangle_scalar); also counts the samples inside.
void add_group_calls(SampleWorkload& w, const RasterJob& job, std::uint32_t triangle, Band& band) {
  const GroupPattern& gp = *w.pattern;
  const std::size_t first_lane = std::size_t(job.first.depth - w.buffers->depth.get());
  std::int64_t f_row[3] = {job.f[0], job.f[1], job.f[2]};
  for (int row = 0; row < job.rows; ++row) {
    const int y = job.y0 + row;
    const double z_y = job.dzdy * (double(y) - job.vy);
    std::int64_t f[3] = {f_row[0], f_row[1], f_row[2]};
    for (int g = 0; g < job.groups; ++g) {
      GroupCall call{};
      call.triangle = triangle;
      bool none = false, all_inside = true;
      const std::int64_t f_here[3] = {f[0], f[1], f[2]};
      for (int e = 0; e < 3; ++e) {
        none |= f[e] + job.c_max[e] < 0;
        all_inside &= f[e] + job.c_min[e] >= 0;
        call.f[e] = std::int32_t(f[e] < kEdgeClamp ? f[e] : kEdgeClamp);
        f[e] += job.step_x[e];
      }
      if (none) continue;
      const int gx = job.gx0 + g * gp.group_px;
      call.test_edges = !all_inside;
      call.z_base = float(job.z0 + job.dzdx * (double(gx) - job.vx) + z_y);
      call.lane = first_lane + std::size_t(row) * job.row_lanes + std::size_t(g * gp.lanes);
      band.calls.push_back(call);
      ++w.calls;
      if (all_inside) {
        w.inside_samples += std::uint64_t(gp.group_px) * std::uint64_t(gp.samples);
        ++w.full_calls;
        continue;
      }
      for (int l = 0; l < gp.lanes; ++l) {
        bool inside = gp.valid[l] != 0;
        for (int e = 0; e < 3; ++e) {
          inside &= f_here[e] + std::int64_t(job.dx[e]) * gp.oy_fx8[l] -
                        std::int64_t(job.dy[e]) * gp.ox_fx8[l] >=
                    0;
        }
        w.inside_samples += inside;
      }
    }
    for (int e = 0; e < 3; ++e) f_row[e] += job.step_y[e];
  }
}

/// `count` triangles of size min_px..max_px in a tile_px tile, split into the bands that
/// SampleRasterizer uses (default band budget) and into its RasterJobs and group calls.
std::unique_ptr<SampleWorkload> make_sample_workload(const SampleMode& mode, int tile_px, int count,
                                                     double min_px, double max_px, bool inside_tile,
                                                     std::uint32_t seed) {
  auto w = std::make_unique<SampleWorkload>();
  const SamplePattern pattern = mode.pattern();
  w->pattern = make_group_pattern(pattern);
  const GroupPattern& gp = *w->pattern;
  w->tile_px = tile_px;
  // The product's band height, from the product itself.
  w->band_rows = SampleRasterizer(tile_px, pattern, mode.rate, sample_kernels_scalar()).band_rows();
  w->buffer_px = gp.group_px == 1
                     ? tile_px
                     : (tile_px + gp.group_px - 1) / gp.group_px * gp.group_px + gp.group_px;
  w->row_lanes = std::size_t(w->buffer_px) * std::size_t(gp.stride);
  w->buffers = std::make_unique<BandBuffers>(std::size_t(w->band_rows) * w->row_lanes);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  w->triangles.resize(std::size_t(count));
  for (int i = 0; i < count; ++i) {
    const double size = min_px + (max_px - min_px) * unit(rng);
    // Inside the tile, or anywhere overlapping it (then clipped like a tile's triangle).
    const double lo = inside_tile ? 0.0 : -size / 2, hi = tile_px - (inside_tile ? size : size / 2);
    const double x = lo + (std::max(hi, lo) - lo) * unit(rng);
    const double y = lo + (std::max(hi, lo) - lo) * unit(rng);
    BenchTriangle& bt = w->triangles[std::size_t(i)];
    bt.setup = random_triangle(rng, x, y, size, std::uint32_t(i));
    for (int k = 0; k < 3; ++k) bt.rgb[k] = quantize_color(bt.setup.color[0][k]);
  }
  for (int y0 = 0; y0 < tile_px; y0 += w->band_rows) {
    Band band;
    band.y0 = y0;
    band.y1 = std::min(y0 + w->band_rows, tile_px);
    for (std::uint32_t i = 0; i < w->triangles.size(); ++i) {
      BenchTriangle& bt = w->triangles[i];
      const PixelRect r = intersect(touched_pixels(bt.setup), PixelRect{0, y0, tile_px, band.y1});
      if (r.empty()) continue;
      RasterJob job;
      if (!make_raster_job(*w, bt, r, y0, job)) continue;
      band.jobs.push_back(job);
      add_group_calls(*w, job, i, band);
    }
    w->bands.push_back(std::move(band));
  }
  return w;
}

/// Workloads are built once per (mode, size) and shared by every implementation.
SampleWorkload& cached_workload(const SampleMode& mode, const std::string& key, int tile_px,
                                int count, double min_px, double max_px, bool inside_tile) {
  static std::map<std::string, std::unique_ptr<SampleWorkload>> cache;
  std::unique_ptr<SampleWorkload>& w = cache[std::string(mode.name) + "/" + key];
  if (!w) w = make_sample_workload(mode, tile_px, count, min_px, max_px, inside_tile, 4321);
  return *w;
}

/// The SampleGroupFn / ResolvePixelsFn workload: 128 triangles of 2-24 px over a 64 px tile.
SampleWorkload& mixed_workload(const SampleMode& mode) {
  return cached_workload(mode, "mixed", 64, 128, 2.0, 24.0, false);
}

/// Kernels of one benchmark: the scalar twins, or the SIMD ones of a forced target
/// (restored to the best one by the destructor).
struct ForcedKernels {
  SampleKernels kernels;
  std::int64_t target;
  ForcedKernels(benchmark::State& state, std::int64_t t) : target(t) {
    if (target != 0) testing::force_simd_target(target);
    kernels = target != 0 ? sample_kernels_simd() : sample_kernels_scalar();
    state.SetLabel(target != 0 ? testing::simd_target_name() : "scalar");
  }
  ~ForcedKernels() {
    if (target != 0) testing::force_simd_target(0);
  }
  ForcedKernels(const ForcedKernels&) = delete;
  ForcedKernels& operator=(const ForcedKernels&) = delete;
};

/// The other side of the sanity check: the SIMD kernels of this target for the scalar
/// benchmark (the best target), else the scalar twins.
SampleKernels check_partner(std::int64_t target) {
  return target != 0 ? sample_kernels_scalar() : sample_kernels_simd();
}

bool same_band(const BandBuffers& a, const BandBuffers& b, std::size_t lanes) {
  const auto eq = [lanes](const auto* x, const auto* y) {
    return std::memcmp(x, y, lanes * sizeof(*x)) == 0;
  };
  return eq(a.depth.get(), b.depth.get()) && eq(a.r.get(), b.r.get()) && eq(a.g.get(), b.g.get()) &&
         eq(a.b.get(), b.b.get());
}

/// Group constants of every triangle, set up by `kernels` as the raster kernel does.
std::vector<GroupTriangle> setup_triangles(const SampleWorkload& w, const SampleKernels& kernels) {
  std::vector<GroupTriangle> tris(w.triangles.size());
  for (std::size_t i = 0; i < tris.size(); ++i) {
    const BenchTriangle& bt = w.triangles[i];
    kernels.setup(*w.pattern, bt.dx, bt.dy, true, float(bt.setup.dzdx), float(bt.setup.dzdy),
                  tris[i]);
  }
  return tris;
}

/// Runs one band's group calls into `buf`; `record` gets each call's result and written
/// bits (for the sanity check).
template <class Record>
bool run_group_calls(const SampleWorkload& w, const Band& band, SampleGroupFn sample,
                     const std::vector<GroupTriangle>& tris, const BandBuffers& buf,
                     Record record) {
  bool any = false;
  for (const GroupCall& call : band.calls) {
    const BenchTriangle& bt = w.triangles[call.triangle];
    const bool flat = bt.setup.flat_color;
    std::uint64_t written[kMaxGroupLanes / 64] = {0, 0, 0, 0};
    const bool hit =
        sample(*w.pattern, tris[call.triangle], call.test_edges ? call.f : nullptr, call.z_base,
               flat ? bt.rgb : nullptr, buf.at(call.lane), flat ? nullptr : written);
    record(hit, written);
    any |= hit;
  }
  return any;
}

void run_sample_group(benchmark::State& state, const SampleMode& mode, std::int64_t target) {
  SampleWorkload& w = mixed_workload(mode);
  ForcedKernels forced(state, target);
  const SampleKernels& kernels = forced.kernels;
  const std::vector<GroupTriangle> tris = setup_triangles(w, kernels);
  {
    // Sanity check: both implementations on the same calls give the same triangle
    // constants, results, written bits and buffers.
    const SampleKernels other = check_partner(target);
    const std::vector<GroupTriangle> other_tris = setup_triangles(w, other);
    const std::size_t lanes = std::size_t(w.pattern->lanes);
    for (std::size_t i = 0; i < tris.size(); ++i) {
      for (int e = 0; e < 3; ++e) {
        if (!std::equal(tris[i].c[e], tris[i].c[e] + lanes, other_tris[i].c[e])) {
          state.SkipWithError("SetupGroupFn: scalar and SIMD edge offsets differ");
          return;
        }
      }
      if (std::memcmp(tris[i].dz, other_tris[i].dz, lanes * sizeof(float)) != 0) {
        state.SkipWithError("SetupGroupFn: scalar and SIMD depth offsets differ");
        return;
      }
    }
    BandBuffers a(w.buffers->lanes), b(w.buffers->lanes);
    for (const Band& band : w.bands) {
      const std::size_t n = w.band_lanes(band);
      a.reset(n);
      b.reset(n);
      std::vector<std::uint64_t> log_a, log_b;
      const auto logger = [](std::vector<std::uint64_t>& log) {
        return [&log](bool hit, const std::uint64_t* written) {
          log.push_back(hit);
          log.insert(log.end(), written, written + kMaxGroupLanes / 64);
        };
      };
      run_group_calls(w, band, kernels.sample, tris, a, logger(log_a));
      run_group_calls(w, band, other.sample, other_tris, b, logger(log_b));
      if (log_a != log_b || !same_band(a, b, n)) {
        state.SkipWithError("SampleGroupFn: scalar and SIMD outputs differ");
        return;
      }
    }
  }
  // Each band starts cleared, as in the product; the clear is not timed (manual time).
  const BandBuffers& buf = *w.buffers;
  bool any = false;
  for (auto _ : state) {
    double seconds = 0.0;
    for (const Band& band : w.bands) {
      kernels.clear(buf.depth.get(), w.band_lanes(band));
      const auto start = std::chrono::steady_clock::now();
      any |= run_group_calls(
          w, band, kernels.sample, tris, buf,
          [](bool, const std::uint64_t* written) { benchmark::DoNotOptimize(written); });
      benchmark::ClobberMemory();
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    state.SetIterationTime(seconds);
  }
  benchmark::DoNotOptimize(any);
  const double n = double(state.iterations());
  const double samples_per_call = double(w.pattern->group_px) * double(w.pattern->samples);
  state.counters["groups/s"] = benchmark::Counter(n * double(w.calls), benchmark::Counter::kIsRate);
  state.counters["samples/s"] =
      benchmark::Counter(n * double(w.calls) * samples_per_call, benchmark::Counter::kIsRate);
  state.counters["full_groups"] = double(w.full_calls) / double(w.calls);
}

/// A RasterJob writing into `to` instead of the workload's buffers.
RasterJob rebase(const SampleWorkload& w, RasterJob job, const BandBuffers& to) {
  job.first = to.at(std::size_t(job.first.depth - w.buffers->depth.get()));
  return job;
}

void run_raster_jobs(const SampleWorkload& w, const Band& band, RasterTriangleFn raster,
                     GroupTriangle& scratch, const BandBuffers& buf) {
  for (const RasterJob& job : band.jobs) raster(*w.pattern, rebase(w, job, buf), scratch);
}

struct RasterSize {
  const char* name;
  double size_px;
  int count;
  int tile_px;  ///< the product's default 64, or 256 (its largest) to hold a 256 px triangle
};
const RasterSize kRasterSizes[] = {
    {"4px", 4.0, 256, 64}, {"32px", 32.0, 16, 64}, {"256px", 256.0, 2, 256}};

void run_sample_raster(benchmark::State& state, const SampleMode& mode, const RasterSize& size,
                       std::int64_t target) {
  SampleWorkload& w =
      cached_workload(mode, size.name, size.tile_px, size.count, size.size_px, size.size_px, true);
  ForcedKernels forced(state, target);
  const SampleKernels& kernels = forced.kernels;
  auto scratch = std::make_unique<GroupTriangle>();
  {
    // Sanity check: both implementations leave the same buffers after every band.
    const SampleKernels other = check_partner(target);
    BandBuffers a(w.buffers->lanes), b(w.buffers->lanes);
    for (const Band& band : w.bands) {
      const std::size_t n = w.band_lanes(band);
      a.reset(n);
      b.reset(n);
      run_raster_jobs(w, band, kernels.raster, *scratch, a);
      run_raster_jobs(w, band, other.raster, *scratch, b);
      if (!same_band(a, b, n)) {
        state.SkipWithError("RasterTriangleFn: scalar and SIMD outputs differ");
        return;
      }
    }
  }
  const BandBuffers& buf = *w.buffers;
  for (auto _ : state) {
    double seconds = 0.0;
    for (const Band& band : w.bands) {
      kernels.clear(buf.depth.get(), w.band_lanes(band));
      const auto start = std::chrono::steady_clock::now();
      for (const RasterJob& job : band.jobs) kernels.raster(*w.pattern, job, *scratch);
      benchmark::ClobberMemory();
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    state.SetIterationTime(seconds);
  }
  benchmark::DoNotOptimize(buf.depth.get());
  const double n = double(state.iterations());
  state.counters["triangles/s"] =
      benchmark::Counter(n * double(w.triangles.size()), benchmark::Counter::kIsRate);
  state.counters["samples/s"] =
      benchmark::Counter(n * double(w.inside_samples), benchmark::Counter::kIsRate);
}

void run_sample_resolve(benchmark::State& state, const SampleMode& mode, std::int64_t target) {
  SampleWorkload& w = mixed_workload(mode);
  ForcedKernels forced(state, target);
  const SampleKernels& kernels = forced.kernels;
  // The first band of the mixed workload, rasterized by the scalar twins: some samples
  // keep depth +infinity and resolve to the background.
  const Band& band = w.bands.front();
  const std::size_t n_lanes = w.band_lanes(band);
  w.buffers->reset(n_lanes);
  auto scratch = std::make_unique<GroupTriangle>();
  run_raster_jobs(w, band, sample_kernels_scalar().raster, *scratch, *w.buffers);
  const std::uint32_t background[3] = {quantize_color(0.25f), quantize_color(0.5f),
                                       quantize_color(0.75f)};
  const int pixels = w.tile_px, rows = band.y1 - band.y0;
  std::vector<std::uint32_t> sums(3 * std::size_t(pixels));
  std::vector<float> min_depth(static_cast<std::size_t>(pixels));
  const auto resolve_rows = [&](ResolvePixelsFn resolve, std::vector<std::uint32_t>* all_sums,
                                std::vector<float>* all_depth) {
    for (int row = 0; row < rows; ++row) {
      resolve(*w.pattern, pixels, w.buffers->at(std::size_t(row) * w.row_lanes), background,
              sums.data(), min_depth.data());
      if (all_sums != nullptr) all_sums->insert(all_sums->end(), sums.begin(), sums.end());
      if (all_depth != nullptr) {
        all_depth->insert(all_depth->end(), min_depth.begin(), min_depth.end());
      }
      benchmark::DoNotOptimize(sums.data());
      benchmark::DoNotOptimize(min_depth.data());
    }
  };
  {
    // Sanity check: the same sums and nearest depths from both implementations.
    std::vector<std::uint32_t> sums_a, sums_b;
    std::vector<float> depth_a, depth_b;
    resolve_rows(kernels.resolve, &sums_a, &depth_a);
    resolve_rows(check_partner(target).resolve, &sums_b, &depth_b);
    if (sums_a != sums_b ||
        std::memcmp(depth_a.data(), depth_b.data(), depth_a.size() * sizeof(float)) != 0) {
      state.SkipWithError("ResolvePixelsFn: scalar and SIMD outputs differ");
      return;
    }
  }
  for (auto _ : state) {
    resolve_rows(kernels.resolve, nullptr, nullptr);
    benchmark::ClobberMemory();
  }
  const double n = double(state.iterations()) * double(pixels) * double(rows);
  state.counters["pixels/s"] = benchmark::Counter(n, benchmark::Counter::kIsRate);
  state.counters["samples/s"] =
      benchmark::Counter(n * double(w.pattern->samples), benchmark::Counter::kIsRate);
}

/// sphere_grid and its front end, built once for the stage benchmarks.
struct GridStages {
  covrast::Scene scene;
  std::unique_ptr<GeometryFrontEnd> front_end;
  std::unique_ptr<HugePageBuffer> setup_storage;  ///< the chunks' slices, as the renderer's
  std::vector<ChunkSetups> chunks;
  std::vector<std::vector<PixelBounds16>> bounds;  ///< per chunk, for binning
};

/// Sets up every chunk of `s` as Renderer::render_frame does: each chunk starts over in its
/// slice of the shared buffer.
void setup_all_chunks(GridStages& s, SetupCounters& counters) {
  for (std::uint32_t c = 0; c < s.front_end->chunk_count(); ++c) {
    s.chunks[c].reset(
        static_cast<TriangleSetup*>(s.setup_storage->data()) + std::size_t(c) * kTrianglesPerChunk,
        s.front_end->chunk_triangle_count(c));
    s.bounds[c].clear();
    s.front_end->setup_chunk(c, s.chunks[c], s.bounds[c], counters);
  }
}

GridStages& grid_stages() {
  static GridStages stages = [] {
    GridStages s;
    s.scene = covrast::load_scene(std::filesystem::path(COVRAST_SOURCE_DIR) / "scenes" /
                                  "sphere_grid.json");
    return s;
  }();
  if (!stages.front_end) {
    stages.front_end =
        std::make_unique<GeometryFrontEnd>(stages.scene, stages.scene.width, stages.scene.height);
    for (std::size_t i = 0; i < stages.front_end->instance_count(); ++i) {
      stages.front_end->transform_vertices(i, 0, stages.front_end->vertex_count(i));
    }
    stages.setup_storage = std::make_unique<HugePageBuffer>(stages.front_end->triangle_count() *
                                                            sizeof(TriangleSetup));
    stages.chunks.resize(stages.front_end->chunk_count());
    stages.bounds.resize(stages.front_end->chunk_count());
    SetupCounters counters;
    setup_all_chunks(stages, counters);
  }
  return stages;
}

template <class Body>
void run_stage(benchmark::State& state, Body body) {
  GridStages* stages = nullptr;
  try {
    stages = &grid_stages();
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  for (auto _ : state) body(*stages);
  state.counters["triangles/s"] =
      benchmark::Counter(double(state.iterations()) * double(stages->scene.triangle_count()),
                         benchmark::Counter::kIsRate);
}

/// sphere_grid's aliased frame, rendered once for stage/fxaa.
const covrast::Image& grid_aliased_frame() {
  static const covrast::Image frame = [] {
    covrast::RenderOptions options;
    options.mode = covrast::parse_render_mode("aliased");
    options.threads = 1;
    return covrast::render(grid_stages().scene, options).color;
  }();
  return frame;
}

/// The whole post-process on one thread with `kernels`: luma, then filter into `output`.
void fxaa_frame(const covrast::Image& input, const covrast::FxaaOptions& options,
                const FxaaKernels& kernels, LumaPlane& luma, covrast::Image& output) {
  output.rgb = input.rgb;
  fxaa_luma_rows(input, luma, 0, input.height, kernels);
  fxaa_rows(input, luma, options, output, 0, input.height, kernels);
}

void run_fxaa(benchmark::State& state, std::int64_t target) {
  const covrast::Image* input = nullptr;
  try {
    input = &grid_aliased_frame();
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  const covrast::FxaaOptions options;
  LumaPlane luma{input->width, input->height,
                 std::vector<float>(std::size_t(input->width) * input->height)};
  covrast::Image output = *input, expected = *input;
  fxaa_frame(*input, options, fxaa_kernels_scalar(), luma, expected);
  if (target != 0) testing::force_simd_target(target);
  const FxaaKernels kernels = target != 0 ? fxaa_kernels_simd() : fxaa_kernels_scalar();
  if (target != 0) testing::force_simd_target(0);
  fxaa_frame(*input, options, kernels, luma, output);
  if (output.rgb != expected.rgb) {
    state.SkipWithError("the SIMD output differs from the scalar twin's");
    return;
  }
  for (auto _ : state) {
    fxaa_frame(*input, options, kernels, luma, output);
    benchmark::DoNotOptimize(output.rgb.data());
  }
  state.counters["pixels/s"] = benchmark::Counter(
      double(state.iterations()) * double(input->rgb.size() / 3), benchmark::Counter::kIsRate);
  std::size_t changed = 0;
  for (std::size_t i = 0; i < output.rgb.size(); i += 3) {
    changed += std::memcmp(&output.rgb[i], &input->rgb[i], 3) != 0;
  }
  state.counters["changed_pixels"] = double(changed);
}

void register_all() {
  struct Size {
    const char* name;
    double min_px, max_px;
  };
  const Size sizes[] = {{"small", 1.0, 8.0}, {"large", 8.0, 60.0}};
  for (const Size& s : sizes) {
    benchmark::RegisterBenchmark(("kernel/coverage/scalar/" + std::string(s.name)).c_str(),
                                 [s](benchmark::State& state) {
                                   run_kernel(state, coverage_rows_scalar, 0, s.min_px, s.max_px);
                                 })
        ->UseRealTime();
    const std::int64_t usable = testing::compiled_simd_targets() & hwy::SupportedTargets();
    for (std::int64_t bits = usable; bits != 0; bits &= bits - 1) {
      const std::int64_t target = bits & -bits;
      benchmark::RegisterBenchmark(
          ("kernel/coverage/simd:" + std::string(hwy::TargetName(target)) + "/" + s.name).c_str(),
          [s, target](benchmark::State& state) {
            run_kernel(state, coverage_rows_simd, target, s.min_px, s.max_px);
          })
          ->UseRealTime();
    }
  }
  for (const Size& s : sizes) {
    benchmark::RegisterBenchmark(("kernel/coverage_group/scalar/" + std::string(s.name)).c_str(),
                                 [s](benchmark::State& state) {
                                   run_cover_group(state, cover_group_scalar, 0, s.min_px,
                                                   s.max_px);
                                 })
        ->UseRealTime();
    const std::int64_t usable = testing::compiled_simd_targets() & hwy::SupportedTargets();
    for (std::int64_t bits = usable; bits != 0; bits &= bits - 1) {
      const std::int64_t target = bits & -bits;
      benchmark::RegisterBenchmark(
          ("kernel/coverage_group/simd:" + std::string(hwy::TargetName(target)) + "/" + s.name)
              .c_str(),
          [s, target](benchmark::State& state) {
            run_cover_group(state, cover_group_simd, target, s.min_px, s.max_px);
          })
          ->UseRealTime();
    }
  }

  // Sample-mode kernels: scalar, then every Highway target compiled in and supported.
  std::vector<std::pair<std::string, std::int64_t>> impls = {{"scalar", 0}};
  const std::int64_t sample_usable = testing::compiled_simd_targets() & hwy::SupportedTargets();
  for (std::int64_t bits = sample_usable; bits != 0; bits &= bits - 1) {
    const std::int64_t target = bits & -bits;
    impls.emplace_back("simd:" + std::string(hwy::TargetName(target)), target);
  }
  constexpr double kSampleMinTime = 0.05;  // seconds: many short benchmarks on 2 shared cores
  for (const SampleMode& mode : kSampleModes) {
    for (const auto& [impl, target] : impls) {
      benchmark::RegisterBenchmark(("kernel/sample/" + std::string(mode.name) + "/" + impl).c_str(),
                                   [&mode, target = target](benchmark::State& state) {
                                     run_sample_group(state, mode, target);
                                   })
          ->UseManualTime()
          ->MinTime(kSampleMinTime);
    }
  }
  for (const SampleMode& mode : kSampleModes) {
    for (const RasterSize& size : kRasterSizes) {
      for (const auto& [impl, target] : impls) {
        benchmark::RegisterBenchmark(
            ("kernel/sample_raster/" + std::string(mode.name) + "/" + impl + "/" + size.name)
                .c_str(),
            [&mode, &size, target = target](benchmark::State& state) {
              run_sample_raster(state, mode, size, target);
            })
            ->UseManualTime()
            ->MinTime(kSampleMinTime);
      }
    }
  }
  for (const SampleMode& mode : kSampleModes) {
    for (const auto& [impl, target] : impls) {
      benchmark::RegisterBenchmark(
          ("kernel/sample_resolve/" + std::string(mode.name) + "/" + impl).c_str(),
          [&mode, target = target](benchmark::State& state) {
            run_sample_resolve(state, mode, target);
          })
          ->UseRealTime()
          ->MinTime(kSampleMinTime);
    }
  }

  benchmark::RegisterBenchmark("stage/transform",
                               [](benchmark::State& state) {
                                 run_stage(state, [](GridStages& s) {
                                   for (std::size_t i = 0; i < s.front_end->instance_count(); ++i) {
                                     s.front_end->transform_vertices(i, 0,
                                                                     s.front_end->vertex_count(i));
                                   }
                                 });
                               })
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  benchmark::RegisterBenchmark("stage/setup_chunk",
                               [](benchmark::State& state) {
                                 run_stage(state, [](GridStages& s) {
                                   SetupCounters counters;
                                   setup_all_chunks(s, counters);
                                   benchmark::DoNotOptimize(counters);
                                 });
                               })
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  benchmark::RegisterBenchmark("stage/bin_chunk",
                               [](benchmark::State& state) {
                                 static std::vector<ChunkBins> bins;
                                 static std::vector<std::uint32_t> scratch;
                                 run_stage(state, [](GridStages& s) {
                                   const TileGrid grid(s.scene.width, s.scene.height, 64);
                                   bins.resize(s.bounds.size());
                                   for (std::size_t c = 0; c < s.bounds.size(); ++c)
                                     bin_chunk(grid, s.bounds[c], bins[c], scratch);
                                   benchmark::DoNotOptimize(bins.data());
                                 });
                               })
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  for (const auto& [impl, target] : impls) {
    benchmark::RegisterBenchmark(
        ("stage/fxaa/" + impl).c_str(),
        [target = target](benchmark::State& state) { run_fxaa(state, target); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  register_all();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
