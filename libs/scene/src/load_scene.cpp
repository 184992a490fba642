// The top level of a scene file, and the two entry points.
#include "fahr/scene/load_scene.h"

#include <fstream>
#include <sstream>

#include "parsers.h"

namespace fahr::scene {

namespace {

using detail::IssueLog;
using detail::MapReader;

void parse_header(const MapReader& top, Scene& scene) {
  IssueLog& log = top.log();
  if (top.require("format_version")) {
    top.read("format_version", kSceneFormatVersion, kSceneFormatVersion, scene.format_version);
  }
  if (top.require("name") && top.read("name", scene.name) && !detail::is_valid_name(scene.name)) {
    log.add(top.value("name").Mark(), "name",
            "'" + scene.name + "' is not a valid name: use 1-64 of A-Z a-z 0-9 _ -");
  }
  top.read("description", scene.description);
  top.read("gravity_mps2", detail::closed(-1.0e3, 1.0e3), scene.gravity_mps2);
}

std::shared_ptr<const Scene> parse_checked(std::string_view text, std::string_view display_name,
                                           const std::filesystem::path& base_dir,
                                           const LoadOptions& options) {
  IssueLog log{std::string(display_name)};
  YAML::Node root;
  try {
    root = YAML::Load(std::string(text));
  } catch (const YAML::Exception& error) {
    log.add(error.mark, "", "YAML syntax error: " + error.msg);
    log.throw_if_any();
  }
  auto scene = std::make_shared<Scene>();
  scene->source_name = std::string(display_name);
  scene->base_dir = base_dir;
  scene->source_text = std::string(text);
  if (text.size() > kMaxSceneTextBytes) {
    log.add(YAML::Mark::null_mark(), "",
            "the scene file is " + std::to_string(text.size()) +
                " bytes; SceneDescription "
                "carries at most " +
                std::to_string(kMaxSceneTextBytes));
  }
  const detail::ParseContext ctx{log, base_dir, options};
  const MapReader top(
      log, root, "",
      {"format_version", "name", "description", "run", "dds", "rates", "gravity_mps2", "bodies",
       "device", "solver", "contact", "qos", "glottic_view"});
  if (top.is_map()) {
    parse_header(top, *scene);
    scene->rates = detail::parse_rates(ctx, top);
    scene->run = detail::parse_run(ctx, top, scene->rates);
    scene->dds = detail::parse_dds(ctx, top);
    scene->bodies = detail::parse_bodies(ctx, top);
    scene->device = detail::parse_device(ctx, top, scene->bodies);
    scene->solver = detail::parse_solver(ctx, top);
    scene->contact = detail::parse_contact(ctx, top, scene->bodies);
    scene->qos = detail::parse_qos(ctx, top);
    scene->glottic_view = detail::parse_glottic_view(ctx, top, scene->bodies);
  }
  log.throw_if_any();
  return scene;
}

}  // namespace

std::shared_ptr<const Scene> parse_scene(std::string_view text, std::string_view display_name,
                                         const std::filesystem::path& base_dir,
                                         const LoadOptions& options) {
  return parse_checked(text, display_name, base_dir, options);
}

std::shared_ptr<const Scene> load_scene(const std::filesystem::path& path,
                                        const LoadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw SceneError({SceneIssue{path.string(), 0, 0, "", "cannot open the scene file"}});
  }
  std::ostringstream text;
  text << in.rdbuf();
  const std::filesystem::path absolute = std::filesystem::absolute(path).lexically_normal();
  return parse_checked(text.str(), path.string(), absolute.parent_path(), options);
}

}  // namespace fahr::scene
