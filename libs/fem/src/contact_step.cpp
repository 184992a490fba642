// One FEM step under the contact contract: forces, free step, compliance,
// free-motion centres, projection.
#include "fahr/fem/contact_step.h"

#include <algorithm>
#include <cmath>

namespace fahr::fem {
namespace {

constexpr std::int32_t kNoSlot = -1;
// Projected Gauss-Seidel sweeps of the compliance correction at most.
constexpr int kCorrectionSweeps = 100;

// Candidates carry no force; obstacle contacts are the tissue against a rigid
// surface, not the tool's push; force-only contacts are nothing but force.
bool carries_force(const Contact& c) {
  if (c.kind == ContactKind::kForceOnly) return c.force_n > 0.0;
  return c.kind == ContactKind::kTool && c.state != ContactState::kCandidate && c.force_n > 0.0;
}

// Adds a force of `magnitude` along `direction` on a sphere to the nodal
// forces `out` (3 per node), through the sphere's node weights.
void spread_force(const SphereLinks& links, std::uint32_t sphere, double magnitude,
                  const Eigen::Vector3d& direction, std::span<double> out) {
  const auto nodes = links.nodes(sphere);
  const auto weights = links.weights(sphere);
  for (std::size_t m = 0; m < nodes.size(); ++m) {
    for (std::size_t d = 0; d < 3; ++d) {
      out[3 * std::size_t{nodes[m]} + d] +=
          weights[m] * magnitude * direction[static_cast<Eigen::Index>(d)];
    }
  }
}

}  // namespace

ContactStep::ContactStep(Body& body, const SphereLinks& links, const ContactStepSettings& settings)
    : body_(body),
      links_(links),
      settings_(settings),
      projection_settings_(body.settings().projection) {
  const std::size_t dofs = 3 * body.node_count();
  const std::size_t k = settings_.max_compliance_spheres;
  carry_n_.assign(dofs, 0.0);
  force_n_.assign(dofs, 0.0);
  free_positions_.assign(body.positions_m().begin(), body.positions_m().end());
  projected_.assign(dofs, 0.0);
  start_positions_.assign(body.positions_m().begin(), body.positions_m().end());
  spheres_.reserve(k);
  lambda_n_.reserve(k);
  normals_.reserve(k);
  compliance_.reserve(9 * k * k);
  compliance_of_.reserve(k);
  if (settings_.volume_floor.ratio > 0.0) {
    volume_floor_ = std::make_unique<VolumeFloor>(body.element_rest(), settings_.volume_floor);
  }
  normals_of_.reserve(k);
  free_centres_.reserve(k);
  const std::size_t rows = 2 * k;
  correction_slot_.assign(rows, 0);
  correction_normal_.assign(rows, Eigen::Vector3d::Zero());
  correction_gap_m_.assign(rows, 0.0);
  correction_w_.assign(rows * rows, 0.0);
  correction_mu_.assign(rows, 0.0);
  correction_pushed_n_.assign(rows, 0.0);
  correction_force_n_.assign(dofs, 0.0);
  correction_dx_m_.assign(dofs, 0.0);
}

bool ContactStep::fix_compliance_spheres(std::span<const std::uint32_t> spheres) {
  fixed_spheres_ = true;
  spheres_.clear();
  compliance_valid_ = false;
  const bool known = std::all_of(spheres.begin(), spheres.end(),
                                 [&](std::uint32_t s) { return s < links_.size(); });
  if (!known || spheres.size() > settings_.max_compliance_spheres) {
    compliance_.clear();
    free_centres_.clear();
    return false;
  }
  spheres_.assign(spheres.begin(), spheres.end());
  slot_of_sphere_.assign(links_.size(), kNoSlot);
  for (std::size_t i = 0; i < spheres_.size(); ++i)
    slot_of_sphere_[spheres_[i]] = static_cast<std::int32_t>(i);
  lambda_n_.assign(spheres_.size(), 0.0);
  normals_.assign(spheres_.size(), Eigen::Vector3d::Zero());
  compliance_.assign(9 * spheres_.size() * spheres_.size(), 0.0f);
  const auto x = body_.positions_m();
  std::copy(x.begin(), x.end(), free_positions_.begin());
  update_compliance(true);
  update_free_centres();
  return compliance_valid_;
}

void ContactStep::set_obstacles(std::span<const ObstacleField* const> fields,
                                const ObstacleProjectionSettings& settings) {
  obstacles_ = fields.empty()
                   ? nullptr
                   : std::make_unique<ObstacleProjection>(fields, body_.node_count(), settings);
  projection_settings_.project_obstacle_contacts = obstacles_ == nullptr;
  // The floor's tets are held in A with or without anatomy.
  support_ratio_ = settings.support_stiffness_ratio;
  supports_ = (obstacles_ || volume_floor_) && support_ratio_ > 0.0
                  ? std::make_unique<ObstacleSupport>(
                        body_.node_count(), volume_floor_ ? body_.element_rest().size() : 0)
                  : nullptr;
  body_.set_supports({}, {}, 0.0);
}

bool ContactStep::reset() {
  if (obstacles_) obstacles_->forget_clearances();
  if (supports_ && supports_->clear()) body_.set_supports({}, {}, 0.0);
  std::fill(carry_n_.begin(), carry_n_.end(), 0.0);
  std::fill(lambda_n_.begin(), lambda_n_.end(), 0.0);
  const auto x = body_.positions_m();
  std::copy(x.begin(), x.end(), free_positions_.begin());
  projection_ = {};
  compliance_valid_ = false;
  if (!fixed_spheres_) {
    spheres_.clear();
    compliance_.clear();
  }
  update_compliance(true);
  update_free_centres();
  return compliance_valid_ || spheres_.empty();
}

void ContactStep::add_sphere_force(const Contact& c) {
  spread_force(links_, c.sphere_id, c.force_n, c.normal, force_n_);
}

// The spheres of this step's block (unless fixed) and the force each
// carries; the contact forces join the carried correction in force_n_.
void ContactStep::collect(const ContactSet* contacts) {
  std::copy(carry_n_.begin(), carry_n_.end(), force_n_.begin());
  std::fill(carry_n_.begin(), carry_n_.end(), 0.0);
  tool_force_n_.setZero();
  if (fixed_spheres_) {
    std::fill(lambda_n_.begin(), lambda_n_.end(), 0.0);
  } else {
    spheres_.clear();
    lambda_n_.clear();
    normals_.clear();
  }
  if (contacts == nullptr) return;
  for (const Contact& c : contacts->contacts) {
    if (c.sphere_id >= links_.size()) continue;
    std::int32_t slot = kNoSlot;
    if (fixed_spheres_) {
      slot = slot_of_sphere_[c.sphere_id];
    } else {
      const auto found = std::find(spheres_.begin(), spheres_.end(), c.sphere_id);
      if (found != spheres_.end()) {
        slot = static_cast<std::int32_t>(found - spheres_.begin());
      } else if (spheres_.size() < settings_.max_compliance_spheres) {
        slot = static_cast<std::int32_t>(spheres_.size());
        spheres_.push_back(c.sphere_id);
        lambda_n_.push_back(0.0);
        normals_.push_back(c.normal);
      }
    }
    if (!settings_.apply_contact_forces || !carries_force(c)) continue;
    add_sphere_force(c);
    tool_force_n_ += c.force_n * c.normal;
    if (slot == kNoSlot) continue;
    const auto i = static_cast<std::size_t>(slot);
    if (lambda_n_[i] == 0.0) {
      lambda_n_[i] = c.force_n;
      normals_[i] = c.normal;
    } else {
      // A second pushing contact on the sphere: one resultant force.
      const Eigen::Vector3d f = lambda_n_[i] * normals_[i] + c.force_n * c.normal;
      lambda_n_[i] = f.norm();
      if (lambda_n_[i] > 0.0) normals_[i] = f / lambda_n_[i];
    }
  }
}

void ContactStep::apply_forces(std::span<const double> extra_forces_n) {
  body_.clear_external_forces();
  for (std::size_t n = 0; n < body_.node_count(); ++n) {
    Eigen::Vector3d f(force_n_[3 * n], force_n_[3 * n + 1], force_n_[3 * n + 2]);
    if (!extra_forces_n.empty()) {
      f += Eigen::Vector3d(extra_forces_n[3 * n], extra_forces_n[3 * n + 1],
                           extra_forces_n[3 * n + 2]);
    }
    if (f.squaredNorm() > 0.0) body_.set_external_force(static_cast<std::uint32_t>(n), f);
  }
}

// W depends only on the factorisation: with the same spheres and no
// refactorisation since, the last block is still exact and is reused.
void ContactStep::update_compliance(bool refactorised) {
  const std::size_t k = spheres_.size();
  if (k == 0) {
    compliance_.clear();
    return;
  }
  const bool along = along_normals();
  if (compliance_valid_ && !refactorised &&
      std::equal(spheres_.begin(), spheres_.end(), compliance_of_.begin(), compliance_of_.end()) &&
      (!along ||
       std::equal(normals_.begin(), normals_.end(), normals_of_.begin(), normals_of_.end()))) {
    ++compliance_reuses_;
    return;
  }
  if (along) {
    compliance_.resize(3 * k * k);
    compliance_valid_ = body_.compliance_along(spheres_, normals_, links_, compliance_);
    normals_of_.assign(normals_.begin(), normals_.end());
  } else {
    compliance_.resize(9 * k * k);
    compliance_valid_ = body_.compliance(spheres_, links_, compliance_);
  }
  ++compliance_solves_;
  compliance_of_.assign(spheres_.begin(), spheres_.end());
  if (!compliance_valid_ && !fixed_spheres_) {
    // No block rather than a wrong one; fixed spheres retry next step.
    spheres_.clear();
    compliance_.clear();
  }
}

// c_free = c - W N lambda: x_free = x - h^2 A^-1 J^T N lambda on this
// step's factor, so exact wherever W is.
void ContactStep::update_free_centres() {
  const std::size_t k = spheres_.size();
  free_centres_.resize(k);
  const double* x = free_positions_.data();
  const bool along = along_normals();
  for (std::size_t s = 0; s < k; ++s) {
    Eigen::Vector3d shift = Eigen::Vector3d::Zero();
    for (std::size_t t = 0; t < k && compliance_valid_; ++t) {
      if (lambda_n_[t] == 0.0) continue;
      if (along) {
        // Column t is W_st n_t, n_t the normal lambda_t pushed along.
        for (std::size_t d = 0; d < 3; ++d) {
          shift[static_cast<Eigen::Index>(d)] +=
              lambda_n_[t] * double{compliance_[(3 * s + d) * k + t]};
        }
        continue;
      }
      for (std::size_t d = 0; d < 3; ++d) {
        const float* row = compliance_.data() + (3 * s + d) * 3 * k + 3 * t;
        shift[static_cast<Eigen::Index>(d)] +=
            lambda_n_[t] * (double{row[0]} * normals_[t].x() + double{row[1]} * normals_[t].y() +
                            double{row[2]} * normals_[t].z());
      }
    }
    free_centres_[s] = links_.centre(spheres_[s], x) - shift;
  }
}

bool ContactStep::diverged() const {
  const auto x = body_.positions_m();
  const double limit2 = settings_.divergence_limit_m * settings_.divergence_limit_m;
  for (std::size_t n = 0; n < body_.node_count(); ++n) {
    const Eigen::Vector3d moved = Eigen::Vector3d(x[3 * n], x[3 * n + 1], x[3 * n + 2]) -
                                  body_.rest_position(static_cast<std::uint32_t>(n));
    // Written so that a NaN counts as diverged.
    if (!(moved.squaredNorm() <= limit2)) return true;
  }
  return false;
}

// Gauss-Seidel between the tool and the bone: the ContactSet's projection,
// then the anatomy's pass; again while
// the anatomy's moves broke a tool constraint, up to the round limit. The
// anatomy always has the last word.
void ContactStep::alternate_with_anatomy(const ContactSet* contacts) {
  const auto inverse_mass = body_.inverse_mass_per_kg();
  const bool tool = contacts != nullptr && !contacts->contacts.empty();
  const int rounds = obstacles_ ? obstacles_->settings().max_rounds : 1;
  ProjectionReport anatomy;
  int sweeps = 0;
  if (obstacles_) obstacles_->begin_step();
  // The floor is for tissue squeezed between the blade and bone: it acts in
  // steps where something presses the body (a tool contact projected or
  // carrying force, or an external load). Kept on after the blade left, it
  // held a fold the hold had left (tets the elastic step pressed below the
  // floor in every step, the floor pushing them back): the tongue stayed
  // 3.9 mm from where the blade found it, where without the floor it went
  // back within 0.5 s (docs/design/anatomy-contact.md).
  bool pressed = external_load_;
  if (tool) {
    for (const Contact& c : contacts->contacts) {
      pressed = pressed ||
                (c.kind != ContactKind::kObstacle && (contact_is_projected(c) || carries_force(c)));
    }
  }
  VolumeFloor* const floor_pass = pressed ? volume_floor_.get() : nullptr;
  floor_in_force_ = floor_pass != nullptr;
  int volume_below = 0;
  int volume_unresolved = 0;
  Eigen::Vector3d tool_push = Eigen::Vector3d::Zero();
  for (int round = 0; round < rounds; ++round) {
    // After a round: whether the anatomy's last pass left nothing to redo.
    bool settled = round > 0;
    if (tool) {
      projection_ = project_contacts(*contacts, links_, inverse_mass, projection_settings_,
                                     projected_, start_positions_);
      sweeps += projection_.sweeps;
      tool_push += projection_.tool_push_kg_m;
      // It moved nothing the tool constraints needed (with a floor: nor
      // squeezed a tet below it, checked after the floor's pass).
      settled = settled && projection_.sweeps <= 1 && projection_.converged;
      if (settled && floor_pass == nullptr) break;
    }
    if (floor_pass != nullptr) {
      const VolumeFloorReport floor = floor_pass->project(projected_, inverse_mass);
      volume_below += floor.below;
      volume_unresolved = floor.unresolved;
      if (settled && floor.below == 0) break;
    }
    if (!obstacles_) break;
    ++anatomy.obstacle_rounds;
    // Without tool constraints or a floor, nothing the anatomy moved can
    // need another round.
    if (obstacles_->project(projected_, inverse_mass, anatomy, start_positions_,
                            body_.rest_positions_m()) == 0 ||
        (!tool && floor_pass == nullptr))
      break;
  }
  projection_.sweeps = sweeps;
  projection_.tool_push_kg_m = tool_push + compliance_push_kg_m_;
  projection_.volume_floor_below = volume_below;
  projection_.volume_floor_unresolved = volume_unresolved;
  projection_.obstacle_rounds = anatomy.obstacle_rounds;
  projection_.obstacle_nodes = anatomy.obstacle_nodes;
  projection_.obstacle_unresolved = anatomy.obstacle_unresolved;
  projection_.obstacle_non_finite = anatomy.obstacle_non_finite;
  projection_.obstacle_deepest_m = anatomy.obstacle_deepest_m;
  projection_.obstacle_returned = obstacles_ ? obstacles_->nodes_returned() : 0;
  projection_.obstacle_beyond = obstacles_ ? obstacles_->nodes_beyond() : 0;
}

// The tool's constraints on the block's spheres met through the tissue's
// compliance before the projection. Each active tool contact on a block
// sphere is a row: its penetration g of the free motion (which already
// carries the set's lambda), its normal n. The step finds the change mu of
// each row's force with lambda + mu >= 0, n^T W N mu >= g, and lambda + mu
// > 0 only where the row then touches (projected Gauss-Seidel on the row
// block of W), and moves every node by h^2 A^-1 J^T N mu: the implicit
// step's own response to those forces, so the whole tissue gives way as its
// stiffness says. The projection after it only takes up what the
// linearisation leaves and the spheres outside the block, instead of moving
// each sphere's own nodes, the light ones most (move_sphere_centre's spread
// by inverse mass). The bound is on the total force, not on mu: a sphere
// the free motion left off its plane gives back what the haptic side's
// lambda pushed it by. With mu >= 0 the correction only ever added push, and
// where the haptic tick lags the FEM (1 kHz FEM) the two settled into a
// cycle of a few steps whose one-sided corrections added up to a push the
// hand never felt (the flat punch's force 4 % under the FEM's static force,
// drifting to 8 % over 2.5 s; -0.5 % with the bound on the total).
void ContactStep::correct_through_compliance(const ContactSet* contacts) {
  if (contacts == nullptr || !compliance_valid_ || along_normals() || spheres_.empty()) return;
  const std::size_t k = spheres_.size();
  const std::size_t capacity = correction_slot_.size();
  std::size_t rows = 0;
  bool violated = false;  // a row penetrates, or pushes a sphere that left the blade
  for (const Contact& c : contacts->contacts) {
    if (rows == capacity) break;
    if (c.kind != ContactKind::kTool || c.state != ContactState::kActive) continue;
    const auto found = std::find(spheres_.begin(), spheres_.end(), c.sphere_id);
    if (found == spheres_.end()) continue;
    const double length = c.normal.norm();
    if (!(length > 1e-9)) continue;
    const Eigen::Vector3d n = c.normal / length;
    const Eigen::Vector3d centre = links_.centre(c.sphere_id, projected_.data());
    correction_slot_[rows] = static_cast<std::size_t>(found - spheres_.begin());
    correction_normal_[rows] = n;
    correction_gap_m_[rows] = links_.radius_m(c.sphere_id) - (centre - c.plane_point_m).dot(n);
    correction_pushed_n_[rows] = std::max(0.0, c.force_n);
    violated = violated || correction_gap_m_[rows] > 0.0 ||
               (correction_gap_m_[rows] < 0.0 && correction_pushed_n_[rows] > 0.0);
    ++rows;
  }
  if (!violated) return;
  // n_i^T W_st n_j from the 3k x 3k block.
  for (std::size_t i = 0; i < rows; ++i) {
    for (std::size_t j = 0; j < rows; ++j) {
      const std::size_t s = correction_slot_[i];
      const std::size_t t = correction_slot_[j];
      double v = 0.0;
      for (std::size_t d = 0; d < 3; ++d) {
        const float* row = compliance_.data() + (3 * s + d) * 3 * k + 3 * t;
        v += correction_normal_[i][static_cast<Eigen::Index>(d)] *
             (double{row[0]} * correction_normal_[j].x() +
              double{row[1]} * correction_normal_[j].y() +
              double{row[2]} * correction_normal_[j].z());
      }
      correction_w_[i * rows + j] = v;
    }
  }
  std::fill(correction_mu_.begin(), correction_mu_.begin() + static_cast<std::ptrdiff_t>(rows),
            0.0);
  for (int sweep = 0; sweep < kCorrectionSweeps; ++sweep) {
    double largest = 0.0;
    for (std::size_t i = 0; i < rows; ++i) {
      const double diagonal = correction_w_[i * rows + i];
      if (!(diagonal > 0.0)) continue;
      double moved = 0.0;
      for (std::size_t j = 0; j < rows; ++j)
        moved += correction_w_[i * rows + j] * correction_mu_[j];
      const double mu = std::max(-correction_pushed_n_[i],
                                 correction_mu_[i] + (correction_gap_m_[i] - moved) / diagonal);
      largest = std::max(largest, std::abs(mu - correction_mu_[i]) * diagonal);
      correction_mu_[i] = mu;
    }
    if (largest <= projection_settings_.tolerance_m) break;
  }
  std::fill(correction_force_n_.begin(), correction_force_n_.end(), 0.0);
  Eigen::Vector3d impulse = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < rows; ++i) {
    const double mu = correction_mu_[i];
    if (mu == 0.0 || !std::isfinite(mu)) continue;
    spread_force(links_, spheres_[correction_slot_[i]], mu, correction_normal_[i],
                 correction_force_n_);
    impulse += mu * correction_normal_[i];
  }
  if (!body_.step_motion(correction_force_n_, correction_dx_m_)) return;
  for (std::size_t i = 0; i < projected_.size(); ++i) {
    if (!std::isfinite(correction_dx_m_[i])) return;
  }
  for (std::size_t i = 0; i < projected_.size(); ++i) projected_[i] += correction_dx_m_[i];
  const double h = body_.time_step_s();
  compliance_push_kg_m_ = impulse * h * h;
}

