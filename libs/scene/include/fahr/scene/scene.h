// The scene: everything a run needs to know, in SI units, checked by the
// loader and immutable afterwards (services share one const instance).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fahr/scene/body.h"
#include "fahr/scene/contact_settings.h"
#include "fahr/scene/device_settings.h"
#include "fahr/scene/glottic_view_settings.h"
#include "fahr/scene/qos_override.h"
#include "fahr/scene/run_settings.h"
#include "fahr/scene/solver_settings.h"

namespace fahr::scene {

struct Scene {
  int format_version = kSceneFormatVersion;
  std::string name;  // [A-Za-z0-9_-], 1-64 chars (idl string<64>)
  std::string description;
  // Where the scene came from: the file, or a display name for parsed text.
  std::string source_name;
  // Folder relative paths in the scene are resolved against.
  std::filesystem::path base_dir;
  // The scene text as read, at most kMaxSceneTextBytes (SceneDescription).
  std::string source_text;

  RunSettings run;
  DdsSettings dds;
  Rates rates;
  Eigen::Vector3d gravity_mps2{kDefaultGravityX, kDefaultGravityY,
                               kDefaultGravityZ};  // world frame, m/s^2
  std::vector<Body> bodies;                        // in file order; pairs and device refer by index
  std::optional<DeviceSettings> device;
  FemSolverSettings solver;
  ContactSettings contact;
  std::map<std::string, QosOverride, std::less<>> qos;  // by topic name
  // The glottic view score (absent: not scored).
  std::optional<GlotticViewSettings> glottic_view;

  // Index of the body with this name, or nullopt.
  std::optional<std::size_t> find_body(std::string_view body_name) const;
  // Index of the tool body (at most one), or nullopt.
  std::optional<std::size_t> tool_index() const;
  std::size_t count(BodyRole role) const;
};

}  // namespace fahr::scene
