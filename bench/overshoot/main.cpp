// fahr_overshoot_bench: the paper's Figure 7 on the neonatal tongue. The
// simulated hand (the gateway's overshoot script) presses the blade into the
// tongue until its pull reaches 3x the device's peak force, holds 5 s and
// lets go; the whole loop (gateway, haptic service, FEM service) runs in
// lockstep in this process (sim/stack_sim). Printed side by side: the
// force-aware response and the penalty baseline on the same script.
//
//   fahr_overshoot_bench [--scene FILE] [--factor 3] [--response both|force-aware|penalty]
//                        [--youngs-pa E] [--tool-stops scene|on|off] [--stiffening C20/C10]
//                        [--volume-floor R] [--w-normals N] [--held-proxy load|stay|limit]
//                        [--fem-anatomy on|off] [--fem-support RATIO] [--fem-anatomy-rounds N]
//                        [--candidate-margin-mm M] [--trace FILE] [--tick-trace FILE] [--check]
//
// --youngs-pa, --tool-stops, --stiffening, --volume-floor, --w-normals and
// --held-proxy load|stay change the scene's keys. --held-proxy limit,
// --fem-anatomy off, --fem-support, --fem-anatomy-rounds and
// --candidate-margin-mm rerun a comparison against a choice the services do
// not offer (stack_sim::Experiments; docs/design/retired-modes.md).
// --stiffening: the tongue's compression stiffening, the Yeoh ratio C20/C10
// (libs/fem compression_stiffening.h; 0: off), instead of the scene's.
// --trace: one CSV line per FEM step of each run (FILE with the response's
// name appended): inversions and where they are, the anatomy projection,
// the tool's contacts, the largest principal Green strain, the elements past
// twice their rest length and the most strained one.
//
// --check: exit 1 unless the force-aware run meets the targets
// (no NaN, no inverted tet, the device lost track for at least 4 s of the
// 5 s hold, the tool's push on the tissue as the FEM
// applied it within the limit + 5 % while lost track, the tissue reaching
// at most 0.5 mm deeper into the held blade than when it froze, no strain
// growth from 1x to 3x, no element stretched to twice its rest length at 1x
// or at the end of the hold, the published gap equal to
// (commanded - limit) / K_c, the re-engagement force step within the
// bound, the tongue within 1 mm of where the blade found it 1 s after the
// blade leaves it). --check-release: the targets for any tet mesh only (no
// FEM step diverged, no tet inverted after the blade left, the tongue within
// 1 mm of where the blade found it 1 s later). --check-hold: those and the
// hold's, all of --check but no inverted tet and no torn element while the
// blade presses (which the shipped tongue does not meet at every pull).
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iterator>
#include <limits>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "fahr/bench_support/results_file.h"
#include "fahr/cli/cli.h"
#include "fahr/common/solver_threads.h"
#include "fahr/common/tool_row_forces.h"
#include "fahr/common/wire_eigen.h"
#include "fahr/fem/strain.h"
#include "fahr/geometry/tet_deformation.h"
#include "fahr/geometry/tet_quality.h"
#include "fahr/scene/load_scene.h"
#include "fahr/stack_sim/stack_sim.h"

namespace {

using namespace fahr;

// The overshoot script's keyframes (libs/device/src/trajectory.cpp).
constexpr double kHoldEndS = 10.5;  // the hand starts to let go
constexpr double kScriptEndS = 14.5;
// Re-engagement: the catching-up bound of docs/design/force-aware-decision.md,
// K_c (|dx_d| + v_c dt) + B (|dv_d| + v_c) for the scene's coupling and a
// hand at the script's speed; recomputed here from the run's own figures.
constexpr double kCatchUpSpeedMps = 0.05;

struct Result {
  const char* name = "";
  double limit_n = 0.0;
  double max_commanded_n = 0.0;
  double max_reaction_n = 0.0;
  double max_reaction_lost_ratio = 0.0;  // reaction / limit while lost track (as sent)
  // Measured on the FEM side, per FEM step on a ContactSet sent while lost
  // track: the tool's push on the tissue (fem::ContactStep::tool_reaction_n)
  // over the limit, and how much deeper the tissue reached into the held
  // blade than when it froze (nodes' depth in the blade's field at the
  // proxy's pose). The same push of a step on the last set before the hold,
  // taken while the device was already lost, apart.
  double max_fem_reaction_lost_ratio = 0.0;
  // The same ratio, per FEM step on a held set: the first (the step that
  // meets the freeze) and all of them, for the hold's median and smallest.
  // The paper's hold keeps the tissue as the freeze left it, so its push
  // stays what it was then, relative to the limit.
  double fem_reaction_first_held_ratio = 0.0;
  std::vector<double> fem_reaction_held_ratios;
  double max_fem_reaction_transition_ratio = 0.0;
  double max_fem_reaction_n = 0.0;
  double max_flow_into_held_m = 0.0;
  double strain_1x = 0.0, strain_3x = 0.0;
  // Elements stretched beyond kTornStrain at 1x and at the end of the hold,
  // and where the most strained one lay at 1x.
  int torn_1x = 0, torn_3x = 0;
  int torn_1x_light = 0;       // torn at 1x with a node under kLightNode x the median node's mass
  int torn_1x_fixed = 0;       // torn at 1x with a node fixed to bone
  int torn_1x_held = 0;        // torn at 1x with the free node of a held tet (three nodes fixed)
  int light_elements = 0;      // elements with such a node
  int torn_1x_near_bone = 0;   // torn at 1x with a node within kNearM of a bone
  int torn_1x_near_blade = 0;  // ... with its centroid within kNearM of the blade
  Eigen::Vector3d worst_1x_rest_mm = Eigen::Vector3d::Zero();
  double worst_1x_lightest_mass = 0.0;  // its lightest node's mass / the median node's
  double max_gap_error_m = 0.0;         // while lost track at the device's peak limit
  double max_held_drift_m = 0.0;        // the held proxy's largest distance from where it froze
  std::uint64_t lost_ticks_at_peak = 0;
  double max_reengage_step_n = 0.0;
  double reengage_bound_n = 0.0;
  double max_penetration_m = 0.0;
  // The ContactSet's tool rows on one tick: the largest sum of their forces
  // and their resultant then. Far apart, the rows squeeze the tissue from
  // both faces of the blade (a pinch: docs/design/force-aware-decision.md).
  double max_row_force_sum_n = 0.0;
  double row_resultant_at_max_sum_n = 0.0;
  // Per tick, contacts within the row margin that were not rows, and per
  // FEM step the largest node motion (m) and whether that node went back
  // against its motion of the step before: while pressing at half the limit
  // or more before the device first lost track, and while it had lost track.
  std::vector<double> dropped_pressing, dropped_lost;
  std::vector<double> motion_pressing_m, motion_lost_m;
  std::uint64_t reversed_pressing = 0, reversed_lost = 0;
  // The tool rows' force centre's move from one FEM state to the next (m, at
  // the first tick of each state whose rows push, against the state before),
  // in the same two windows: the load going from one part of the blade to
  // another.
  std::vector<double> centre_move_pressing_m, centre_move_lost_m;
  double max_anatomy_depth_m = 0.0;  // deepest node into bone before the FEM moved it out
  int max_inverted = 0;
  double max_elastic_j = 0.0;
  // 1 s after the blade left the tongue: the largest node's distance from
  // its rest position, and from where it was when the blade first touched
  // (the tongue as it lay under gravity: the check's reference).
  double displacement_after_m = -1.0;
  double displacement_after_from_found_m = -1.0;
  int max_inverted_after_left = 0;  // inverted tets in any FEM step after the blade left
  std::uint64_t lost_ticks = 0;
  bool finite = true;
  std::uint64_t divergence_resets = 0;  // FEM steps that diverged and reset the tongue to rest
  std::uint64_t anatomy_returned = 0,
                anatomy_beyond_steps = 0;  // the FEM's bone rules (service_step.h)
  double wall_s = 0.0;
  // Wall time of the base steps that ran a FEM step (the FEM step, the
  // haptic tick and its digest together: an upper bound of the FEM's), ms.
  double fem_base_step_mean_ms = 0.0, fem_base_step_max_ms = 0.0;
  // Thread-CPU time of the FEM service's step alone, ms.
  double fem_cpu_median_ms = 0.0, fem_cpu_p99_ms = 0.0, fem_cpu_max_ms = 0.0;
  // Per tet: inverted after some FEM step of the run; inverted at its end.
  std::vector<std::uint8_t> ever_inverted, inverted_at_end;
  // Per rest radius ratio class (kRadiusRatioEdges): the mesh's tets and
  // those of them ever inverted and inverted at the end.
  std::vector<std::size_t> class_tets, class_inverted, class_inverted_at_end;
};

// Rest radius ratio classes (3 inradius / circumradius; a regular tet has 1,
// a sliver near 0): are the tets that invert the mesh's poor ones?
constexpr double kRadiusRatioEdges[] = {0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0};
constexpr std::size_t kRadiusRatioClasses = std::size(kRadiusRatioEdges) - 1;

std::size_t radius_ratio_class(double ratio) {
  std::size_t c = 0;
  while (c + 1 < kRadiusRatioClasses && ratio >= kRadiusRatioEdges[c + 1]) ++c;
  return c;
}

// Marks the tets inverted in the body's current state (its elements are the
// mesh's tets, in order).
void mark_inverted(const fem::Body& body, std::vector<std::uint8_t>& marks) {
  const fem::ElementRest& rest = body.element_rest();
  const double* x = body.positions_m().data();
  for (std::size_t e = 0; e < rest.size(); ++e) {
    if (geometry::deformation_gradient(x, rest.tets[e], rest.dm_inv[e]).determinant() <= 0.0)
      marks[e] = 1;
  }
}

// The mesh's tets by rest radius ratio class, and those ever inverted.
void count_by_radius_ratio(const geometry::TetMesh& mesh, Result& r) {
  r.class_tets.assign(kRadiusRatioClasses, 0);
  r.class_inverted.assign(kRadiusRatioClasses, 0);
  r.class_inverted_at_end.assign(kRadiusRatioClasses, 0);
  const auto& rest = mesh.rest_positions();
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
    const auto& t = mesh.tets()[e];
    const std::size_t c = radius_ratio_class(
        geometry::tet_shape(rest[t[0]], rest[t[1]], rest[t[2]], rest[t[3]]).radius_ratio);
    ++r.class_tets[c];
    if (r.ever_inverted[e] != 0) ++r.class_inverted[c];
    if (r.inverted_at_end[e] != 0) ++r.class_inverted_at_end[c];
  }
}

