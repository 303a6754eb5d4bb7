// The pipeline: the only file that knows every stage and owns the oneTBB scheduling.
//
//   scene -> [setup: transform, clip, snap]  parallel over vertex blocks, then chunks
//         -> [binning]                        parallel over chunks (counting sort per chunk)
//         -> [raster + tile resolve]          parallel over tiles, per-thread scratch
//         -> [post-process: fxaa mode only]   parallel over rows of the whole frame
//         -> image
//
// Each phase is a parallel loop over a fixed decomposition (chunks of the global triangle
// sequence, tiles of a fixed grid), and each task writes only its own output, so the image
// is the same for every thread count.
#include "binning/tile_bins.hpp"
#include "core/fork_join.hpp"
#include "core/tile_raster.hpp"
#include "geometry/frontend.hpp"
#include "post/background.hpp"
#include "post/fxaa.hpp"
#include "raster/rasterizers.hpp"

#include <covrast/renderer.hpp>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/enumerable_thread_specific.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <string>

namespace covrast {

using detail::TriangleSetup;

// The raster's buffers are sized for the API's largest tile.
static_assert(detail::kMaxTilePx == kMaxTilePx);

namespace {

using Clock = std::chrono::steady_clock;

/// How many binned triangles ahead the tile loop prefetches (each draw takes long enough for
/// a fetch from memory to arrive in time).
constexpr std::size_t kPrefetchAhead = 4;

/// A tile's triangles are scattered through their chunks: the tile loops fetch each set-up
/// (two cache lines) kPrefetchAhead triangles before drawing it.
void prefetch_setup(const detail::TriangleSetup& t) {
  const char* bytes = reinterpret_cast<const char*>(&t);
  __builtin_prefetch(bytes);
  __builtin_prefetch(bytes + 64);
}

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

/// Vertices per transform task: whole blocks, as transform_vertices requires.
constexpr std::size_t kVerticesPerBlock = detail::kVerticesPerTransformBlock;

/// Rows per post-process task: enough work per task (a 1920-pixel row is ~2000 pixel
/// tests) to hide the scheduling, small enough to balance 2..64 threads.
constexpr int kPostRowsPerTask = 8;

void check_fxaa_options(const FxaaOptions& fxaa) {
  if (!valid_fxaa_preset(fxaa.quality_preset)) {
    throw InputError("FXAA quality preset " + std::to_string(fxaa.quality_preset) +
                     " unknown: expected 10..15, 20..29 or 39");
  }
  const auto in_unit = [](float v) { return v >= 0.0f && v <= 1.0f; };  // false for NaN
  if (!in_unit(fxaa.edge_threshold) || !in_unit(fxaa.edge_threshold_min) || !in_unit(fxaa.subpix)) {
    throw InputError("FXAA edge thresholds and subpix must each lie in [0, 1]");
  }
}

/// FXAA over the finished frame: it reads a copy of the frame (the search along an edge
/// reaches up to ~20 pixels away, across tiles), so each output pixel depends on the input
/// only and any split over rows gives the same bytes. `input` and `luma` are per-frame
/// memory kept by the Renderer. Call inside the arena. The first pass copies the rows and
/// computes their luma; the second rewrites, in the frame, only the pixels FXAA blends.
void post_process_fxaa(const FxaaOptions& options, Image& input, detail::LumaPlane& luma,
                       Image& frame) {
  input.width = frame.width;
  input.height = frame.height;
  input.rgb.resize(frame.rgb.size());
  luma.width = frame.width;
  luma.height = frame.height;
  luma.luma.resize(std::size_t(frame.width) * frame.height);
  const detail::FxaaKernels kernels = detail::fxaa_kernels_simd();
  const auto rows = tbb::blocked_range<int>(0, frame.height, kPostRowsPerTask);
  detail::fork_join_for(rows, [&](const tbb::blocked_range<int>& r) {
    std::copy(frame.pixel(0, r.begin()),
              frame.pixel(0, r.begin()) + 3 * std::size_t(frame.width) * r.size(),
              input.pixel(0, r.begin()));
    detail::fxaa_luma_rows(input, luma, r.begin(), r.end(), kernels);
  });
  detail::fork_join_for(rows, [&](const tbb::blocked_range<int>& r) {
    detail::fxaa_rows(input, luma, options, frame, r.begin(), r.end(), kernels);
  });
}

}  // namespace

bool valid_fxaa_preset(int quality_preset) {
  return !detail::fxaa_search_steps(quality_preset).empty();
}

struct Renderer::Impl {
  const Scene& scene;
  RenderOptions options;
  int width_px;
  int height_px;
  int threads;
  detail::TileGrid grid;
  detail::GeometryFrontEnd front_end;
  /// Coverage mode draws each tile nearest first, unless every instance is a convex surface
  /// (set per frame by set_up_triangles; the same for every tile, so tiles agree on the order).
  bool nearest_first = false;
  /// Every chunk's set-up triangles, chunk c in its slice from triangle c * kTrianglesPerChunk:
  /// one allocation, so that a first frame faults it in as a few huge pages rather than
  /// ~7000 small ones (one frame per process is the usual command-line use).
  detail::HugePageBuffer setup_storage;
  std::vector<detail::ChunkSetups> chunk_triangles;
  std::vector<std::vector<detail::PixelBounds16>> chunk_bounds;  ///< per triangle, for binning
  std::vector<detail::ChunkBins> chunk_bins;
  detail::ThreadAllowance thread_allowance;  ///< before the arena, which it outlives
  tbb::task_arena arena;
  tbb::enumerable_thread_specific<std::vector<std::uint32_t>> bin_scratch;
  tbb::enumerable_thread_specific<std::unique_ptr<detail::TileRasterizer>> rasterizers;
  tbb::enumerable_thread_specific<detail::SetupCounters> setup_counters;
  tbb::enumerable_thread_specific<double> resolve_thread_ms;
  Image post_input;             ///< fxaa mode: the aliased frame the post-process reads
  detail::LumaPlane post_luma;  ///< fxaa mode: its luma

