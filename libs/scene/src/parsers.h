// The scene schema, section by section. Each parser reads one part of the file
// through a MapReader, applies the defaults of defaults.h to what is absent,
// and logs every problem with its place instead of stopping at the first.
#pragma once

#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

#include "fahr/scene/load_scene.h"
#include "fahr/scene/scene.h"
#include "yaml_reader.h"

namespace fahr::scene::detail {

struct ParseContext {
  IssueLog& log;
  std::filesystem::path base_dir;
  LoadOptions options;

  // path resolved against base_dir (when relative), normalised.
  std::filesystem::path resolve(const std::string& path) const;
};

// Body and scene names: 1-64 of [A-Za-z0-9_-] (they travel as idl string<64>).
bool is_valid_name(std::string_view name);

std::vector<Body> parse_bodies(const ParseContext& ctx, const MapReader& top);
Rates parse_rates(const ParseContext& ctx, const MapReader& top);
RunSettings parse_run(const ParseContext& ctx, const MapReader& top, const Rates& rates);
DdsSettings parse_dds(const ParseContext& ctx, const MapReader& top);
std::optional<DeviceSettings> parse_device(const ParseContext& ctx, const MapReader& top,
                                           const std::vector<Body>& bodies);
FemSolverSettings parse_solver(const ParseContext& ctx, const MapReader& top);
ContactSettings parse_contact(const ParseContext& ctx, const MapReader& top,
                              const std::vector<Body>& bodies);
std::optional<GlotticViewSettings> parse_glottic_view(const ParseContext& ctx, const MapReader& top,
                                                      const std::vector<Body>& bodies);
std::map<std::string, QosOverride, std::less<>> parse_qos(const ParseContext& ctx,
                                                          const MapReader& top);
// A pose mapping: position_m and one of orientation_rpy_deg / orientation_quat_wxyz.
Pose parse_pose(const ParseContext& ctx, const YAML::Node& node, const std::string& path);

}  // namespace fahr::scene::detail