void print_radius_ratio_table(const Result& r) {
  const std::vector<std::size_t>& tets = r.class_tets;
  const std::vector<std::size_t>& inverted = r.class_inverted;
  std::printf(
      "\n| rest radius ratio | tets | inverted after some FEM step (force-aware) | share of the "
      "class |"
      " inverted at the end of the run |\n|---|---:|---:|---:|---:|\n");
  for (std::size_t c = 0; c < kRadiusRatioClasses; ++c) {
    std::printf(
        "| [%.2f, %.2f%s | %zu | %zu | %.1f %% | %zu |\n", kRadiusRatioEdges[c],
        kRadiusRatioEdges[c + 1], c + 1 == kRadiusRatioClasses ? "]" : ")", tets[c], inverted[c],
        tets[c] > 0 ? 100.0 * static_cast<double>(inverted[c]) / static_cast<double>(tets[c]) : 0.0,
        r.class_inverted_at_end[c]);
  }
}

// The held tool's push on the tissue over the hold (Result's held ratios):
// median and smallest, 0 when the device never lost track.
struct HeldLoad {
  double median = 0.0, smallest = 0.0;
};

HeldLoad held_load(const Result& r) {
  HeldLoad held;
  if (r.fem_reaction_held_ratios.empty()) return held;
  std::vector<double> sorted = r.fem_reaction_held_ratios;
  std::sort(sorted.begin(), sorted.end());
  held.median = sorted[sorted.size() / 2];
  held.smallest = sorted.front();
  return held;
}

// The q-quantile of `values` (the element at floor(q n), 0 for none).
double quantile_of(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto at =
      std::min(values.size() - 1, static_cast<std::size_t>(q * static_cast<double>(values.size())));
  const auto it = values.begin() + static_cast<std::ptrdiff_t>(at);
  std::nth_element(values.begin(), it, values.end());
  return *it;
}

// The median of `values` (0 for none).
double median_of(std::vector<double> values) {
  return quantile_of(std::move(values), 0.5);
}

// A point's signed distance from the blade at the proxy's pose, m (< 0
// inside).
double blade_distance_at(const stack_sim::StackSim& sim, const Eigen::Vector3d& x) {
  const auto& proxy = sim.command().world_from_proxy();
  const Eigen::Quaterniond q = common::to_eigen(proxy.orientation());
  const Eigen::Vector3d t = common::to_eigen(proxy.position_m());
  return sim.haptic_setup().tool->sdf->query(q.conjugate() * (x - t)).distance_m;
}

// A point's signed distance from the nearest bone, m (< 0 inside).
double bone_distance_at(const stack_sim::StackSim& sim, const Eigen::Vector3d& x) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& field : sim.fem().setup().anatomy)
    nearest = std::min(nearest, field->sample(x).distance_m);
  return nearest;
}

// Where the tool rows' forces act: their plane points weighted by force, m
// (zero, and `pushing` false, without a pushing row). Its moves from one FEM
// state to the next say which part of the blade the rows are on.
struct RowCentre {
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  bool pushing = false;
};

RowCentre row_force_centre(const msg::ContactSet& contacts) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double total = 0.0;
  for (const auto& c : contacts.contacts()) {
    if (c.kind() == msg::CONTACT_OBSTACLE || !(c.force_n() > 0.0)) continue;
    sum += c.force_n() * common::to_eigen(c.point_m());
    total += c.force_n();
  }
  if (!(total > 0.0)) return {};
  return {.centre_m = sum / total, .pushing = true};
}

// The tongue's deepest node inside the blade at the proxy's pose, m (0 when
// none is inside).
double deepest_in_blade_m(const stack_sim::StackSim& sim) {
  const fem::Body& body = sim.body();
  double deepest = 0.0;
  for (std::uint32_t n = 0; n < body.node_count(); ++n)
    deepest = std::max(deepest, -blade_distance_at(sim, body.position(n)));
  return deepest;
}

// Node n's position after the FEM's implicit step, before any projection.
Eigen::Vector3d free_position(const stack_sim::StackSim& sim, std::uint32_t n) {
  const auto x = sim.fem().contact_step().free_positions_m();
  const std::size_t i = 3 * std::size_t{n};
  return {x[i], x[i + 1], x[i + 2]};
}

// The largest node motion of one FEM step (the trace's columns).
struct StepMotion {
  double largest_m = 0.0;
  std::uint32_t node = 0;
  bool reversed = false;
};

double max_displacement_m(const fem::Body& body) {
  double largest = 0.0;
  for (std::uint32_t n = 0; n < body.node_count(); ++n) {
    largest = std::max(largest, (body.position(n) - body.rest_position(n)).norm());
  }
  return largest;
}

