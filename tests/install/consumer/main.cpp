// Loads the installed neonatal scene through the installed fahr::scene.
#include <cstdio>
#include <exception>

#include "fahr/scene/load_scene.h"

int main() {
  try {
    const auto scene =
        fahr::scene::load_scene(FAHR_DATA_DIR "/deployment/scenes/neonatal_intubation.yaml");
    std::printf("fahr_consumer: scene '%s' with %zu bodies\n", scene->name.c_str(),
                scene->bodies.size());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_consumer: %s\n", e.what());
    return 1;
  }
}
