// fahr_glottic_score: the glottic view score (POGO) of a scene, by lines of
// sight (fahr::glottic_view, what the visualizer publishes) and by a pixel
// count of the same view (tools/scene_render's rasterizer), side by side,
// for one blade pose or over a recording; and the laryngoscopist's picture.
//
//   fahr_glottic_score [--scene FILE] [--pose initial|pressing|X,Y,Z,PITCH]
//                     [--eye X,Y,Z | --around DEG,MM,ASIDE] [--png FILE] [--samples N]
//   fahr_glottic_score --recording RUN.mcap [--every-ms 100] [--png-prefix P]
//
// --pose: the tool's pose, a preset of meshes/neonatal/README.md or the tip
// at X,Y,Z mm turned PITCH degrees about +z (default: the scene's pose).
// --eye X,Y,Z: the eye in the world, mm, instead of the scene's eye on the
// tool. --around DEG,MM,ASIDE: the eye MM from the opening's centre, turned
// DEG from its normal towards the mouth (+x) in the mid-sagittal plane and
// ASIDE mm along +z. --anatomy-only: only the rigid anatomy in the view, no
// soft body and no tool (what the skeleton of the airway allows). --recording: the tongue and the
// tool pose of each FEM state in the file, scored every --every-ms of the run's simulated time;
// prints the rest view, the one under the blade's largest force on the tissue, the best and the
// last, each by both methods; --png-prefix P writes P_rest.png, P_pressed.png, P_best.png and
// P_last.png.
//
// A line per view: "view <label>: rays R % (seen/facing samples, its wall
// time), pixels P % (seen/drawn), difference D points". Exit 0, or 1 on an
// error (named).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

#include "contact_setPubSubTypes.h"
#include "deformation_statePubSubTypes.h"
#include "fahr/cli/cli.h"
#include "fahr/common/cdr_bytes.h"
#include "fahr/glottic_view/blade_from_contacts.h"
#include "fahr/glottic_view/scene_view.h"
#include "fahr/mcap/reader.h"
#include "fahr/scene/load_scene.h"
#include "fahr/scenegen/blade_poses.h"
#include "pixel_view.h"

namespace fahr::glottic_score {
namespace {

std::vector<double> numbers(const std::string& text, std::size_t count, const std::string& flag) {
  std::vector<double> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != item.size() || !std::isfinite(v)) {
      throw std::invalid_argument(flag + ": '" + item + "' is not a number");
    }
    out.push_back(v);
  }
  if (out.size() != count) {
    throw std::invalid_argument(flag + ": " + std::to_string(count) + " comma-separated numbers");
  }
  return out;
}

Eigen::Isometry3d pose_from(const std::string& text, const scene::Scene& scene) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  if (text.empty() || text == "scene") {
    const auto tool = scene.tool_index();
    if (tool) {
      pose.linear() = scene.bodies[*tool].pose.orientation.toRotationMatrix();
      pose.translation() = scene.bodies[*tool].pose.position_m;
    }
    return pose;
  }
  double pitch_deg = 0.0;
  Eigen::Vector3d tip_mm = Eigen::Vector3d::Zero();
  bool found = false;
  for (const auto& p : scenegen::suggested_blade_poses()) {
    if (p.name == text) {
      pitch_deg = p.pitch_deg;
      tip_mm = p.tip_mm;
      found = true;
    }
  }
  if (!found) {
    const auto v = numbers(text, 4, "--pose");
    tip_mm = Eigen::Vector3d(v[0], v[1], v[2]);
    pitch_deg = v[3];
  }
  pose.linear() = Eigen::AngleAxisd(pitch_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).matrix();
  pose.translation() = 1e-3 * tip_mm;
  return pose;
}

struct Compared {
  glottic_view::ViewScore rays;
  double rays_ms = 0.0;  // wall time of the ray-cast score
  PixelShare pixels;
};

Compared compare(glottic_view::SceneGlotticView& view, const SceneMeshes& meshes,
                 const ViewInput& in) {
  std::vector<std::span<const Eigen::Vector3d>> spans(in.deformable_positions.begin(),
                                                      in.deformable_positions.end());
  Compared c;
  const auto t0 = std::chrono::steady_clock::now();
  c.rays = view.view.score(in.eye_m, in.world_from_tool, spans);
  c.rays_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  c.pixels = pixel_share(meshes, view.view.opening(), in);
  return c;
}

