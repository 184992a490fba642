// A scripted laryngoscopy on a scene with its deformable bodies, the whole
// loop in lockstep in one process (fahr::stack_sim): where the blade is,
// the force it puts on each deformable body, how far each body has moved,
// and the glottic view score (POGO) from the scene's eye, every
// --trace-every seconds; then the peaks. For a laryngoscopy that reaches
// the epiglottis on a scene where it is soft
// (bench/support/soft_epiglottis_scene.sh): README.md.
//
//   fahr_laryngoscopy_bench --scene FILE [--script NAME | --keyframes FILE] [--seconds S]
//                     [--trace-every S] [--eye-in-tool-mm X Y Z]
//
// --keyframes FILE: the hand's own keyframes instead of a script, one per
// line "t_s x_mm y_mm z_mm pitch_deg" (the blade tip in the world frame,
// the pitch about +z), '#' starts a comment: to try a motion before it
// becomes a script.
//
//   fahr_laryngoscopy_bench --scene FILE --sight-corridor DEG [DEG...] [--corridor-half-width-mm W]
//                     [--corridor-mouth-z-mm Z]
//
// No run: how far each deformable body at rest reaches above a line of
// sight from the glottic opening's centre, turned DEG from its normal
// towards the mouth in the mid-sagittal plane, within W of the mid-line
// (default 5 mm, half a Miller 1's width): what a straight blade along that
// line must press out of the way for the glottis to be seen past it.
// --corridor-mouth-z-mm Z: the strip's centre runs from the opening to z = Z
// in the mouth's plane instead (a paraglossal path: Z > 0, the right).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "fahr/cli/cli.h"
#include "fahr/common/solver_threads.h"
#include "fahr/glottic_view/blade_from_contacts.h"
#include "fahr/glottic_view/scene_view.h"
#include "fahr/scene/load_scene.h"
#include "fahr/stack_sim/stack_sim.h"

