// Raster stage, sample modes: the walk over one triangle's rows and column groups
// (RasterJob, sample_kernel.hpp) that the SIMD kernel (sample_kernel.cpp, once per Highway
// target) and its scalar twin (sample_kernel_scalar.cpp) share. Each includes this file
// inside its own namespace, so that the walk is compiled for the target of the group
// functions it calls and inlines them; hence no include guard (one inclusion per namespace).
//
// Per row and per group of the rectangle, the edge functions at the group's corner bound
// its samples (c_min, c_max): a group outside some edge's reach holds none and is skipped;
// otherwise `setup()` runs once, before the first such group, and `sample(f32, z_base, out,
// written)` tests the group's samples, with f32 null when all of them are inside all edges.
// The group's depth base is z0 + dz/dx (gx - vx) + dz/dy (y - vy), in that order.

template <class Setup, class Sample>
inline void walk_triangle_groups(const GroupPattern& pattern, const RasterJob& job, Setup setup,
                                 Sample sample) {
  const std::size_t lanes = std::size_t(pattern.lanes);
  bool set_up = false;
  std::int64_t f_row[3] = {job.f[0], job.f[1], job.f[2]};
  for (int row = 0; row < job.rows; ++row) {
    const int y = job.y0 + row;
    const double z_y = job.dzdy * (double(y) - job.vy);
    std::int64_t f[3] = {f_row[0], f_row[1], f_row[2]};
    std::size_t lane = std::size_t(row) * job.row_lanes;
    for (int g = 0; g < job.groups; ++g, lane += lanes) {
      bool none = false, all_inside = true;
      std::int32_t f32[3];
      for (int e = 0; e < 3; ++e) {
        none |= f[e] + job.c_max[e] < 0;
        all_inside &= f[e] + job.c_min[e] >= 0;
        f32[e] = std::int32_t(f[e] < kEdgeClamp ? f[e] : kEdgeClamp);
        f[e] += job.step_x[e];
      }
      if (none) continue;
      if (!set_up) {
        setup();
        set_up = true;
      }
      const int gx = job.gx0 + g * pattern.group_px;
      const float z_base = float(job.z0 + job.dzdx * (double(gx) - job.vx) + z_y);
      const GroupSamples out{job.first.depth + lane, job.first.r + lane, job.first.g + lane,
                             job.first.b + lane};
      std::uint64_t written[kMaxGroupLanes / 64] = {0, 0, 0, 0};
      std::uint64_t* written_ptr = job.rgb != nullptr ? nullptr : written;
      const bool any = sample(all_inside ? nullptr : f32, z_base, out, written_ptr);
      if (any && job.rgb == nullptr) job.shade_fn(job.shade_context, gx, y, written, out);
    }
    for (int e = 0; e < 3; ++e) f_row[e] += job.step_y[e];
  }
}