void print(const std::string& label, const Compared& c, const ViewInput& in) {
  std::printf(
      "view %s: rays %.1f %% (%zu/%zu samples, %.2f ms), pixels %.1f %% (%zu/%zu), difference "
      "%.1f points; eye (%.1f, %.1f, %.1f) mm\n",
      label.c_str(), 100.0 * c.rays.visible_share, c.rays.visible, c.rays.samples, c.rays_ms,
      100.0 * c.pixels.visible_share, c.pixels.visible, c.pixels.total,
      100.0 * std::abs(c.rays.visible_share - c.pixels.visible_share), 1e3 * in.eye_m.x(),
      1e3 * in.eye_m.y(), 1e3 * in.eye_m.z());
}

void write_png(const SceneMeshes& meshes, const glottic_view::Opening& opening, const ViewInput& in,
               const std::string& path) {
  const std::string error = write_view_png(meshes, opening, in, path);
  if (!error.empty()) throw std::runtime_error(error);
  std::printf("wrote %s\n", path.c_str());
}

// One scored moment of a recording.
struct Moment {
  double t_s = 0.0;
  std::vector<Eigen::Vector3d> tongue;
  Eigen::Isometry3d world_from_tool = Eigen::Isometry3d::Identity();
  bool has_tool = false;
  double share = 0.0;
  double force_n = 0.0;  // the blade's force on the tissue (its ContactSet rows)
};

int run_recording(glottic_view::SceneGlotticView& view, const SceneMeshes& meshes,
                  const std::string& path, double every_ms, const std::string& png_prefix,
                  const Eigen::Isometry3d& scene_tool_pose) {
  if (view.deformable_body_ids.empty()) throw std::runtime_error("the scene has no soft body");
  const std::uint32_t body = view.deformable_body_ids.front();
  const std::size_t nodes = view.deformable_node_counts.front();
  msg::DeformationState state;
  msg::ContactSet contacts;
  Moment current, rest, pressed, best, last;
  // Until a ContactSet says where the blade is, it is where the scene puts it.
  current.world_from_tool = scene_tool_pose;
  current.has_tool = true;
  bool have_rest = false;
  std::int64_t t0 = -1, next = 0;
  std::size_t scored = 0, refused = 0;
  const auto every_ns = static_cast<std::int64_t>(every_ms * 1e6);
  const auto report = mcap::read_file(path, [&](const mcap::Channel& c,
                                                const mcap::MessageView& m) {
    if (c.topic == "fahr/ContactSet") {
      if (!common::decode_cdr<msg::ContactSetPubSubType>(m.data, contacts)) return;
      const glottic_view::BladeFromContacts blade = glottic_view::blade_from_contacts(contacts);
      if (!blade.world_from_tool) return;
      current.world_from_tool = *blade.world_from_tool;
      current.has_tool = true;
      current.force_n = blade.tool_force_n;
      return;
    }
    if (c.topic != "fahr/DeformationState") return;
    if (!common::decode_cdr<msg::DeformationStatePubSubType>(m.data, state)) return;
    if (state.body_id() != body) return;
    // The run's simulated time (lockstep: the clock's; real time: the wall's).
    const std::int64_t t = state.header().sim_time_ns();
    if (t0 < 0) t0 = t;
    if (t < next) return;
    next = t + every_ns;
    const auto& xyz = state.positions_m();
    if (xyz.size() != 3 * nodes) {
      ++refused;
      return;
    }
    current.tongue.resize(nodes);
    for (std::size_t i = 0; i < nodes; ++i)
      current.tongue[i] = Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    current.t_s = static_cast<double>(t - t0) * 1e-9;
    const Eigen::Vector3d eye = current.world_from_tool * view.eye_in_tool_m;
    const std::span<const Eigen::Vector3d> tongue(current.tongue);
    try {
      current.share =
          view.view
              .score(eye, current.has_tool ? std::optional(current.world_from_tool) : std::nullopt,
                     std::span(&tongue, 1))
              .visible_share;
    } catch (const std::invalid_argument&) {
      ++refused;  // a non-finite state: not scored
      return;
    }
    ++scored;
    if (!have_rest) {
      rest = current;
      have_rest = true;
    }
    if (current.share > best.share || scored == 1) best = current;
    if (current.force_n > pressed.force_n || scored == 1) pressed = current;
    last = current;
  });
  if (!report.valid()) {
    std::fprintf(stderr, "fahr_glottic_score: %s: %s (read what could be)\n", path.c_str(),
                 report.error.empty() ? "no footer or a bad CRC" : report.error.c_str());
  }
  if (scored == 0) throw std::runtime_error(path + ": no DeformationState of the soft body");
  std::printf("fahr_glottic_score: %s: %zu states scored every %.0f ms, %zu refused\n",
              path.c_str(), scored, every_ms, refused);
  const std::pair<const char*, const Moment*> moments[] = {
      {"rest", &rest}, {"pressed", &pressed}, {"best", &best}, {"last", &last}};
  for (const auto& [label, moment] : moments) {
    ViewInput in;
    in.eye_m = moment->world_from_tool * view.eye_in_tool_m;
    if (moment->has_tool) in.world_from_tool = moment->world_from_tool;
    in.deformable_positions.emplace_back(moment->tongue);
    char name[64];
    std::snprintf(name, sizeof name, "%s (t %.2f s, blade %.2f N)", label, moment->t_s,
                  moment->force_n);
    print(name, compare(view, meshes, in), in);
    if (!png_prefix.empty()) {
      write_png(meshes, view.view.opening(), in, png_prefix + "_" + label + ".png");
    }
  }
  return 0;
}