  Impl(const Scene& s, const RenderOptions& o, int w, int h, int t)
      : scene(s),
        options(o),
        width_px(w),
        height_px(h),
        threads(t),
        grid(w, h, o.tile),
        front_end(s, w, h, o.cull_hidden_backfaces),
        setup_storage(front_end.triangle_count() * sizeof(TriangleSetup)),
        thread_allowance(t),
        arena(t),
        rasterizers(
            [mode = o.mode, tile = o.tile] { return detail::make_tile_rasterizer(mode, tile); }) {
    chunk_triangles.resize(front_end.chunk_count());
    chunk_bounds.resize(front_end.chunk_count());
    chunk_bins.resize(front_end.chunk_count());
    // On the arena's threads, as many as the options allow.
    detail::fork_join_execute(arena, [&] { front_end.prepare_environment(); });
  }

  /// The frame's image, all zeros, and its depth (1 = far) when the options ask for it.
  RenderResult blank_result() const;
  /// The rasterizers' counters that run over the Renderer's life.
  struct LifeCounters {
    std::uint64_t overflows = 0, hidden_draws = 0;
  };
  /// Zeroes the per-frame counters; returns the life counters so far.
  LifeCounters begin_frame_counters();
  /// Setup, part 1: vertices to clip space, in fixed blocks per instance; part 2: clip,
  /// snap and set up each chunk of triangles.
  void set_up_triangles();
  /// Each chunk bins its own triangles.
  void bin_triangles();
  /// Raster and resolve, one task per range of tiles, each tile drawn from start to end by
  /// one worker's rasterizer.
  void raster_tiles(const detail::FrameTarget& target);
  /// One tile: its triangles (coverage: nearest first; the other modes in submission order,
  /// chunk by chunk), then the resolve.
  void raster_tile(detail::TileRasterizer& raster, int tile, const detail::FrameTarget& target);
  void draw_in_submission_order(detail::TileRasterizer& raster, int tile);
  /// binning/tile_bins.hpp, sort_nearest_first: the A-buffer then drops what its proven
  /// layers and closed sets hide as it arrives.
  void draw_nearest_first(detail::TileRasterizer& raster, int tile);
  /// When each stage of a frame began, and when the frame ended.
  struct StageTimes {
    Clock::time_point setup, binning, raster, post, end;
  };
  /// The counters and stage times of a frame.
  void fill_stats(RenderStats& st, const LifeCounters& before, const StageTimes& t) const;
};

RenderResult Renderer::Impl::blank_result() const {
  RenderResult result;
  result.color.width = width_px;
  result.color.height = height_px;
  result.color.rgb.assign(std::size_t(width_px) * height_px * 3, 0);
  if (options.want_depth) {
    result.depth.width = width_px;
    result.depth.height = height_px;
    result.depth.depth.assign(std::size_t(width_px) * height_px, 1.0f);
  }
  return result;
}

Renderer::Impl::LifeCounters Renderer::Impl::begin_frame_counters() {
  for (auto& c : setup_counters) c = {};
  LifeCounters before;
  for (const auto& r : rasterizers) {
    before.overflows += r->overflow_count();
    before.hidden_draws += r->hidden_draw_count();
    r->take_resolve_paths();  // what an earlier frame left
  }
  for (auto& r : resolve_thread_ms) r = 0;
  return before;
}

void Renderer::Impl::set_up_triangles() {
  nearest_first = options.mode.kind == ModeKind::Coverage && !front_end.every_instance_convex();
  std::vector<std::pair<std::size_t, std::size_t>> blocks;
  for (std::size_t i = 0; i < front_end.instance_count(); ++i) {
    for (std::size_t v = 0; v < front_end.vertex_count(i); v += kVerticesPerBlock) {
      blocks.emplace_back(i, v);
    }
  }
  detail::fork_join_for(std::size_t(0), blocks.size(), [&](std::size_t b) {
    auto [instance, begin] = blocks[b];
    std::size_t end = std::min(begin + kVerticesPerBlock, front_end.vertex_count(instance));
    front_end.transform_vertices(instance, begin, end);
  });
  detail::fork_join_for(std::uint32_t(0), front_end.chunk_count(), [&](std::uint32_t c) {
    // Room for one output per input in the chunk's slice (clipping can add more, and then
    // the chunk moves to its own array).
    chunk_triangles[c].reset(static_cast<TriangleSetup*>(setup_storage.data()) +
                                 std::size_t(c) * detail::kTrianglesPerChunk,
                             front_end.chunk_triangle_count(c));
    chunk_bounds[c].clear();
    chunk_bounds[c].reserve(front_end.chunk_triangle_count(c));
    front_end.setup_chunk(c, chunk_triangles[c], chunk_bounds[c], setup_counters.local());
  });
}

void Renderer::Impl::bin_triangles() {
  detail::fork_join_for(std::uint32_t(0), front_end.chunk_count(), [&](std::uint32_t c) {
    detail::bin_chunk(grid, chunk_bounds[c], chunk_bins[c], bin_scratch.local());
  });
}

void Renderer::Impl::raster_tiles(const detail::FrameTarget& target) {
  detail::fork_join_for(tbb::blocked_range<int>(0, grid.tile_count(), 1),
                        [&](const tbb::blocked_range<int>& r) {
                          detail::TileRasterizer& raster = *rasterizers.local();
                          for (int tile = r.begin(); tile < r.end(); ++tile) {
                            raster_tile(raster, tile, target);
                          }
                        });
}

void Renderer::Impl::draw_in_submission_order(detail::TileRasterizer& raster, int tile) {
  for (std::size_t c = 0; c < chunk_bins.size(); ++c) {
    const auto& tris = chunk_triangles[c];
    const std::span<const std::uint32_t> list = chunk_bins[c].tile(tile);
    for (std::size_t k = 0; k < list.size(); ++k) {
      if (k + kPrefetchAhead < list.size()) prefetch_setup(tris[list[k + kPrefetchAhead]]);
      raster.draw(tris[list[k]]);
    }
  }
}

void Renderer::Impl::draw_nearest_first(detail::TileRasterizer& raster, int tile) {
  thread_local std::vector<const detail::TriangleSetup*> order;
  order.clear();
  for (std::size_t c = 0; c < chunk_bins.size(); ++c) {
    for (const std::uint32_t i : chunk_bins[c].tile(tile)) order.push_back(&chunk_triangles[c][i]);
  }
  detail::sort_nearest_first(order);
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (k + kPrefetchAhead < order.size()) prefetch_setup(*order[k + kPrefetchAhead]);
    raster.draw(*order[k]);
  }
}

