// Raster stage, sample-based modes: the sub-pixel sample positions (docs/supersampling.md).
// Every pixel uses the same pattern, so the image is deterministic and a pixel's samples
// depend only on its integer position.
#pragma once

#include <cstdint>
#include <vector>

namespace covrast::detail {

/// Sample offsets from a pixel's top-left corner in units of 1/unit pixel, each in
/// [0, unit); sample s is (x[s], y[s]).
struct SamplePattern {
  std::int32_t unit = 256;
  std::vector<std::int32_t> x;
  std::vector<std::int32_t> y;
  int size() const { return int(x.size()); }
};

/// Correlated multi-jittered sampling (Kensler 2013), n x n samples snapped to the grid
/// of 1/unit pixel (requires unit >= n^2). Sample s = j n + i lies in coarse cell (i, j)
/// of the n x n grid, and its fine column i n + sy(j) and fine row j n + sx(i) (sx, sy
/// seeded permutations) are all distinct: one sample in each of the n^2 columns and n^2
/// rows of width 1/n^2 (n-rooks). Fine cell k spans the integers [a(k), a(k + 1)),
/// a(k) = floor(k unit / n^2), and the sample takes a hashed jitter inside it.
SamplePattern cmj_pattern(int n, std::int32_t unit, std::uint32_t seed);

/// ssaa:N, the default supersampling pattern: the ordered grid, ssaa_grid_pattern(n). Of the
/// patterns measured it has the lowest RMSE of the coverage of a straight edge over all
/// angles and positions, and on the benchmark scenes (docs/supersampling.md).
SamplePattern ssaa_pattern(int n);
/// ssaa-grid:N: the ordered grid ((i + 0.5) / n, (j + 0.5) / n), rounded to 1/256 pixel.
SamplePattern ssaa_grid_pattern(int n);
/// ssaa-cmj:N: cmj_pattern(n, 256, fixed seed). With 256 / n^2 an integer (n = 1, 2, 4, 8,
/// 16) every coarse and fine cell has the same size.
SamplePattern ssaa_cmj_pattern(int n);
/// msaa:K: the Direct3D 11 standard positions for K = 2, 4, 8, 16 (1/16 pixel units from
/// the centre, so exact in 1/256).
SamplePattern msaa_pattern(int k);

/// The reference mode: cmj_pattern(64, 2^20, fixed seed).
inline constexpr int kReferenceGrid = 64;
inline constexpr std::int32_t kReferenceUnit = std::int32_t(1) << 20;
SamplePattern reference_pattern();

}  // namespace covrast::detail
