// Stage benchmarks below the frame level:
//   kernel/coverage/scalar/<size>          coverage_rows_scalar, the reference twin
//   kernel/coverage/simd:<target>/<size>   coverage_rows_simd forced to each Highway target
//                                          compiled in and supported by this CPU
//   stage/transform, stage/setup_chunk, stage/bin_chunk   on sphere_grid at 1920x1080
//
// The kernel runs on realistic inputs: random triangles inside a 64 x 64 tile, set up group
// by group of kColumnGroup columns exactly as the coverage rasterizer does, and the kernel is
// called for the top and bottom partial runs of each group (the interior run needs no
// kernel). <size> is "small" (1-8 px, like sphere_grid) or "large" (8-60 px).
#include "binning/tile_bins.hpp"
#include "geometry/frontend.hpp"
#include "raster/coverage_kernel.hpp"

#include <covrast/scene.hpp>

#include <benchmark/benchmark.h>
#include <hwy/targets.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <exception>
#include <filesystem>
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

void run_kernel(benchmark::State& state, CoverageRowsFn kernel, std::int64_t target, double min_px,
                double max_px) {
  if (target != 0) force_coverage_kernel_target(target);
  state.SetLabel(target != 0 ? coverage_kernel_target_name() : "scalar");
  const std::vector<KernelJob> jobs = make_kernel_jobs(min_px, max_px, 1234);
  constexpr std::size_t kStride = kColumnGroup * 2;
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
  if (target != 0) force_coverage_kernel_target(0);
  const double n = double(state.iterations());
  state.counters["columns/s"] =
      benchmark::Counter(n * double(columns), benchmark::Counter::kIsRate);
  state.counters["pixels/s"] = benchmark::Counter(n * double(pixels), benchmark::Counter::kIsRate);
}

/// sphere_grid and its front end, built once for the stage benchmarks.
struct GridStages {
  covrast::Scene scene;
  std::unique_ptr<GeometryFrontEnd> front_end;
  std::vector<std::vector<TriangleSetup>> chunks;
};

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
    stages.chunks.resize(stages.front_end->chunk_count());
    SetupCounters counters;
    for (std::uint32_t c = 0; c < stages.front_end->chunk_count(); ++c) {
      stages.front_end->setup_chunk(c, stages.chunks[c], counters);
    }
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
    const std::int64_t usable = coverage_kernel_targets() & hwy::SupportedTargets();
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
                                   for (std::uint32_t c = 0; c < s.front_end->chunk_count(); ++c) {
                                     s.chunks[c].clear();
                                     s.front_end->setup_chunk(c, s.chunks[c], counters);
                                   }
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
                                   bins.resize(s.chunks.size());
                                   for (std::size_t c = 0; c < s.chunks.size(); ++c)
                                     bin_chunk(grid, s.chunks[c], bins[c], scratch);
                                   benchmark::DoNotOptimize(bins.data());
                                 });
                               })
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
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