void Renderer::Impl::raster_tile(detail::TileRasterizer& raster, int tile,
                                 const detail::FrameTarget& target) {
  raster.begin_tile(grid.tile_rect(tile), target);
  if (nearest_first) {
    draw_nearest_first(raster, tile);
  } else {
    draw_in_submission_order(raster, tile);
  }
  // end_tile resolves; banded modes also rasterise there, and that part counts as raster.
  const double deferred = raster.deferred_raster_ms();
  Clock::time_point r0 = Clock::now();
  raster.end_tile(target);
  resolve_thread_ms.local() +=
      ms_between(r0, Clock::now()) - (raster.deferred_raster_ms() - deferred);
}

void Renderer::Impl::fill_stats(RenderStats& st, const LifeCounters& before,
                                const StageTimes& t) const {
  st.triangles_in = front_end.triangle_count();
  for (const auto& c : setup_counters) {
    st.triangles_culled += c.culled;
    st.triangles_clipped += c.clipped;
    st.triangles_backface_culled += c.backface_culled;
  }
  for (const auto& tris : chunk_triangles) st.triangles_setup += tris.size();
  for (const auto& b : chunk_bins) st.bin_entries += b.triangle_index.size();
  double resolve_total = 0;
  for (double r : resolve_thread_ms) resolve_total += r;
  for (const auto& r : rasterizers) {
    st.scratch_bytes += r->scratch_bytes();
    st.fragment_overflows += r->overflow_count();
    st.hidden_bin_entries += r->hidden_draw_count();
    st.resolve_paths += r->take_resolve_paths();
  }
  // The counters run over the Renderer's life.
  st.fragment_overflows -= before.overflows;
  st.hidden_bin_entries -= before.hidden_draws;
  st.setup_ms = ms_between(t.setup, t.binning);
  st.binning_ms = ms_between(t.binning, t.raster);
  // The tile pass interleaves raster and resolve per tile; the resolve share is the summed
  // per-thread resolve time spread over the threads that ran.
  st.resolve_ms = resolve_total / std::max(1, threads);
  st.raster_ms = std::max(0.0, ms_between(t.raster, t.post) - st.resolve_ms);
  st.post_ms = ms_between(t.post, t.end);
  st.render_ms = ms_between(t.setup, t.end);
  st.threads = threads;
  st.tile = options.tile;
}

