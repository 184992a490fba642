// The command-line options every scene-driven service takes (scene, DDS
// vendor, domain and profile, duration, real time or lockstep), declared
// once so the services spell and document them the same way.
#pragma once

#include <string>

#include "fahr/cli/cli.h"
#include "fahr/scene/scene.h"

namespace fahr::runtime {

struct ServiceOptions {
  std::string scene_path;
  std::string dds;           // empty: FAHR_DDS, else the scene
  std::string domain;        // empty: FAHR_DOMAIN_ID, else the scene
  std::string profile;       // empty: FAHR_DDS_PROFILE, else none
  std::string security;      // empty: FAHR_DDS_SECURITY, else no DDS Security
  std::string mode;          // empty: the scene's run.mode
  double duration_s = -1.0;  // < 0: the scene's run.duration_s; 0: until SIGINT/SIGTERM
  std::string cpus;          // empty: wherever the kernel puts it (cpu_pinning.h)

  // Lockstep when --mode says so, else when the scene does.
  bool lockstep(const scene::Scene& scene) const;
  // The run's duration in seconds (0: until stopped).
  double duration_or_scene_s(const scene::Scene& scene) const;
};

// Adds --scene (required), --dds, --domain, --dds-profile, --security, --duration-s, --mode,
// --cpus.
void add_service_options(fahr::cli::App& app, ServiceOptions& options);

}  // namespace fahr::runtime
