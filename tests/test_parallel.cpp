// Tests of for_each_in_parallel (include/covrast/renderer.hpp): every index runs exactly once
// on at most the threads asked for, frames rendered inside it are the frames rendered alone,
// and an exception thrown by one call reaches the caller.
#include <covrast/error.hpp>
#include <covrast/renderer.hpp>
#include <covrast/tools.hpp>

#include <catch2/catch.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <atomic>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "test_meshes.hpp"

TEST_CASE("for_each_in_parallel runs every index once, on at most the threads asked for",
          "[pipeline][parallel][threads]") {
  std::vector<std::atomic<int>> runs(1000);
  std::mutex mutex;
  std::set<std::thread::id> workers;
  covrast::for_each_in_parallel(runs.size(), 2, [&](std::size_t i) {
    ++runs[i];
    const std::lock_guard<std::mutex> lock(mutex);
    workers.insert(std::this_thread::get_id());
  });
  for (std::size_t i = 0; i < runs.size(); ++i) REQUIRE(runs[i] == 1);
  CHECK(workers.size() <= 2);
  CHECK_THROWS_AS(covrast::for_each_in_parallel(1, -1, [](std::size_t) {}), covrast::InputError);
}

TEST_CASE("for_each_in_parallel: frames rendered inside it, and exceptions",
          "[pipeline][parallel][threads]") {
  covrast::Scene scene = covrast::test::pixel_scene(48, 32);
  scene.meshes.push_back({});
  scene.meshes.back().mesh = covrast::test::uv_sphere(12, 24);
  scene.meshes.back().model = glm::scale(glm::dmat4(1.0), glm::dvec3(12.0));
  scene.meshes.back().color_source = covrast::ColorSource::PerTriangle;
  covrast::RenderOptions options;
  const covrast::Image alone = covrast::render(scene, options).color;
  options.threads = 1;
  std::vector<covrast::Image> frames(6);
  covrast::for_each_in_parallel(
      frames.size(), 0, [&](std::size_t i) { frames[i] = covrast::render(scene, options).color; });
  for (const covrast::Image& frame : frames) CHECK(frame.rgb == alone.rgb);

  std::atomic<int> started{0};
  CHECK_THROWS_WITH(covrast::for_each_in_parallel(100, 1,
                                                  [&](std::size_t i) {
                                                    ++started;
                                                    if (i == 3) throw std::runtime_error("case 3");
                                                  }),
                    "case 3");
  CHECK(started < 100);  // one thread, in order: the calls after the failure are skipped
}