Renderer::Renderer(const Scene& scene, const RenderOptions& options) {
  int w = options.width > 0 ? options.width : scene.width;
  int h = options.height > 0 ? options.height : scene.height;
  if (w < 1 || h < 1 || w > kMaxImageSide || h > kMaxImageSide) {
    throw InputError("image size " + std::to_string(w) + "x" + std::to_string(h) +
                     " out of range: each side must be 1.." + std::to_string(kMaxImageSide));
  }
  if (!valid_tile_px(options.tile)) {
    throw InputError("tile size " + std::to_string(options.tile) + " out of range: must be " +
                     tile_px_rule());
  }
  if (options.threads < 0 || options.threads > kMaxThreads) {
    throw InputError("thread count " + std::to_string(options.threads) +
                     " out of range: must be 0.." + std::to_string(kMaxThreads) +
                     " (0 = all cores)");
  }
  int threads = options.threads > 0 ? options.threads : tbb::info::default_concurrency();
#if !defined(NDEBUG) || defined(COVRAST_CHECKS)
  // The scene's precondition (renderer.hpp), checked where covrast checks its invariants
  // (core/checks.hpp: debug, sanitizer and checks builds): a scene that check_scene refuses is
  // an InputError naming the problem here, not undefined behaviour in a later stage.
  check_scene(scene);
#endif
  // Fail early on modes that cannot be built.
  detail::make_tile_rasterizer(options.mode, options.tile);
  if (options.mode.kind == ModeKind::Fxaa) check_fxaa_options(options.fxaa);
  impl_ = std::make_unique<Impl>(scene, options, w, h, threads);
}

Renderer::~Renderer() = default;

RenderResult Renderer::render_frame() {
  Impl& im = *impl_;
  RenderResult result = im.blank_result();
  // The background is a display colour (a clear colour), not tone-mapped (docs/shading.md).
  // A transparent or skybox background renders the frame over black, then again over white
  // (post/background.hpp): set-up and binning are shared, the tile pass runs twice.
  const bool keyed = im.scene.background_kind != BackgroundKind::Color;
  Image over_white;
  if (keyed) over_white = result.color;
  const detail::FrameTarget target{&result.color, im.options.want_depth ? &result.depth : nullptr,
                                   keyed ? glm::vec3(0.0f) : im.scene.background_linear};
  const detail::FrameTarget white_target{&over_white, nullptr, glm::vec3(1.0f)};
  const Impl::LifeCounters before = im.begin_frame_counters();
  Clock::time_point t0, t1, t2, t3, t4;
  detail::fork_join_execute(im.arena, [&] {
    t0 = Clock::now();
    im.set_up_triangles();
    t1 = Clock::now();
    im.bin_triangles();
    t2 = Clock::now();
    im.raster_tiles(target);
    if (keyed) im.raster_tiles(white_target);
    t3 = Clock::now();
    if (im.options.mode.kind == ModeKind::Fxaa) {
      post_process_fxaa(im.options.fxaa, im.post_input, im.post_luma, result.color);
      if (keyed) post_process_fxaa(im.options.fxaa, im.post_input, im.post_luma, over_white);
    }
    if (im.scene.background_kind == BackgroundKind::Transparent) {
      detail::key_transparent(result.color, over_white);
    } else if (im.scene.background_kind == BackgroundKind::Skybox) {
      detail::key_skybox(result.color, over_white,
                         detail::SkyView(im.scene, im.width_px, im.height_px),
                         detail::has_transmission(im.scene));
    }
    t4 = Clock::now();
  });
  im.fill_stats(result.stats, before, {t0, t1, t2, t3, t4});
  return result;
}

RenderResult render(const Scene& scene, const RenderOptions& options) {
  Renderer renderer(scene, options);
  return renderer.render_frame();
}

}  // namespace covrast