// The largest node's distance from `from` (one position per node).
double max_displacement_m(const fem::Body& body, const std::vector<Eigen::Vector3d>& from) {
  double largest = 0.0;
  for (std::uint32_t n = 0; n < body.node_count(); ++n) {
    largest = std::max(largest, (body.position(n) - from[n]).norm());
  }
  return largest;
}

// Inverted tets now, and how many of them lie within `near_m` of the
// anatomy (a node that close to a bone's surface, or inside) and of the
// blade at the proxy's pose (the tet's centroid).
struct Inversions {
  int count = 0;
  int near_anatomy = 0;
  int near_blade = 0;
  double worst_rest_radius_ratio =
      1.0;  // of the inverted tets at rest: are they the mesh's slivers?
};

// Whether element e has a node within near_m of a bone, and its centroid
// within near_m of the blade (at the proxy's pose).
std::pair<bool, bool> near_bone_and_blade(const stack_sim::StackSim& sim, std::size_t e,
                                          double near_m) {
  const fem::Body& body = sim.body();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double nearest_bone = std::numeric_limits<double>::infinity();
  for (const auto node : body.element_rest().tets[e]) {
    const Eigen::Vector3d x = body.position(node);
    centroid += 0.25 * x;
    nearest_bone = std::min(nearest_bone, bone_distance_at(sim, x));
  }
  return {nearest_bone < near_m, blade_distance_at(sim, centroid) < near_m};
}

Inversions locate_inversions(const stack_sim::StackSim& sim, double near_m) {
  Inversions out;
  const fem::Body& body = sim.body();
  const geometry::TetMesh& mesh = sim.tongue_mesh();
  const fem::ElementRest& elements = body.element_rest();
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
    const auto& tet = mesh.tets()[e];
    if (geometry::deformation_gradient(body.positions_m().data(), elements.tets[e],
                                       elements.dm_inv[e])
            .determinant() > 0.0)
      continue;
    ++out.count;
    const auto& rest = mesh.rest_positions();
    out.worst_rest_radius_ratio = std::min(
        out.worst_rest_radius_ratio,
        geometry::tet_shape(rest[tet[0]], rest[tet[1]], rest[tet[2]], rest[tet[3]]).radius_ratio);
    const auto [bone, blade] = near_bone_and_blade(sim, e, near_m);
    out.near_anatomy += bone ? 1 : 0;
    out.near_blade += blade ? 1 : 0;
  }
  return out;
}

// Inverted tets of the FEM's free motion (the implicit step before any
// projection): inversions the projection did not make.
int inverted_free(const stack_sim::StackSim& sim) {
  return fem::inverted_element_count(sim.body().element_rest(),
                                     sim.fem().contact_step().free_positions_m());
}

struct ToolContacts {
  int active = 0, frozen = 0, force_only = 0, obstacle = 0;
  // The tool's entries' forces summed as magnitudes, and the largest, N:
  // against their resultant they show rows that cancel (a squeeze).
  double force_sum_n = 0.0, largest_force_n = 0.0;
};

ToolContacts count_contacts(const msg::ContactSet& set) {
  ToolContacts c;
  for (const auto& contact : set.contacts()) {
    if (contact.kind() != msg::CONTACT_OBSTACLE) {
      c.force_sum_n += contact.force_n();
      c.largest_force_n = std::max(c.largest_force_n, contact.force_n());
    }
    if (contact.kind() == msg::CONTACT_OBSTACLE) {
      ++c.obstacle;
    } else if (contact.kind() == msg::CONTACT_FORCE_ONLY) {
      ++c.force_only;
    } else if (contact.state() == msg::CONSTRAINT_FROZEN) {
      ++c.frozen;
    } else if (contact.state() == msg::CONSTRAINT_ACTIVE) {
      ++c.active;
    }
  }
  return c;
}

// What a run varies (the command line's choices).
struct RunChoices {
  double factor = 3.0;
  bool fem_anatomy = true;
  double support_ratio = -1.0;  // < 0: the service's
  double youngs_pa = 0.0;       // 0: the scene's
  double stiffening = -1.0;     // < 0: the scene's
  std::string tool_stops = "scene";
  int fem_anatomy_rounds = 0;  // 0: the FEM's
  std::string held_proxy = "scene";
  double candidate_margin_mm = -1.0;
  int w_normals = 0;
  double volume_floor = -1.0;  // < 0: the scene's
  std::string trace_path;
  std::string tick_trace_path;
};

// PREFIX.<response>.csv with its header line; null when PREFIX is empty.
std::FILE* open_trace(const std::string& prefix, const std::string& response, const char* header) {
  if (prefix.empty()) return nullptr;
  const std::string path = prefix + "." + response + ".csv";
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (file == nullptr) throw std::runtime_error("cannot write " + path);
  std::fputs(header, file);
  return file;
}

// A principal Green strain of 1.5 is a stretch to twice the rest length:
// tissue under a blade pressed at the device's limit does not tear like
// that (an estimate: no source gives the tongue's limit).
constexpr double kTornStrain = 1.5;

struct StrainSurvey {
  int beyond = 0;         // elements past kTornStrain
  int beyond_light = 0;   // ... of which with a node lighter than kLightNode x the median node
  int beyond_fixed = 0;   // ... of which with a node fixed to bone
  int beyond_held = 0;    // ... with a free node of a held tet (three nodes fixed)
  int light = 0;          // elements with such a node, torn or not
  std::size_t worst = 0;  // the most strained element
  double largest = 0.0;
  double worst_lightest = 0.0;  // the worst element's lightest node's mass / the median node's
};

// A node this much lighter than the median node takes a correction of its
// sphere's centre far larger than the centre's (the mass-weighted spread,
// contact-contract.md).
constexpr double kLightNode = 0.25;

// Where the torn elements lie: this close (m) to a bone or to the blade.
constexpr double kNearM = 1e-3;

// Elements past kTornStrain with a node within kNearM of a bone, and with
// their centroid within kNearM of the blade.
std::pair<int, int> torn_near_bone_and_blade(const stack_sim::StackSim& sim) {
  const fem::Body& body = sim.body();
  const fem::ElementRest& elements = body.element_rest();
  std::pair<int, int> count{0, 0};
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const double strain = fem::principal_green_strain(geometry::deformation_gradient(
        body.positions_m().data(), elements.tets[e], elements.dm_inv[e]));
    if (!(strain > kTornStrain)) continue;
    const auto [bone, blade] = near_bone_and_blade(sim, e, kNearM);
    count.first += bone ? 1 : 0;
    count.second += blade ? 1 : 0;
  }
  return count;
}

StrainSurvey survey_strain(const fem::Body& body) {
  StrainSurvey out;
  const auto& rest = body.element_rest();
  const auto x = body.positions_m();
  const auto mass = body.mass_kg();
  std::vector<double> sorted(mass.begin(), mass.end());
  const auto middle = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
  std::nth_element(sorted.begin(), middle, sorted.end());
  const double median = *middle;
  const auto lightest = [&](std::size_t e) {
    double m = std::numeric_limits<double>::infinity();
    for (const std::uint32_t n : rest.tets[e]) m = std::min(m, mass[n] / median);
    return m;
  };
  // Fixed nodes have no inverse mass. A held tet has three: its fourth, free
  // node is the apex over a face of the attachment.
  const auto inverse_mass = body.inverse_mass_per_kg();
  const auto fixed_in = [&](std::size_t e) {
    int count = 0;
    for (const std::uint32_t n : rest.tets[e]) count += inverse_mass[n] == 0.0 ? 1 : 0;
    return count;
  };
  const auto any_fixed = [&](std::size_t e) { return fixed_in(e) > 0; };
  std::vector<std::uint8_t> held_apex(body.node_count(), 0);
  for (std::size_t e = 0; e < rest.size(); ++e) {
    if (fixed_in(e) != 3) continue;
    for (const std::uint32_t n : rest.tets[e])
      if (inverse_mass[n] != 0.0) held_apex[n] = 1;
  }
  const auto next_to_held = [&](std::size_t e) {
    return std::any_of(rest.tets[e].begin(), rest.tets[e].end(),
                       [&](std::uint32_t n) { return held_apex[n] != 0; });
  };
  for (std::size_t e = 0; e < rest.size(); ++e) {
    const double strain = fem::principal_green_strain(
        geometry::deformation_gradient(x.data(), rest.tets[e], rest.dm_inv[e]));
    const bool light = lightest(e) < kLightNode;
    out.light += light ? 1 : 0;
    if (strain > kTornStrain) {
      out.beyond_fixed += any_fixed(e) ? 1 : 0;
      out.beyond_held += next_to_held(e) ? 1 : 0;
      ++out.beyond;
      out.beyond_light += light ? 1 : 0;
    }
    if (strain > out.largest) {
      out.largest = strain;
      out.worst = e;
    }
  }
  out.worst_lightest = lightest(out.worst);
  return out;
}