void ContactStep::project(const ContactSet* contacts) {
  std::copy(free_positions_.begin(), free_positions_.end(), projected_.begin());
  compliance_push_kg_m_.setZero();
  if (volume_floor_) volume_floor_->begin_step();
  correct_through_compliance(contacts);
  alternate_with_anatomy(contacts);
  const double h2 = body_.time_step_s() * body_.time_step_s();
  const auto mass = body_.mass_kg();
  for (std::size_t n = 0; n < body_.node_count(); ++n) {
    const Eigen::Vector3d moved(projected_[3 * n] - free_positions_[3 * n],
                                projected_[3 * n + 1] - free_positions_[3 * n + 1],
                                projected_[3 * n + 2] - free_positions_[3 * n + 2]);
    if (moved.squaredNorm() == 0.0) continue;
    const auto node = static_cast<std::uint32_t>(n);
    body_.set_node_position(
        node, Eigen::Vector3d(projected_[3 * n], projected_[3 * n + 1], projected_[3 * n + 2]));
    const Eigen::Vector3d carry = mass[n] * moved / h2;
    for (std::size_t d = 0; d < 3; ++d) carry_n_[3 * n + d] = carry[static_cast<Eigen::Index>(d)];
  }
}

StepReport ContactStep::step(const ContactSet* contacts, std::span<const double> extra_forces_n) {
  collect(contacts);
  apply_forces(extra_forces_n);
  external_load_ =
      std::any_of(extra_forces_n.begin(), extra_forces_n.end(), [](double f) { return f != 0.0; });
  const auto start = body_.positions_m();
  std::copy(start.begin(), start.end(), start_positions_.begin());
  StepReport report = body_.step(nullptr, nullptr);
  std::int64_t t0 = thread_cpu_ns();
  const auto lap = [&t0](std::int64_t& part) {
    const std::int64_t t = thread_cpu_ns();
    part += t - t0;
    t0 = t;
  };
  const auto x = body_.positions_m();
  std::copy(x.begin(), x.end(), free_positions_.begin());
  update_compliance(report.refactorised);
  update_free_centres();
  lap(report.cpu.compliance_ns);
  projection_ = {};
  floor_in_force_ = false;
  if (obstacles_ || volume_floor_ || (contacts != nullptr && !contacts->contacts.empty())) {
    project(contacts);
  }
  lap(report.cpu.projection_ns);
  const double h = body_.time_step_s();
  tool_reaction_n_ = tool_force_n_ + projection_.tool_push_kg_m / (h * h);
  // A tet is held in A only while the floor that moved it is in force: once
  // nothing presses the body the floor's pass stops, and springs left in A
  // for it would only slow the tissue's return (tets whose free motion did
  // not open them stayed held after the blade left, and the tongue crept
  // back over seconds with a sliver held inverted: docs/design/anatomy-contact.md).
  VolumeFloor* const held_floor = floor_in_force_ ? volume_floor_.get() : nullptr;
  if (supports_ &&
      supports_->update(obstacles_.get(), held_floor, start_positions_, free_positions_)) {
    body_.set_supports(supports_->supports(), supports_->tet_supports(), support_ratio_);
  }
  lap(report.cpu.supports_ns);
  projection_.obstacle_supported = static_cast<int>(body_.support_count());
  report.projection = projection_;
  report.contacts_applied = contacts != nullptr;
  if (settings_.divergence_limit_m > 0.0 && diverged()) {
    // Rare and off the 1 kHz path: the reset refactorises (CHOLMOD allocates).
    body_.reset_to_rest();
    reset();
    report.diverged_reset = true;
  }
  return report;
}

}  // namespace fahr::fem
