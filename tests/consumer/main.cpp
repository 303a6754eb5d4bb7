// The consumer of an installed covrast (tests/consumer/CMakeLists.txt): builds a scene in
// memory, renders it and checks two pixels. Exit 0 when they are right, 1 otherwise.
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <cstdint>
#include <cstdio>

int main() {
  covrast::Scene scene;
  scene.width = 64;
  scene.height = 48;
  scene.background_linear = glm::vec3(0.0f);  // black
  // A unit triangle seen from z = 3 covers the image centre, not its corners.
  covrast::add_instance(scene,
                        covrast::make_mesh({.name = "triangle",
                                            .positions = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}},
                                            .indices = {0, 1, 2}}),
                        {.color_srgb = glm::vec3(1.0f, 0.2f, 0.0f)});
  covrast::check_scene(scene);
  const covrast::Image image = covrast::render(scene, {}).color;
  const std::uint8_t* centre = image.pixel(32, 24);
  const std::uint8_t* corner = image.pixel(0, 0);
  std::printf("covrast consumer: centre %d %d %d, corner %d %d %d\n", centre[0], centre[1],
              centre[2], corner[0], corner[1], corner[2]);
  const bool ok = centre[0] == 255 && centre[1] == 51 && centre[2] == 0 && corner[0] == 0 &&
                  corner[1] == 0 && corner[2] == 0;
  return ok ? 0 : 1;
}