namespace {

using namespace fahr;

// The blade's rows on one body: its tool contacts (active or frozen, not the
// anatomy's, not candidates). Their force is blade_from_contacts's.
std::size_t tool_rows(const msg::ContactSet& set) {
  return static_cast<std::size_t>(
      std::count_if(set.contacts().begin(), set.contacts().end(), [](const msg::Contact& c) {
        return c.kind() != msg::CONTACT_OBSTACLE && c.state() != msg::CONSTRAINT_CANDIDATE;
      }));
}

// Body b's node positions as points, for the view.
void positions_of(const stack_sim::StackSim& sim, std::size_t b,
                  std::vector<Eigen::Vector3d>& points) {
  const auto x = sim.body(b).positions_m();
  points.resize(x.size() / 3);
  for (std::size_t n = 0; n < points.size(); ++n) {
    points[n] = Eigen::Vector3d(x[3 * n], x[3 * n + 1], x[3 * n + 2]);
  }
}

// Keyframes from a file (see the header); throws naming the file and line.
device::Trajectory read_keyframes(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error(path + ": cannot open");
  std::vector<device::Keyframe> keyframes;
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    line = line.substr(0, line.find('#'));
    std::istringstream in(line);
    double t = 0.0, x = 0.0, y = 0.0, z = 0.0, pitch = 0.0;
    if (!(in >> t)) continue;  // blank or comment
    std::string rest;
    if (!(in >> x >> y >> z >> pitch) || (in >> rest) || !std::isfinite(t + x + y + z + pitch)) {
      throw std::runtime_error(path + ":" + std::to_string(number) +
                               ": want five finite numbers: t_s x_mm y_mm z_mm pitch_deg");
    }
    keyframes.push_back({t, 1e-3 * Eigen::Vector3d(x, y, z), pitch});
  }
  try {
    return device::Trajectory(std::move(keyframes));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

// The sight-corridor table (see the header).
void print_sight_corridor(const glottic_view::SceneGlotticView& view, const scene::Scene& scene,
                          const std::vector<double>& degrees, double half_width_m,
                          double mouth_z_m) {
  const auto& opening = view.view.opening();
  std::vector<std::string> names;
  for (const auto& body : scene.bodies) {
    if (body.role == scene::BodyRole::kDeformable) names.push_back(body.name);
  }
  std::printf(
      "sight corridor: scene %s, glottic opening at (%.1f, %.1f, %.1f) mm; a strip %.1f mm either"
      " side of a centre line from the opening's z to z %.1f mm at the mouth (x = 0)\n",
      scene.name.c_str(), 1e3 * opening.centre_m.x(), 1e3 * opening.centre_m.y(),
      1e3 * opening.centre_m.z(), 1e3 * half_width_m, 1e3 * mouth_z_m);
  for (const double deg : degrees) {
    // Turn the normal about z, the way that leans it towards the mouth (+x).
    const double a = deg * std::acos(-1.0) / 180.0;
    Eigen::Vector3d sight = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) * opening.normal;
    const Eigen::Vector3d other = Eigen::AngleAxisd(-a, Eigen::Vector3d::UnitZ()) * opening.normal;
    if (other.x() > sight.x()) sight = other;
    std::printf(
        "\nline %.0f deg from the opening's normal, direction (%.3f, %.3f); at x = 0 it is"
        " at y %.1f mm\n",
        deg, sight.x(), sight.y(),
        sight.x() > 0.0
            ? 1e3 * (opening.centre_m.y() - opening.centre_m.x() * sight.y() / sight.x())
            : std::nan(""));
    std::printf("  x mm | line y mm");
    for (const auto& name : names) {
      std::printf(" | %s: top, bottom y mm, top above the line mm", name.c_str());
    }
    std::printf("\n");
    std::vector<double> most(names.size(), -1e9);
    std::vector<double> most_x(names.size(), 0.0);
    for (double x_mm = 1e3 * opening.centre_m.x(); x_mm <= 0.0; x_mm += 5.0) {
      const double x = 1e-3 * x_mm;
      if (sight.x() <= 0.0) break;
      const double line_y =
          opening.centre_m.y() + (x - opening.centre_m.x()) * sight.y() / sight.x();
      // The corridor's centre across: the opening's z there, mouth_z_m at x = 0.
      const double centre_z = opening.centre_m.z() + (mouth_z_m - opening.centre_m.z()) *
                                                         (x - opening.centre_m.x()) /
                                                         (0.0 - opening.centre_m.x());
      std::printf("%6.1f | %9.1f", x_mm, 1e3 * line_y);
      for (std::size_t b = 0; b < names.size(); ++b) {
        // The body's highest rest node in a 5 mm slab around x, near the mid-line.
        double top = -1e9;
        double bottom = 1e9;
        for (const auto& p : view.deformable_rest_m[b]) {
          if (std::abs(p.x() - x) <= 2.5e-3 && std::abs(p.z() - centre_z) <= half_width_m) {
            top = std::max(top, p.y());
            bottom = std::min(bottom, p.y());
          }
        }
        if (top < -1e8) {
          std::printf(" | %6s %6s %6s", "-", "-", "-");
          continue;
        }
        const double above = top - line_y;
        if (above > most[b]) {
          most[b] = above;
          most_x[b] = x_mm;
        }
        std::printf(" | %6.1f %6.1f %6.1f", 1e3 * top, 1e3 * bottom, 1e3 * above);
      }
      std::printf("\n");
    }
    for (std::size_t b = 0; b < names.size(); ++b) {
      if (most[b] < -1e8) continue;
      std::printf(
          "sight corridor %.0f deg: '%s' reaches %.1f mm above the line at most (x %.1f mm)\n", deg,
          names[b].c_str(), 1e3 * most[b], most_x[b]);
    }
  }
}

// What hides the glottis at the end of the run: the view from the eye at
// the blade's last pose with everything, then with the rigid anatomy and
// one occluder at a time (the blade, or one soft body; the others are left
// out by moving them a metre away), then the rigid anatomy alone.
void print_what_hides(const stack_sim::StackSim& sim, glottic_view::SceneGlotticView& view) {
  const auto blade = glottic_view::blade_from_contacts(sim.contacts(0));
  if (!blade.world_from_tool) return;
  const Eigen::Vector3d eye = *blade.world_from_tool * view.eye_in_tool_m;
  const std::size_t bodies = sim.body_count();
  std::vector<std::vector<Eigen::Vector3d>> points(bodies);
  std::vector<std::vector<Eigen::Vector3d>> away(bodies);
  for (std::size_t b = 0; b < bodies; ++b) {
    positions_of(sim, b, points[b]);
    away[b] = points[b];
    for (auto& p : away[b]) p.x() += 1.0;
  }
  // only_body: that body alone (bodies: all of them; bodies + 1: none).
  const auto score = [&](bool tool, std::size_t only_body) {
    std::vector<std::span<const Eigen::Vector3d>> spans;
    for (std::size_t b = 0; b < bodies; ++b) {
      const bool in = only_body == bodies || only_body == b;
      spans.emplace_back(in ? points[b] : away[b]);
    }
    return 100.0 *
           view.view.score(eye, tool ? blade.world_from_tool : std::nullopt, spans).visible_share;
  };
  std::printf(
      "laryngoscopy_bench: at the end, eye (%.1f, %.1f, %.1f) mm: POGO %.1f %%; with the "
      "rigid anatomy and only the blade %.1f %%",
      1e3 * eye.x(), 1e3 * eye.y(), 1e3 * eye.z(), score(true, bodies), score(true, bodies + 1));
  for (std::size_t b = 0; b < bodies; ++b) {
    std::printf(", only '%s' %.1f %%", sim.fem(b).setup().scene_body->name.c_str(),
                score(false, b));
  }
  std::printf(", nothing but the rigid anatomy %.1f %%\n", score(false, bodies + 1));
}

}  // namespace

