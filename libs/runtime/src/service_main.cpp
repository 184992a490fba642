// Error reporting shared by the service mains.
#include "fahr/runtime/service_main.h"

#include <cstdio>
#include <exception>

#include "fahr/common/config_error.h"
#include "fahr/geometry/load_error.h"
#include "fahr/scene/scene_error.h"

namespace fahr::runtime {

int run_service_main(const char* service_name, int (*run)(int argc, char** argv), int argc,
                     char** argv) {
  try {
    return run(argc, argv);
  } catch (const scene::SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const geometry::LoadError& e) {
    std::fprintf(stderr, "%s: %s\n", service_name, e.what());
    return 2;
  } catch (const common::ConfigError& e) {
    std::fprintf(stderr, "%s: %s\n", service_name, e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", service_name, e.what());
    return 1;
  }
}

}  // namespace fahr::runtime
