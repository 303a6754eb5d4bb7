// Raster stage, aliased mode: the scalar twin of the depth-test kernel (aliased_kernel.hpp).
#include "raster/aliased/aliased_kernel.hpp"

namespace covrast::detail {

void raster_aliased_scalar(const TriangleSetup& t, const PixelRect& r, const AliasedTile& tile,
                           std::uint64_t id) {
  const AliasedJob job = make_aliased_job(t, r, tile, id);
  std::int64_t row[3] = {job.e[0], job.e[1], job.e[2]};
  for (int j = 0; j < job.height; ++j) {
    const double zy = job.dzdy * ((job.y0 + j + 0.5) - job.vy);
    double* depth = job.depth + std::size_t(j) * job.stride;
    std::uint64_t* owner = job.owner + std::size_t(j) * job.stride;
    std::int64_t e0 = row[0], e1 = row[1], e2 = row[2];
    for (int i = 0; i < job.width; ++i) {
      if ((e0 | e1 | e2) >= 0) {
        const double px = (job.x0 + i) + 0.5;
        const float z = float(job.z0 + job.dzdx * (px - job.vx) + zy);
        if (z < depth[i]) {
          depth[i] = z;
          owner[i] = job.id;
        }
      }
      e0 += job.step_x[0];
      e1 += job.step_x[1];
      e2 += job.step_x[2];
    }
    for (int k = 0; k < 3; ++k) row[k] += job.step_y[k];
  }
}

}  // namespace covrast::detail