int main(int argc, char** argv) {
  fahr::common::run_solver_libraries_on_one_thread(argv);
  cli::App app{"a scripted laryngoscopy in lockstep: forces per body, motion, glottic view"};
  std::string scene_path = FAHR_SOURCE_DIR "/deployment/scenes/neonatal_intubation.yaml";
  std::string script_name = "intubation";
  double seconds = 0.0;
  double trace_every_s = 0.5;
  std::string keyframes_path;
  std::vector<double> corridor_deg;
  double corridor_half_width_mm = 5.0;
  double corridor_mouth_z_mm = 0.0;
  std::vector<double> eye_in_tool_mm;
  app.add_option("--scene", scene_path, "scene file");
  app.add_option("--sight-corridor", corridor_deg,
                 "no run: each body's height above lines of sight this many degrees from the "
                 "glottic opening's normal")
      ->check(cli::Range(0.0, 89.0));
  app.add_option("--corridor-half-width-mm", corridor_half_width_mm,
                 "the corridor's half width about the mid-line, mm")
      ->check(cli::Range(0.1, 50.0));
  app.add_option("--eye-in-tool-mm", eye_in_tool_mm,
                 "X Y Z: the laryngoscopist's eye in the tool frame instead of the scene's, mm");
  app.add_option("--corridor-mouth-z-mm", corridor_mouth_z_mm,
                 "where the corridor crosses the mouth's plane (x = 0) across, mm (+z: the "
                 "patient's right; the paraglossal path), straight from the opening")
      ->check(cli::Range(-50.0, 50.0));
  app.add_option("--script", script_name, "the simulated hand's script")
      ->check(cli::IsMember({std::begin(device::kScriptNames), std::end(device::kScriptNames)}));
  app.add_option("--keyframes", keyframes_path, "the hand's keyframes instead of the script");
  app.add_option("--seconds", seconds, "simulated time, s; 0: the whole script")
      ->check(cli::Range(0.0, 3600.0));
  app.add_option("--trace-every", trace_every_s, "a trace row every this many seconds")
      ->check(cli::Range(0.001, 100.0));
  if (const auto exit = app.parse(argc, argv)) return *exit;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  try {
    stack_sim::StackOptions options;
    device::script_by_name(script_name, options.script);  // the option checks the name
    if (!keyframes_path.empty()) {
      options.keyframes = read_keyframes(keyframes_path);
      script_name = std::filesystem::path(keyframes_path).filename().string();
    }
    auto scene = std::make_shared<scene::Scene>(*scene::load_scene(scene_path));
    if (!corridor_deg.empty()) {
      print_sight_corridor(glottic_view::glottic_view_from_scene(*scene), *scene, corridor_deg,
                           1e-3 * corridor_half_width_mm, 1e-3 * corridor_mouth_z_mm);
      return 0;
    }
    if (seconds == 0.0) {
      seconds = options.keyframes
                    ? options.keyframes->duration().count()
                    : device::script_trajectory(options.script, 1.0, 1.0).duration().count();
    }
    stack_sim::StackSim sim(scene, options);
    auto view = glottic_view::glottic_view_from_scene(*scene);
    if (!eye_in_tool_mm.empty()) {
      if (eye_in_tool_mm.size() != 3 ||
          !std::all_of(eye_in_tool_mm.begin(), eye_in_tool_mm.end(),
                       [](double v) { return std::isfinite(v) && std::abs(v) <= 10000.0; })) {
        throw std::runtime_error("--eye-in-tool-mm: want three finite numbers within 10 m");
      }
      view.eye_in_tool_m =
          1e-3 * Eigen::Vector3d(eye_in_tool_mm[0], eye_in_tool_mm[1], eye_in_tool_mm[2]);
    }
    const std::size_t bodies = sim.body_count();
    std::vector<std::vector<Eigen::Vector3d>> points(bodies);
    std::vector<double> peak_force(bodies, 0.0);
    std::vector<double> peak_motion(bodies, 0.0);
    std::vector<std::uint64_t> touched_ticks(bodies, 0);
    double peak_total = 0.0;
    // Ticks on which the tool was wedged (the solve's tissue reaction past
    // the limit with bone's rows in it: the tissue got the limit, force
    // only), held (lost track), and the anatomy's largest push on the tool.
    std::uint64_t wedged_ticks = 0;
    std::uint64_t held_ticks = 0;
    double peak_anatomy = 0.0;
    // Where the anatomy pushed hardest: the row's surface point and normal
    // (into the anatomy), and when.
    Eigen::Vector3d anatomy_point = Eigen::Vector3d::Zero();
    Eigen::Vector3d anatomy_normal = Eigen::Vector3d::Zero();
    double anatomy_row_n = 0.0;
    double anatomy_t = 0.0;
    // Per rigid body (the haptic side keys an anatomy row by body id << 20
    // | sample): the largest push it gave the blade (the length of the sum
    // of its rows' forces on one tick) and when: the upper gum and the lips
    // take a levered blade's load.
    struct AnatomyPush {
      std::uint32_t id = 0;
      std::string name;
      Eigen::Vector3d tick_sum = Eigen::Vector3d::Zero();
      double peak_n = 0.0;
      double peak_t = 0.0;
    };
    std::vector<AnatomyPush> pushes;
    for (const scene::Body& body : scene->bodies) {
      if (body.role == scene::BodyRole::kObstacle) pushes.push_back({body.id, body.name});
    }
    double pogo_first = -1.0;
    double pogo_best = 0.0;
    double pogo_best_t = 0.0;
    const auto steps = static_cast<std::uint64_t>(std::llround(seconds * 1000.0));
    const auto trace_steps =
        std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(trace_every_s * 1e3)));
    std::printf("laryngoscopy_bench: scene %s, script %s, %.1f s, %zu deformable bodies\n",
                scene->name.c_str(), script_name.c_str(), seconds, bodies);
    std::printf("  t s | blade tip mm (x, y, z) | hand - blade mm | |F| N");
    for (std::size_t b = 0; b < bodies; ++b) {
      std::printf(" | %s: F N, rows, moved mm", sim.fem(b).setup().scene_body->name.c_str());
    }
    std::printf(" | POGO %%\n");
    for (std::uint64_t k = 1; k <= steps; ++k) {
      sim.step();
      for (std::size_t b = 0; b < bodies; ++b) {
        const double force = glottic_view::blade_from_contacts(sim.contacts(b)).tool_force_n;
        peak_force[b] = std::max(peak_force[b], force);
        if (tool_rows(sim.contacts(b)) > 0) ++touched_ticks[b];
      }
      const auto& report = sim.haptic().response().report();
      if (report.tissue_force_clamped) ++wedged_ticks;
      if (sim.command().lost_track()) ++held_ticks;
      peak_anatomy = std::max(peak_anatomy, report.obstacle_reaction_n);
      const auto& solver = sim.haptic().response().solver();
      for (AnatomyPush& push : pushes) push.tick_sum.setZero();
      for (std::size_t i = 0; i < solver.size(); ++i) {
        if (solver.row(i).kind != contact::RowKind::kObstacle) continue;
        const std::uint32_t body_id = solver.row(i).id >> 20;
        for (AnatomyPush& push : pushes) {
          if (push.id == body_id) push.tick_sum -= solver.lambda(i) * solver.row(i).normal;
        }
        if (solver.lambda(i) > anatomy_row_n) {
          anatomy_row_n = solver.lambda(i);
          anatomy_point = solver.row(i).other_point_m;
          anatomy_normal = solver.row(i).normal;
          anatomy_t = sim.time_s();
        }
      }
      for (AnatomyPush& push : pushes) {
        if (push.tick_sum.norm() > push.peak_n) {
          push.peak_n = push.tick_sum.norm();
          push.peak_t = sim.time_s();
        }
      }
      const auto& f = sim.command().force_n();
      const double total = Eigen::Vector3d(f.x(), f.y(), f.z()).norm();
      peak_total = std::max(peak_total, total);
      if (k % trace_steps != 0 && k != 1) continue;
      const auto blade = glottic_view::blade_from_contacts(sim.contacts(0));
      std::vector<std::span<const Eigen::Vector3d>> spans;
      std::vector<double> moved(bodies);
      for (std::size_t b = 0; b < bodies; ++b) {
        moved[b] = sim.largest_node_motion_m(b);
        positions_of(sim, b, points[b]);
        peak_motion[b] = std::max(peak_motion[b], moved[b]);
        spans.emplace_back(points[b]);
      }
      double pogo = 0.0;
      Eigen::Vector3d tip = Eigen::Vector3d::Zero();
      if (blade.world_from_tool) {
        tip = blade.world_from_tool->translation();
        const Eigen::Vector3d eye = *blade.world_from_tool * view.eye_in_tool_m;
        pogo = 100.0 * view.view.score(eye, blade.world_from_tool, spans).visible_share;
      }
      if (pogo_first < 0.0) pogo_first = pogo;
      if (pogo > pogo_best) {
        pogo_best = pogo;
        pogo_best_t = sim.time_s();
      }
      const auto& gap = sim.command().device_minus_proxy_m();
      std::printf("%5.2f | %6.1f %6.1f %5.1f | %5.1f %5.1f %5.1f | %5.2f", sim.time_s(),
                  1e3 * tip.x(), 1e3 * tip.y(), 1e3 * tip.z(), 1e3 * gap.x(), 1e3 * gap.y(),
                  1e3 * gap.z(), total);
      for (std::size_t b = 0; b < bodies; ++b) {
        std::printf(" | %5.2f %3zu %5.2f",
                    glottic_view::blade_from_contacts(sim.contacts(b)).tool_force_n,
                    tool_rows(sim.contacts(b)), 1e3 * moved[b]);
      }
      std::printf(" | %5.1f\n", pogo);
    }
    std::printf(
        "laryngoscopy_bench: peak |F| %.3f N; POGO at the start %.1f %%, best %.1f %% at %.2f s\n",
        peak_total, pogo_first, pogo_best, pogo_best_t);
    print_what_hides(sim, view);
    std::printf(
        "laryngoscopy_bench: anatomy's push on the blade at most %.3f N; ticks wedged between "
        "anatomy and tissue (the tissue given the limit, force only) %llu, held (lost track) "
        "%llu\n",
        peak_anatomy, static_cast<unsigned long long>(wedged_ticks),
        static_cast<unsigned long long>(held_ticks));
    std::printf(
        "laryngoscopy_bench: the anatomy's largest row %.3f N at %.2f s, at (%.1f, %.1f, %.1f) mm, "
        "pushing the blade along (%.2f, %.2f, %.2f)\n",
        anatomy_row_n, anatomy_t, 1e3 * anatomy_point.x(), 1e3 * anatomy_point.y(),
        1e3 * anatomy_point.z(), -anatomy_normal.x(), -anatomy_normal.y(), -anatomy_normal.z());
    std::printf("laryngoscopy_bench: the largest push on the blade per rigid body:");
    for (const AnatomyPush& push : pushes) {
      if (push.peak_n > 0.0)
        std::printf(" %s %.3f N at %.2f s;", push.name.c_str(), push.peak_n, push.peak_t);
    }
    std::printf("\n");
    for (std::size_t b = 0; b < bodies; ++b) {
      std::printf(
          "laryngoscopy_bench: body '%s': peak tool force %.3f N, ticks touched %llu, largest node "
          "motion %.2f mm, max inverted elements %llu, resets %llu\n",
          sim.fem(b).setup().scene_body->name.c_str(), peak_force[b],
          static_cast<unsigned long long>(touched_ticks[b]), 1e3 * peak_motion[b],
          static_cast<unsigned long long>(sim.fem(b).inverted_max()),
          static_cast<unsigned long long>(sim.fem(b).divergence_resets()));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_laryngoscopy_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