int run(int argc, char** argv) {
  fahr::cli::App app{"fahr_glottic_score: the glottic view score by lines of sight and by pixels"};
  std::string scene_path = FAHR_DEFAULT_SCENE, pose_text, eye_text, around_text, png, recording,
              png_prefix;
  std::size_t samples = 1024;
  double every_ms = 100.0;
  bool anatomy_only = false;
  app.add_option("--scene", scene_path, "scene file (its glottic_view section)");
  app.add_option("--pose", pose_text, "initial | pressing | X,Y,Z,PITCH (mm, deg about +z)");
  app.add_option("--eye", eye_text, "X,Y,Z: the eye in the world, mm (default: the scene's)");
  app.add_option("--around", around_text,
                 "DEG,MM,ASIDE: the eye MM from the opening, DEG from its normal towards the "
                 "mouth, ASIDE mm along +z")
      ->excludes("--eye");
  app.add_flag("--anatomy-only", anatomy_only,
               "only the rigid anatomy in the view: no soft body, no tool (the eye stays)");
  app.add_option("--png", png, "write the laryngoscopist's picture here");
  app.add_option("--samples", samples, "samples on the opening")
      ->check(fahr::cli::Range(16, 1 << 20));
  app.add_option("--recording", recording, "score the FEM states of this MCAP recording");
  app.add_option("--every-ms", every_ms, "score a recording this often")
      ->check(fahr::cli::Range(1.0, 1e6));
  app.add_option("--png-prefix", png_prefix,
                 "a recording's pictures: PREFIX_rest/_pressed/_best/_last.png");
  if (const auto exit = app.parse(argc, argv)) return *exit;

  const auto scene = scene::load_scene(scene_path);
  glottic_view::SceneGlotticView view = glottic_view::glottic_view_from_scene(*scene, samples);
  const SceneMeshes meshes = load_scene_meshes(*scene);
  if (!recording.empty()) {
    return run_recording(view, meshes, recording, every_ms, png_prefix, pose_from("", *scene));
  }

  ViewInput in;
  in.world_from_tool = pose_from(pose_text, *scene);
  in.eye_m = *in.world_from_tool * view.eye_in_tool_m;
  if (!eye_text.empty()) {
    const auto v = numbers(eye_text, 3, "--eye");
    in.eye_m = 1e-3 * Eigen::Vector3d(v[0], v[1], v[2]);
  }
  if (!around_text.empty()) {
    const auto v = numbers(around_text, 3, "--around");
    const glottic_view::Opening& o = view.view.opening();
    const Eigen::Vector3d towards_mouth = o.normal.cross(Eigen::Vector3d::UnitZ()).normalized();
    const double a = v[0] * M_PI / 180.0;
    in.eye_m = o.centre_m + 1e-3 * v[1] * (std::cos(a) * o.normal + std::sin(a) * towards_mouth) +
               1e-3 * v[2] * Eigen::Vector3d::UnitZ();
  }
  if (anatomy_only) {
    in.world_from_tool.reset();
  } else {
    for (const auto& rest : view.deformable_rest_m) in.deformable_positions.emplace_back(rest);
  }
  print(pose_text.empty() ? "scene" : pose_text, compare(view, meshes, in), in);
  if (!png.empty()) write_png(meshes, view.view.opening(), in, png);
  return 0;
}

}  // namespace
}  // namespace fahr::glottic_score

int main(int argc, char** argv) {
  try {
    return fahr::glottic_score::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_glottic_score: %s\n", e.what());
    return 1;
  }
}
