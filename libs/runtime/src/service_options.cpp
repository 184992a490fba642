// The options every scene-driven service takes (see service_options.h).
#include "fahr/runtime/service_options.h"

#include <chrono>

namespace fahr::runtime {

bool ServiceOptions::lockstep(const scene::Scene& scene) const {
  return mode.empty() ? scene.run.mode == scene::RunMode::kLockstep : mode == "lockstep";
}

double ServiceOptions::duration_or_scene_s(const scene::Scene& scene) const {
  return duration_s < 0 ? std::chrono::duration<double>(scene.run.duration).count() : duration_s;
}

void add_service_options(fahr::cli::App& app, ServiceOptions& o) {
  app.add_option("--scene", o.scene_path, "scene file")->required();
  app.add_option("--dds", o.dds, "DDS vendor: fastdds, cyclonedds, inprocess");
  app.add_option("--domain", o.domain, "DDS domain id 0-230");
  app.add_option("--dds-profile", o.profile, "vendor XML configuration");
  app.add_option("--security", o.security,
                 "DDS Security: the station's folder "
                 "(deployment/security/make_station_security.sh; default $FAHR_DDS_SECURITY)");
  app.add_option(
      "--duration-s", o.duration_s,
      "stop after this long; 0 runs until SIGINT/SIGTERM (default: the scene's run.duration_s)");
  app.add_option("--mode", o.mode, "realtime or lockstep (default: the scene's run.mode)")
      ->check(fahr::cli::IsMember({"realtime", "lockstep"}));
  app.add_option("--cpus", o.cpus,
                 "run on these CPUs only, e.g. 0 or 0-1 (default: wherever the kernel puts it)");
}

}  // namespace fahr::runtime