Result run(const std::shared_ptr<const scene::Scene>& scene, bool penalty,
           const RunChoices& choices) {
  const double factor = choices.factor;
  const double youngs_pa = choices.youngs_pa;
  const double stiffening = choices.stiffening;
  const std::string& tool_stops = choices.tool_stops;
  const std::string& trace_path = choices.trace_path;
  const std::string& tick_trace_path = choices.tick_trace_path;
  auto variant = std::make_shared<scene::Scene>(*scene);
  variant->contact.response =
      penalty ? scene::ContactResponse::kPenalty : scene::ContactResponse::kForceAware;
  if (tool_stops != "scene") variant->contact.tool_stops_at_anatomy = tool_stops == "on";
  if (choices.held_proxy == "load") variant->contact.held_proxy = scene::HeldProxy::kLoad;
  if (choices.held_proxy == "stay") variant->contact.held_proxy = scene::HeldProxy::kStay;
  if (youngs_pa > 0.0) {
    for (auto& body : variant->bodies) {
      if (body.deformable) body.deformable->material.youngs_modulus_pa = youngs_pa;
    }
  }
  if (stiffening >= 0.0) {
    for (auto& body : variant->bodies) {
      if (body.deformable) body.deformable->material.yeoh_c20_over_c10 = stiffening;
    }
  }
  if (choices.volume_floor >= 0.0) variant->solver.volume_floor_ratio = choices.volume_floor;
  if (choices.w_normals > 0) {
    variant->solver.compliance_columns = scene::ComplianceColumns::kNormals;
    variant->solver.max_candidate_contacts = choices.w_normals;
  }
  const auto start = std::chrono::steady_clock::now();
  stack_sim::StackOptions options;
  options.script = device::Script::kOvershoot;
  options.overshoot_factor = factor;
  stack_sim::Experiments& experiments = options.experiments;
  experiments.haptic_side_anatomy = !choices.fem_anatomy;
  if (choices.support_ratio >= 0.0) experiments.fem_support_ratio = choices.support_ratio;
  experiments.back_off_held_proxy = choices.held_proxy == "limit";
  if (choices.candidate_margin_mm >= 0.0)
    experiments.candidate_margin_m = 1e-3 * choices.candidate_margin_mm;
  experiments.fem_anatomy_rounds = choices.fem_anatomy_rounds;
  stack_sim::StackSim sim(variant, options);
  Result r;
  r.name = penalty ? "penalty" : "force-aware";
  r.ever_inverted.assign(sim.tongue_mesh().tet_count(), 0);
  std::FILE* trace = open_trace(
      trace_path, r.name,
      "t_s,inverted,inverted_near_anatomy,inverted_near_blade,anatomy_nodes,anatomy_depth_mm,"
      "anatomy_unresolved,anatomy_rounds,sweeps,tool_active,tool_frozen,force_only,obstacle_"
      "contacts,"
      "lost_track,reaction_n,commanded_n,max_displacement_mm,inverted_worst_rest_radius_ratio,"
      "inverted_free,fem_cpu_ms,supported_nodes,"
      "volume_floor_below,volume_floor_unresolved,tool_force_sum_n,tool_largest_force_n,"
      "fem_tool_reaction_n,fem_tool_projection_n,largest_strain,torn,worst_element,"
      "step_motion_mm,step_motion_node,step_motion_reversed,step_motion_blade_mm,step_motion_free_"
      "blade_mm,step_motion_bone_mm\n");
  std::FILE* tick_trace = open_trace(
      tick_trace_path, r.name,
      "t_s,lost_track,force_n,fx,fy,fz,reaction_n,hand_x,hand_y,hand_z,proxy_x,proxy_y,"
      "proxy_z,gap_mm,"
      "limit_n,state,catch_up_limited,yielded,implausible_step,tissue_force_clamped,"
      "obstacle_reaction_n,rows,"
      "pgs_converged,contacts_found,fem_step,pgs_sweeps,missing_compliance,row_force_sum_n,rows_"
      "dropped,row_centre_x_mm,row_centre_y_mm,row_centre_z_mm\n");
  const double k_c = sim.haptic_setup().response.coupling.stiffness_npm;
  const double damping = sim.haptic_setup().response.coupling.damping_nspm;
  bool seen_1x = false, was_lost = false, reengaged = false, left = false, touched = false;
  double set_limit = 0.0;  // the limit at the tick whose ContactSet the FEM applies next
  std::vector<Eigen::Vector3d> found(sim.body().node_count());  // the tongue the blade found
  std::uint64_t reengaged_step = 0, left_step = 0;
  Eigen::Vector3d freeze_proxy = Eigen::Vector3d::Zero(), previous_force = Eigen::Vector3d::Zero();
  double depth_at_freeze_m = 0.0;  // set when a lost-track spell begins
  Eigen::Vector3d previous_hand = Eigen::Vector3d::Zero(),
                  previous_hand_v = Eigen::Vector3d::Zero();
  const auto steps = static_cast<std::uint64_t>((kScriptEndS + 1.5) * 1000.0);
  // The trace's step motion: each node's position and motion at the FEM
  // step before.
  std::vector<Eigen::Vector3d> last_positions, last_motions;
  double fem_step_total_ms = 0.0;
  std::uint64_t fem_steps = 0;
  std::uint64_t dropped_before = 0;
  std::uint64_t centre_state = std::numeric_limits<std::uint64_t>::max();
  RowCentre last_centre;
  for (std::uint64_t k = 0; k < steps; ++k) {
    const auto step_start = std::chrono::steady_clock::now();
    sim.step();
    if (sim.fem_stepped()) {
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - step_start)
              .count();
      fem_step_total_ms += ms;
      ++fem_steps;
      r.fem_base_step_max_ms = std::max(r.fem_base_step_max_ms, ms);
    }
    const msg::ForceCommand& c = sim.command();
    const msg::DevicePose& pose = sim.pose();
    const double limit = pose.renderable_force_n();
    r.limit_n = std::max(r.limit_n, limit);
    const Eigen::Vector3d force = common::to_eigen(c.force_n());
    const Eigen::Vector3d gap = common::to_eigen(c.device_minus_proxy_m());
    const Eigen::Vector3d hand = common::to_eigen(c.answered_position_m());
    r.finite = r.finite && force.allFinite() && gap.allFinite();
    const double commanded = penalty ? force.norm() : k_c * gap.norm();
    r.max_commanded_n = std::max(r.max_commanded_n, commanded);
    const common::ToolRowForces rows_sent = common::tool_row_forces(sim.contacts());
    // Contacts within the row margin that were not rows, this tick.
    const std::uint64_t dropped =
        sim.haptic().metrics().rows_dropped.load(std::memory_order_relaxed);
    const std::uint64_t dropped_tick = dropped - dropped_before;
    dropped_before = dropped;
    const RowCentre row_centre = row_force_centre(sim.contacts());
    if (tick_trace != nullptr) {
      const Eigen::Vector3d proxy = common::to_eigen(c.world_from_proxy().position_m());
      const contact::TickReport& report = sim.haptic().response().report();
      std::fprintf(tick_trace,
                   "%.3f,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%d,%d,"
                   "%d,%d,%d,%.4f,%d,%d,%u,%llu,%d,%d,%.4f,%llu,%.3f,%.3f,%.3f\n",
                   sim.time_s(), c.lost_track() ? 1 : 0, force.norm(), force.x(), force.y(),
                   force.z(), c.tissue_reaction_n(), 1e3 * hand.x(), 1e3 * hand.y(), 1e3 * hand.z(),
                   1e3 * proxy.x(), 1e3 * proxy.y(), 1e3 * proxy.z(), 1e3 * gap.norm(), limit,
                   static_cast<int>(report.state), report.catch_up_limited ? 1 : 0,
                   report.yielded ? 1 : 0, report.implausible_step ? 1 : 0,
                   report.tissue_force_clamped ? 1 : 0, report.obstacle_reaction_n,
                   static_cast<int>(report.load.rows), report.pgs.converged ? 1 : 0,
                   sim.haptic().last_phases().tissue_query.contacts,
                   static_cast<unsigned long long>(sim.contacts().fem_step()), report.pgs.sweeps,
                   report.load.missing_compliance, rows_sent.magnitudes_n,
                   static_cast<unsigned long long>(dropped_tick), 1e3 * row_centre.centre_m.x(),
                   1e3 * row_centre.centre_m.y(), 1e3 * row_centre.centre_m.z());
    }
    // Pressing at half the limit or more, before the device first lost track.
    const bool pressing_before_hold =
        !penalty && r.lost_ticks == 0 && !c.lost_track() && commanded >= 0.5 * limit && limit > 0.0;
    if (pressing_before_hold) r.dropped_pressing.push_back(static_cast<double>(dropped_tick));
    if (!penalty && c.lost_track()) r.dropped_lost.push_back(static_cast<double>(dropped_tick));
    if (!penalty && sim.contacts().fem_step() != centre_state) {
      centre_state = sim.contacts().fem_step();
      if (row_centre.pushing && last_centre.pushing) {
        const double move = (row_centre.centre_m - last_centre.centre_m).norm();
        if (pressing_before_hold) r.centre_move_pressing_m.push_back(move);
        if (c.lost_track()) r.centre_move_lost_m.push_back(move);
      }
      last_centre = row_centre;
    }
    r.max_reaction_n = std::max(r.max_reaction_n, c.tissue_reaction_n());
    for (const auto& contact : sim.contacts().contacts()) {
      if (contact.kind() == msg::CONTACT_OBSTACLE) continue;
      r.max_penetration_m = std::max(r.max_penetration_m, contact.penetration_m());
      if (!touched && contact.state() != msg::CONSTRAINT_CANDIDATE) {
        touched = true;
        for (std::uint32_t n = 0; n < sim.body().node_count(); ++n)
          found[n] = sim.body().position(n);
      }
    }
    if (rows_sent.magnitudes_n > r.max_row_force_sum_n) {
      r.max_row_force_sum_n = rows_sent.magnitudes_n;
      r.row_resultant_at_max_sum_n = rows_sent.resultant_n.norm();
    }
    if (!penalty) {
      if (!seen_1x && commanded >= limit && limit > 0.0) {
        seen_1x = true;
        const StrainSurvey survey = survey_strain(sim.body());
        r.strain_1x = survey.largest;
        r.torn_1x = survey.beyond;
        r.torn_1x_light = survey.beyond_light;
        r.torn_1x_fixed = survey.beyond_fixed;
        r.torn_1x_held = survey.beyond_held;
        r.light_elements = survey.light;
        std::tie(r.torn_1x_near_bone, r.torn_1x_near_blade) = torn_near_bone_and_blade(sim);
        r.worst_1x_lightest_mass = survey.worst_lightest;
        for (const std::uint32_t n : sim.body().element_rest().tets[survey.worst])
          r.worst_1x_rest_mm += 1e3 / 4.0 * sim.body().rest_position(n);  // centroid, mm
      }
      // A FEM step applies the ContactSet of the tick before (StackSim::step):
      // the held tool's push is that of steps on sets the haptic side sent
      // while it had lost track, against the limit it then rendered. The
      // step on the last set before the hold is the free tool's; it is
      // counted apart (max_fem_reaction_transition_ratio).
      if (sim.fem_stepped() && (was_lost || c.lost_track())) {
        const double fem_reaction = sim.fem().contact_step().tool_reaction_n().norm();
        if (was_lost) {
          r.max_fem_reaction_lost_ratio =
              std::max(r.max_fem_reaction_lost_ratio, fem_reaction / set_limit);
          if (r.fem_reaction_held_ratios.empty())
            r.fem_reaction_first_held_ratio = fem_reaction / set_limit;
          r.fem_reaction_held_ratios.push_back(fem_reaction / set_limit);
          r.max_flow_into_held_m =
              std::max(r.max_flow_into_held_m, deepest_in_blade_m(sim) - depth_at_freeze_m);
        } else {
          r.max_fem_reaction_transition_ratio =
              std::max(r.max_fem_reaction_transition_ratio, fem_reaction / set_limit);
        }
      }
      if (c.lost_track()) {
        ++r.lost_ticks;
        if (!was_lost) {
          freeze_proxy = common::to_eigen(c.world_from_proxy().position_m());
          depth_at_freeze_m = deepest_in_blade_m(sim);
        }
        r.max_reaction_lost_ratio =
            std::max(r.max_reaction_lost_ratio, c.tissue_reaction_n() / limit);
        r.max_held_drift_m =
            std::max(r.max_held_drift_m,
                     (common::to_eigen(c.world_from_proxy().position_m()) - freeze_proxy).norm());
        // |gap| = L/K_c + (F_cmd - L)/K_c with F_cmd = K_c |x_d - p_freeze|:
        // the proxy stays where it froze. That holds while the device can
        // render its peak force; once the gateway lowers the limit (the Touch
        // X's continuous force, services/device_gateway), the proxy must back
        // off to keep the tissue within the new limit, and the freeze point
        // no longer gives the gap (the held drift below shows how far).
        if (limit >= r.limit_n) {
          ++r.lost_ticks_at_peak;
          const double f_cmd = k_c * (hand - freeze_proxy).norm();
          r.max_gap_error_m = std::max(
              r.max_gap_error_m, std::abs(gap.norm() - (limit / k_c + (f_cmd - limit) / k_c)));
        }
      }
      if (was_lost && !c.lost_track()) {
        reengaged = true;
        reengaged_step = k;
      }
      was_lost = c.lost_track();
      set_limit = limit;
      const Eigen::Vector3d hand_v = common::to_eigen(pose.linear_velocity_mps());
      if (reengaged && k >= reengaged_step && k < reengaged_step + 50) {
        r.max_reengage_step_n = std::max(r.max_reengage_step_n, (force - previous_force).norm());
        const double bound = k_c * ((hand - previous_hand).norm() + kCatchUpSpeedMps * 1e-3) +
                             damping * ((hand_v - previous_hand_v).norm() + kCatchUpSpeedMps);
        r.reengage_bound_n = std::max(r.reengage_bound_n, bound);
      }
      previous_hand_v = hand_v;
    }
    previous_force = force;
    previous_hand = hand;
    if (sim.time_s() >= kHoldEndS && r.strain_3x == 0.0) {
      const StrainSurvey survey = survey_strain(sim.body());
      r.strain_3x = survey.largest;
      r.torn_3x = survey.beyond;
    }
    if (sim.fem_stepped()) {
      const fem::StepReport& report = sim.fem().last_report();
      r.max_fem_reaction_n =
          std::max(r.max_fem_reaction_n, sim.fem().contact_step().tool_reaction_n().norm());
      r.max_inverted = std::max(r.max_inverted, report.inverted_elements);
      if (left)
        r.max_inverted_after_left = std::max(r.max_inverted_after_left, report.inverted_elements);
      mark_inverted(sim.body(), r.ever_inverted);
      r.max_elastic_j = std::max(r.max_elastic_j, sim.body().energy().elastic_j);
      r.max_anatomy_depth_m = std::max(r.max_anatomy_depth_m, report.projection.obstacle_deepest_m);
      // The node that moved most in this FEM step, and whether it went
      // back against its own motion of the step before (a tissue that
      // rocks step to step, not one that settles).
      if (last_positions.empty()) {
        last_positions.resize(sim.body().node_count());
        last_motions.assign(sim.body().node_count(), Eigen::Vector3d::Zero());
        for (std::uint32_t n = 0; n < sim.body().node_count(); ++n)
          last_positions[n] = sim.body().position(n);
      }
      StepMotion motion;
      for (std::uint32_t n = 0; n < sim.body().node_count(); ++n) {
        const Eigen::Vector3d moved = sim.body().position(n) - last_positions[n];
        if (moved.norm() > motion.largest_m) {
          motion.largest_m = moved.norm();
          motion.node = n;
          motion.reversed = moved.dot(last_motions[n]) < 0.0;
        }
        last_motions[n] = moved;
        last_positions[n] = sim.body().position(n);
      }
      if (pressing_before_hold) {
        r.motion_pressing_m.push_back(motion.largest_m);
        r.reversed_pressing += motion.reversed ? 1 : 0;
      } else if (c.lost_track()) {
        r.motion_lost_m.push_back(motion.largest_m);
        r.reversed_lost += motion.reversed ? 1 : 0;
      }
      if (trace != nullptr) {
        // 1 mm: a tet that close to bone or blade is pressed by it.
        const Inversions inv = locate_inversions(sim, 1e-3);
        const ToolContacts tc = count_contacts(sim.contacts());
        const StrainSurvey survey = survey_strain(sim.body());
        std::fprintf(
            trace,
            "%.3f,%d,%d,%d,%d,%.3f,%d,%d,%d,%d,%d,%d,%d,%d,%.4f,%.4f,%.3f,%.3f,%d,%.3f,%d,"
            "%d,%d,%.3f,"
            "%.3f,%.4f,%.4f,%.3f,%d,%zu,%.4f,%u,%d,%.4f,%.4f,%.4f\n",
            sim.time_s(), inv.count, inv.near_anatomy, inv.near_blade,
            report.projection.obstacle_nodes, 1e3 * report.projection.obstacle_deepest_m,
            report.projection.obstacle_unresolved, report.projection.obstacle_rounds,
            report.projection.sweeps, tc.active, tc.frozen, tc.force_only, tc.obstacle,
            c.lost_track() ? 1 : 0, c.tissue_reaction_n(), commanded,
            1e3 * max_displacement_m(sim.body()), inv.worst_rest_radius_ratio, inverted_free(sim),
            1e-6 * static_cast<double>(sim.last_fem_step_cpu().count()),
            report.projection.obstacle_supported, report.projection.volume_floor_below,
            report.projection.volume_floor_unresolved, tc.force_sum_n, tc.largest_force_n,
            sim.fem().contact_step().tool_reaction_n().norm(),
            sim.fem().contact_step().projection().tool_push_kg_m.norm() /
                (sim.body().time_step_s() * sim.body().time_step_s()),
            survey.largest, survey.beyond, survey.worst, 1e3 * motion.largest_m, motion.node,
            motion.reversed ? 1 : 0, 1e3 * blade_distance_at(sim, sim.body().position(motion.node)),
            1e3 * blade_distance_at(sim, free_position(sim, motion.node)),
            1e3 * bone_distance_at(sim, sim.body().position(motion.node)));
      }
    }
    // The blade has left the tongue: no tool contact in the set after the hold.
    if (!left && sim.time_s() > kHoldEndS) {
      bool touching = false;
      for (const auto& contact : sim.contacts().contacts()) {
        touching = touching || (contact.kind() != msg::CONTACT_OBSTACLE &&
                                contact.state() != msg::CONSTRAINT_CANDIDATE);
      }
      if (!touching) {
        left = true;
        left_step = k;
      }
    }
    if (left && k == left_step + 1000) {
      r.displacement_after_m = max_displacement_m(sim.body());
      r.displacement_after_from_found_m = max_displacement_m(sim.body(), found);
    }
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (fem_steps > 0) r.fem_base_step_mean_ms = fem_step_total_ms / static_cast<double>(fem_steps);
  const auto ms = [](std::chrono::nanoseconds d) { return 1e-6 * static_cast<double>(d.count()); };
  r.fem_cpu_median_ms = ms(sim.fem_step_cpu().percentile(0.5));
  r.fem_cpu_p99_ms = ms(sim.fem_step_cpu().percentile(0.99));
  r.fem_cpu_max_ms = ms(sim.fem_step_cpu().max());
  if (trace != nullptr) std::fclose(trace);
  if (tick_trace != nullptr) std::fclose(tick_trace);
  r.inverted_at_end.assign(sim.tongue_mesh().tet_count(), 0);
  mark_inverted(sim.body(), r.inverted_at_end);
  count_by_radius_ratio(sim.tongue_mesh(), r);
  r.divergence_resets = sim.fem().divergence_resets();
  r.anatomy_returned = sim.fem().anatomy_returned();
  r.anatomy_beyond_steps = sim.fem().anatomy_beyond_steps();
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  fahr::common::run_solver_libraries_on_one_thread(argv);
  fahr::bench_support::MarkdownResults results(argc, argv);
  fahr::cli::App app{"fahr overshoot benchmark (paper Figure 7, neonatal tongue)"};
  app.footer(fahr::bench_support::kMarkdownHelp);
  std::string scene_path = FAHR_SOURCE_DIR "/deployment/scenes/neonatal_intubation.yaml";
  RunChoices choices;
  bool check = false;
  bool check_release = false;
  bool check_hold = false;
  std::string response = "both";
  std::string fem_anatomy = "on";
  app.add_option("--scene", scene_path, "scene file");
  app.add_option("--volume-floor", choices.volume_floor,
                 "no tet ends a FEM step below this share of its rest volume "
                 "(solver.volume_floor_ratio); 0: off "
                 "(default: the scene's)")
      ->check(fahr::cli::Range(0.0, 0.9));
  app.add_option(
         "--fem-anatomy-rounds", choices.fem_anatomy_rounds,
         "the FEM's tool/anatomy alternation rounds per step (libs/fem obstacle_projection.h "
         "max_rounds); default the FEM's")
      ->check(fahr::cli::Range(1, 1000));
  app.add_option("--response", response, "which response to run")
      ->check(fahr::cli::IsMember({"both", "force-aware", "penalty"}));
  app.add_option("--fem-anatomy", fem_anatomy,
                 "the FEM keeps its nodes out of the anatomy itself; off: the haptic side finds "
                 "the tongue's obstacle contacts (a comparison)")
      ->check(fahr::cli::IsMember({"on", "off"}));
  app.add_option(
         "--fem-support", choices.support_ratio,
         "the FEM's anatomy support springs, stiffness over the node's diagonal of A; 0: off "
         "(default: the service's)")
      ->check(fahr::cli::Range(0.0, 1e6));
  app.add_option("--tool-stops", choices.tool_stops,
                 "the tool stops at the rigid anatomy (default: as the scene says)")
      ->check(fahr::cli::IsMember({"scene", "on", "off"}));
  app.add_option("--youngs-pa", choices.youngs_pa,
                 "overrides the deformable body's Young's modulus, Pa (default: the scene's)")
      ->check(fahr::cli::Range(1.0, 1e9));
  app.add_option("--stiffening", choices.stiffening,
                 "the tongue's compression stiffening, Yeoh C20/C10; 0: off (default: the scene's)")
      ->check(fahr::cli::Range(0.0, 100.0));
  app.add_option("--trace", choices.trace_path, "per-FEM-step CSV, FILE.<response>.csv");
  app.add_option("--tick-trace", choices.tick_trace_path,
                 "per-tick CSV (force, hand, proxy, gap), FILE.<response>.csv");
  app.add_option("--factor", choices.factor,
                 "overshoot: the hand's pull as a multiple of the device's peak force")
      ->check(fahr::cli::Range(1.0, 10.0));
  app.add_option("--held-proxy", choices.held_proxy,
                 "while the device has lost track: load (stay, the tissue held by the limited "
                 "load, force only) or stay (stay, the spheres frozen: the paper's c' = c), the "
                 "scene's contact.held_proxy; limit (a comparison: back off to keep the tissue "
                 "at the limit); default the scene's")
      ->check(fahr::cli::IsMember({"scene", "load", "stay", "limit"}));
  app.add_option("--candidate-margin-mm", choices.candidate_margin_mm,
                 "the haptic tick's candidate margin (HapticSetup::candidate_margin_m), mm; "
                 "default the service's 1")
      ->check(fahr::cli::Range(0.0, 5.0));
  app.add_option("--w-normals", choices.w_normals,
                 "W along the normals for this many spheres (the scene's "
                 "solver.compliance_columns: normals and "
                 "max_candidate_contacts); 0: the scene's")
      ->check(fahr::cli::Range(0, 64));
  app.add_flag("--check", check, "exit 1 unless the force-aware run meets the targets");
  app.add_flag("--check-release", check_release,
               "exit 1 unless the force-aware run leaves the tongue sound: no FEM step diverged, "
               "no tet inverted after the blade left, the tongue within 1 mm of where the blade "
               "found it 1 s later (the targets for any tet mesh)")
      ->excludes("--check");
  app.add_flag("--check-hold", check_hold,
               "exit 1 unless the force-aware run holds the tool as it must and leaves the "
               "tongue sound: --check-release's targets and the hold's (lost track for 4 s, the "
               "FEM-side push, the tissue into the held blade, no strain growth, the gap, the "
               "re-engagement step), not --check's no inversion and no torn element")
      ->excludes("--check")
      ->excludes("--check-release");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  try {
    results.begin("overshoot");
    const auto scene = scene::load_scene(scene_path);
    choices.fem_anatomy = fem_anatomy == "on";
    const Result fa = response != "penalty" ? run(scene, false, choices) : Result{};
    const Result pe = response != "force-aware" ? run(scene, true, choices) : Result{};
    const auto mm = [](double m) { return 1e3 * m; };
    std::printf("## Overshoot on %s (%.0fx the device's peak force, hold 5 s)\n\n",
                scene->name.c_str(), choices.factor);
    std::printf("| figure | force-aware | penalty |\n|---|---:|---:|\n");
    std::printf("| device limit (peak renderable) N | %.2f | %.2f |\n", fa.limit_n, pe.limit_n);
    std::printf("| largest commanded force N | %.2f | %.2f |\n", fa.max_commanded_n,
                pe.max_commanded_n);
    std::printf("| largest tissue reaction N | %.3f | %.3f |\n", fa.max_reaction_n,
                pe.max_reaction_n);
    std::printf("| largest tool push on the tissue, FEM side N | %.3f | %.3f |\n",
                fa.max_fem_reaction_n, pe.max_fem_reaction_n);
    std::printf(
        "| largest sum of the tool rows' forces on a tick N (their resultant then) | "
        "%.3f (%.3f) | %.3f (%.3f) |\n",
        fa.max_row_force_sum_n, fa.row_resultant_at_max_sum_n, pe.max_row_force_sum_n,
        pe.row_resultant_at_max_sum_n);
    std::printf(
        "| contacts within the row margin that are not rows, per tick, median: pressing at half "
        "the limit or more before the hold / while lost track | %.0f / %.0f | - |\n",
        median_of(fa.dropped_pressing), median_of(fa.dropped_lost));
    const auto share = [](std::uint64_t part, std::size_t of) {
      return of == 0 ? 0.0 : 100.0 * static_cast<double>(part) / static_cast<double>(of);
    };
    std::printf(
        "| largest node motion a FEM step mm, median (steps where that node went back against "
        "its motion of the step before): pressing before the hold / while lost track | %.2f "
        "(%.0f %%) / %.2f (%.0f %%) | - |\n",
        mm(median_of(fa.motion_pressing_m)),
        share(fa.reversed_pressing, fa.motion_pressing_m.size()), mm(median_of(fa.motion_lost_m)),
        share(fa.reversed_lost, fa.motion_lost_m.size()));
    std::printf(
        "| the tool rows' force centre, its move from one FEM state to the next mm, median "
        "(p90): pressing before the hold / while lost track | %.2f (%.2f) / %.2f (%.2f) | - |\n",
        mm(median_of(fa.centre_move_pressing_m)), mm(quantile_of(fa.centre_move_pressing_m, 0.9)),
        mm(median_of(fa.centre_move_lost_m)), mm(quantile_of(fa.centre_move_lost_m, 0.9)));
    std::printf("| largest reaction / limit while lost track, as sent | %.4f | - |\n",
                fa.max_reaction_lost_ratio);
    std::printf("| largest reaction / limit while lost track, FEM side | %.4f | - |\n",
                fa.max_fem_reaction_lost_ratio);
    std::printf(
        "| ... on the last set before the hold, applied after the device lost track | %.4f | - |\n",
        fa.max_fem_reaction_transition_ratio);
    const HeldLoad held = held_load(fa);
    std::printf(
        "| the tool's push on the tissue / limit while lost track, FEM side: first held step, "
        "median, smallest | %.4f, %.4f, %.4f | - |\n",
        fa.fem_reaction_first_held_ratio, held.median, held.smallest);
    std::printf("| tissue into the held blade beyond its depth at the freeze mm | %.3f | - |\n",
                mm(fa.max_flow_into_held_m));
    std::printf("| lost-track ticks | %llu | - |\n",
                static_cast<unsigned long long>(fa.lost_ticks));
    std::printf(
        "| largest principal Green strain at 1x / at the end of the hold | %.3f / %.3f | - / %.3f "
        "|\n",
        fa.strain_1x, fa.strain_3x, pe.strain_3x);
    std::printf(
        "| elements stretched past principal Green strain %.1f (twice the rest length) at 1x / at "
        "the end of the hold | %d / %d | - / %d |\n",
        kTornStrain, fa.torn_1x, fa.torn_3x, pe.torn_3x);
    std::printf(
        "| ... of those at 1x, with a node lighter than %.2f x the median node (elements with one: "
        "%d) | %d | - |\n",
        kLightNode, fa.light_elements, fa.torn_1x_light);
    std::printf(
        "| ... of those at 1x, with a node fixed to bone / with the free node of a tet whose "
        "other three are fixed | %d / %d | - |\n",
        fa.torn_1x_fixed, fa.torn_1x_held);
    std::printf(
        "| ... of those at 1x, with a node within %.0f mm of a bone / with the centroid within "
        "%.0f "
        "mm of the blade | %d / %d | - |\n",
        1e3 * kNearM, 1e3 * kNearM, fa.torn_1x_near_bone, fa.torn_1x_near_blade);
    std::printf(
        "| the most strained element at 1x: rest centroid mm; its lightest node's mass / the "
        "median node's | (%.1f, %.1f, %.1f); %.2f | - |\n",
        fa.worst_1x_rest_mm.x(), fa.worst_1x_rest_mm.y(), fa.worst_1x_rest_mm.z(),
        fa.worst_1x_lightest_mass);
    std::printf(
        "| largest published-gap error mm (lost-track ticks at the peak limit) | %.3f (%llu) | - "
        "|\n",
        mm(fa.max_gap_error_m), static_cast<unsigned long long>(fa.lost_ticks_at_peak));
    std::printf("| held proxy's largest distance from where it froze mm | %.3f | - |\n",
                mm(fa.max_held_drift_m));
    std::printf("| largest force step in 50 ms of re-engagement N (bound) | %.3f (%.3f) | - |\n",
                fa.max_reengage_step_n, fa.reengage_bound_n);
    std::printf("| deepest tool penetration mm | %.2f | %.2f |\n", mm(fa.max_penetration_m),
                mm(pe.max_penetration_m));
    std::printf(
        "| deepest tongue node into the anatomy before the FEM moved it out mm | %.2f | %.2f |\n",
        mm(fa.max_anatomy_depth_m), mm(pe.max_anatomy_depth_m));
    std::printf("| most inverted tets | %d | %d |\n", fa.max_inverted, pe.max_inverted);
    std::printf("| most inverted tets after the blade left | %d | %d |\n",
                fa.max_inverted_after_left, pe.max_inverted_after_left);
    std::printf("| largest elastic energy mJ | %.2f | %.2f |\n", 1e3 * fa.max_elastic_j,
                1e3 * pe.max_elastic_j);
    std::printf(
        "| tongue 1 s after the blade left: from rest / from where the blade found it mm | "
        "%.2f / %.2f | %.2f / %.2f |\n",
        mm(fa.displacement_after_m), mm(fa.displacement_after_from_found_m),
        mm(pe.displacement_after_m), mm(pe.displacement_after_from_found_m));
    std::printf("| all finite | %s | %s |\n", fa.finite ? "yes" : "no", pe.finite ? "yes" : "no");
    std::printf("| FEM steps that diverged (tongue reset to rest) | %llu | %llu |\n",
                static_cast<unsigned long long>(fa.divergence_resets),
                static_cast<unsigned long long>(pe.divergence_resets));
    std::printf(
        "| FEM: nodes let back through a bone / node-steps beyond a bone | %llu / %llu | %llu / "
        "%llu |\n",
        static_cast<unsigned long long>(fa.anatomy_returned),
        static_cast<unsigned long long>(fa.anatomy_beyond_steps),
        static_cast<unsigned long long>(pe.anatomy_returned),
        static_cast<unsigned long long>(pe.anatomy_beyond_steps));
    std::printf("| wall time s | %.1f | %.1f |\n", fa.wall_s, pe.wall_s);
    std::printf(
        "| base step with a FEM step (FEM + haptic tick + digest) ms mean / max | %.2f / %.2f | "
        "%.2f / %.2f |\n",
        fa.fem_base_step_mean_ms, fa.fem_base_step_max_ms, pe.fem_base_step_mean_ms,
        pe.fem_base_step_max_ms);
    std::printf(
        "| FEM step CPU ms median / p99 / max (period %.1f) | %.2f / %.2f / %.2f | %.2f / %.2f / "
        "%.2f |\n",
        1e3 / scene->rates.fem_hz, fa.fem_cpu_median_ms, fa.fem_cpu_p99_ms, fa.fem_cpu_max_ms,
        pe.fem_cpu_median_ms, pe.fem_cpu_p99_ms, pe.fem_cpu_max_ms);
    for (const auto& body : scene->bodies) {
      if (!body.deformable) continue;
      const auto& m = body.deformable->material;
      const double stiffening =
          choices.stiffening >= 0.0 ? choices.stiffening : m.yeoh_c20_over_c10;
      std::printf("\ntongue material: E %.0f Pa, Yeoh C20/C10 %.2f (compression stiffening%s)\n",
                  choices.youngs_pa > 0.0 ? choices.youngs_pa : m.youngs_modulus_pa, stiffening,
                  stiffening > 0.0 ? "" : " off");
      if (response != "penalty") print_radius_ratio_table(fa);
    }
    if (!check && !check_release && !check_hold) return 0;
    if (response == "penalty") throw std::runtime_error("--check needs the force-aware run");
    int failures = 0;
    const auto expect = [&](bool ok, const char* what) {
      std::printf("%s: %s\n", ok ? "ok" : "FAIL", what);
      failures += ok ? 0 : 1;
    };
    expect(fa.finite && fa.divergence_resets == 0,
           "force-aware: every force and gap finite, no FEM step diverged");
    if (check) {
      // What the tissue must survive: neither holds on the shipped tongue at
      // every pull yet (robustness.sh, docs/design/anatomy-contact.md).
      expect(fa.max_inverted == 0, "force-aware: no inverted tet");
      expect(fa.torn_1x == 0 && fa.torn_3x == 0,
             "force-aware: no element stretched to twice its rest length at 1x or at the end "
             "of the hold");
    }
    if (check || check_hold) {
      // The hold is 5 s (kHoldEndS); the figure is the paper's regime only if
      // the device was lost for most of it.
      expect(fa.lost_ticks >= 4000,
             "force-aware: the device lost track for at least 4 s (the hold is 5 s)");
      expect(fa.max_fem_reaction_lost_ratio <= 1.05,
             "force-aware: the tool's push on the tissue (FEM side) <= 1.05 x limit while lost "
             "track");
      // The bound above holds as well for a hold that lets the tissue go
      // (a few percent of the limit); this is its other side. Half, not
      // more: the tongue under the held blade still creeps and settles on
      // the gum (docs/design/force-aware-decision.md).
      expect(!fa.fem_reaction_held_ratios.empty() &&
                 held_load(fa).median >= 0.5 * fa.fem_reaction_first_held_ratio,
             "force-aware: the held tool keeps the tissue loaded: its push (FEM side) / limit "
             "while lost track, median over the hold, at least half the first held step's");
      expect(fa.max_flow_into_held_m <= 5e-4,
             "force-aware: the tissue reaches at most 0.5 mm deeper into the held blade than at "
             "the freeze");
      expect(fa.strain_3x <= fa.strain_1x * 1.05 + 1e-3,
             "force-aware: no strain growth from 1x to 3x");
      expect(
          fa.max_gap_error_m <= 1e-4,
          "force-aware: published gap = (commanded - limit) / K_c within 0.1 mm at the peak limit");
      expect(fa.max_reengage_step_n <= fa.reengage_bound_n + 1e-9,
             "force-aware: re-engagement force step within the bound");
    }
    if (!check) {
      // (--check's "no inverted tet" covers the time after the blade left.)
      expect(fa.max_inverted_after_left == 0, "force-aware: no inverted tet after the blade left");
    }
    expect(fa.displacement_after_from_found_m >= 0.0 && fa.displacement_after_from_found_m <= 1e-3,
           "force-aware: tongue within 1 mm of where the blade found it, 1 s after the blade left "
           "it");
    return failures == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_overshoot_bench: %s\n", e.what());
    return 2;
  }
}
