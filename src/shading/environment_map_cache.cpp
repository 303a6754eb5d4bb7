// The process-wide cache of prepared environment maps (shading/environment_lighting.hpp).
// Preparing a map (its pyramids and seven prefiltered nodes) costs about 1 s of CPU time for
// a 1k map whatever the image size, and a golden runner or a test suite renders many images
// under one map. The key is the map's contents, not its address: a kept entry holds a copy of
// the texels it was built from and matches only a map of the same size whose texels have the
// same bits, so a map changed in place, or freed and its address reused, is never served a
// stale preparation.
#include "shading/environment_lighting.hpp"

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <mutex>
#include <utility>

namespace covrast::detail {
namespace {

/// The copies of texels the cache may keep [bytes]; the least recently used entries go first.
/// A map larger than this alone is prepared each time and not kept.
constexpr std::size_t kCacheBudgetBytes = std::size_t(256) << 20;

struct CacheEntry {
  EnvironmentMap texels;  ///< what `prepared` was built from
  std::shared_ptr<const PreparedEnvironmentMap> prepared;
};

struct Cache {
  std::mutex mutex;
  std::vector<CacheEntry> entries;  ///< most recently used first
  EnvironmentMapCacheCounts counts;
};

Cache& cache() {
  static Cache instance;
  return instance;
}

std::size_t texel_bytes(const EnvironmentMap& map) {
  return map.radiance_linear.size() * sizeof(glm::vec3);
}

bool same_texels(const EnvironmentMap& a, const EnvironmentMap& b) {
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "texels compared as packed floats");
  return a.width == b.width && a.height == b.height &&
         a.radiance_linear.size() == b.radiance_linear.size() &&
         std::memcmp(a.radiance_linear.data(), b.radiance_linear.data(), texel_bytes(a)) == 0;
}

/// The kept preparation of `map`, moved to the front, or null. Caller holds the mutex.
std::shared_ptr<const PreparedEnvironmentMap> find(Cache& c, const EnvironmentMap& map) {
  for (std::size_t i = 0; i < c.entries.size(); ++i) {
    if (!same_texels(c.entries[i].texels, map)) continue;
    std::rotate(c.entries.begin(), c.entries.begin() + std::ptrdiff_t(i),
                c.entries.begin() + std::ptrdiff_t(i) + 1);
    return c.entries.front().prepared;
  }
  return nullptr;
}

}  // namespace

std::shared_ptr<const PreparedEnvironmentMap> prepare_environment_map(const EnvironmentMap& map) {
  Cache& c = cache();
  {
    const std::lock_guard<std::mutex> lock(c.mutex);
    if (auto kept = find(c, map)) {
      ++c.counts.hits;
      return kept;
    }
  }
  // Prepared outside the lock: the preparation runs parallel loops, and a thread waiting in
  // them may pick up another render's task that asks this cache for a map.
  auto prepared = std::make_shared<const PreparedEnvironmentMap>(map);
  const std::lock_guard<std::mutex> lock(c.mutex);
  ++c.counts.preparations;
  if (auto kept = find(c, map)) return kept;  // another thread prepared it meanwhile
  if (texel_bytes(map) > kCacheBudgetBytes) return prepared;
  c.entries.insert(c.entries.begin(), CacheEntry{map, prepared});
  std::size_t bytes = 0, keep = 0;
  while (keep < c.entries.size() &&
         bytes + texel_bytes(c.entries[keep].texels) <= kCacheBudgetBytes) {
    bytes += texel_bytes(c.entries[keep].texels);
    ++keep;
  }
  c.entries.resize(keep);
  return prepared;
}

EnvironmentMapCacheCounts environment_map_cache_counts() {
  const std::lock_guard<std::mutex> lock(cache().mutex);
  return cache().counts;
}

}  // namespace covrast::detail
