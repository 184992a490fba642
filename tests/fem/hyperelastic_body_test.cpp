// The Stable Neo-Hookean material inside Body's implicit step: no force in
// rigid rotation, the patch test, the body's force and energy against finite
// differences (inverted elements included), its assembled tangent against the
// element-level projected tangent and positive semi-definite, uniaxial
// compression of a cube to 50 % against the energy's own stress-stretch
// curve, and confined compression to 80 %. Every reference is computed here.
// The shipped neonatal tongue under a blade's load is in
// hyperelastic_tongue_test.cpp.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "fahr/fem/hyperelastic_element.h"
#include "fahr/fem/stable_neo_hookean.h"
#include "fahr/geometry/tet_deformation.h"
#include "scenes.h"

namespace fahr::fem {
namespace {

// The tongue's material as the neonatal scene gives it, hyperelastic.
Material tissue() {
  Material m = neonatal_tongue();
  m.youngs_modulus_pa = 10000.0;
  m.rayleigh_mass_per_s = 0.1;
  m.yeoh_c20_over_c10 = kTongueYeohC20OverC10;
  m.model = MaterialModel::kStableNeoHookean;
  return m;
}

BodySettings settings_for(const Material& m, double h_s) {
  BodySettings s;
  s.material = m;
  s.time_step = std::chrono::duration<double>(h_s);
  s.gravity_m_per_s2.setZero();
  s.solver.refactor_period = 0;  // lagged, refreshed on the material's trigger
  s.sleep.enabled = false;
  return s;
}

// The body's nodes moved to x_i = a X_i + b (a teleport; velocities stay 0).
void map_nodes(Body& body, const Eigen::Matrix3d& a, const Eigen::Vector3d& b) {
  for (std::uint32_t i = 0; i < body.node_count(); ++i)
    body.set_node_position(i, a * body.rest_position(i) + b);
}

Eigen::VectorXd elastic_forces(Body& body) {
  Eigen::VectorXd f(3 * static_cast<Eigen::Index>(body.node_count()));
  body.elastic_forces({f.data(), static_cast<std::size_t>(f.size())});
  return f;
}

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

TEST(HyperelasticBody, RigidRotationGivesNoForceAndNoEnergy) {
  const BodyMesh mesh = make_box_mesh({3, 2, 2}, Eigen::Vector3d(0.03, 0.02, 0.02));
  auto body = test::make_body(settings_for(tissue(), 0.005), mesh, {});
  ASSERT_NE(body, nullptr);
  ASSERT_TRUE(body->hyperelastic());
  // Force scale: E times a 10 mm cell's face.
  const double scale = tissue().youngs_modulus_pa * 1e-4;
  std::mt19937 rng(21);
  for (int n = 0; n < 10; ++n) {
    map_nodes(*body, random_rotation(rng), Eigen::Vector3d(0.05, -0.02, 0.01));
    EXPECT_LT(elastic_forces(*body).cwiseAbs().maxCoeff() / scale, 1e-12) << n;
    EXPECT_LT(std::abs(body->energy().elastic_j), 1e-12 * scale * 0.01) << n;
  }
  // And a step from a rotated rest state moves nothing (no gravity).
  map_nodes(*body, random_rotation(rng), Eigen::Vector3d::Zero());
  std::vector<double> before(body->positions_m().begin(), body->positions_m().end());
  const StepReport report = body->step();
  EXPECT_EQ(report.inverted_elements, 0);
  for (std::size_t k = 0; k < before.size(); ++k)
    EXPECT_NEAR(body->positions_m()[k], before[k], 1e-12);
}

// Any affine map gives every tet the same F: the forces of the elements
// around an interior node cancel, the whole body's forces and torques too.
// One map is a reflection (every element inverted).
TEST(HyperelasticBody, AffineDeformationLeavesInteriorNodesInBalance) {
  const double side = 0.03;
  const BodyMesh mesh = make_box_mesh({3, 3, 3}, Eigen::Vector3d(side, side, side));
  auto body = test::make_body(settings_for(tissue(), 0.005), mesh, {});
  ASSERT_NE(body, nullptr);
  const StableNeoHookean snh(tissue());
  std::mt19937 rng(22);
  std::uniform_real_distribution<double> entry(-0.4, 0.4);
  for (int n = 0; n < 6; ++n) {
    Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
    for (int k = 0; k < 9; ++k) a(k) += entry(rng);
    if (n == 5) a.row(0) = -a.row(0);
    map_nodes(*body, a, Eigen::Vector3d(0.01, 0.02, -0.03));
    const Eigen::VectorXd f = elastic_forces(*body);
    const double scale = snh.first_piola(a).norm() * (side / 3) * (side / 3);
    Eigen::Vector3d total = Eigen::Vector3d::Zero();
    int interior = 0;
    for (std::uint32_t i = 0; i < body->node_count(); ++i) {
      const Eigen::Vector3d fi = f.segment<3>(3 * Eigen::Index{i});
      total += fi;
      const Eigen::Vector3d p = body->rest_position(i) / side;
      if ((p.array() > 1e-9).all() && (p.array() < 1.0 - 1e-9).all()) {
        ++interior;
        EXPECT_LT(fi.norm() / scale, 1e-12) << "node " << i << " det " << a.determinant();
      }
    }
    EXPECT_EQ(interior, 8);
    EXPECT_LT(total.norm() / scale, 1e-12);
    // The energy is the volume times Psi(a): every element has F = a.
    EXPECT_NEAR(body->energy().elastic_j, side * side * side * snh.energy_density(a),
                1e-12 * scale * side);
  }
}

// reset_to_rest forgets the kept element tangents too: a body that ran and
// was reset steps bit for bit as a new one.
TEST(HyperelasticBody, AResetBodyStepsAsANewOne) {
  const BodyMesh mesh = test::bar_mesh(2);
  BodySettings settings = settings_for(tissue(), 0.005);
  settings.gravity_m_per_s2 = Eigen::Vector3d(0.0, -9.81, 0.0);
  auto used = test::make_body(settings, mesh, test::fixed_x0(mesh));
  auto fresh = test::make_body(settings, mesh, test::fixed_x0(mesh));
  ASSERT_NE(used, nullptr);
  ASSERT_NE(fresh, nullptr);
  const auto tip = static_cast<std::uint32_t>(mesh.nodes_m.size() - 1);
  used->set_external_force(tip, Eigen::Vector3d(0.0, -0.05, 0.02));
  for (int k = 0; k < 30; ++k) used->step();
  ASSERT_TRUE(used->reset_to_rest());
  for (int k = 0; k < 30; ++k) {
    const StepReport a = used->step();
    const StepReport b = fresh->step();
    ASSERT_EQ(a.refactorised, b.refactorised) << k;
  }
  for (std::size_t i = 0; i < used->positions_m().size(); ++i)
    ASSERT_EQ(used->positions_m()[i], fresh->positions_m()[i]) << i;
}

// A 2 x 2 x 2 cell box of 5 mm cells, its nodes jittered by up to 3 mm so
// that some elements invert.
struct JitteredBox {
  std::unique_ptr<Body> body;
  BodyMesh mesh;
  int inverted = 0;
};

JitteredBox jittered_box(unsigned seed) {
  JitteredBox box;
  box.mesh = make_box_mesh({2, 2, 2}, Eigen::Vector3d(0.01, 0.01, 0.01));
  box.body = test::make_body(settings_for(tissue(), 0.005), box.mesh, {});
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.003, 0.003);
  for (std::uint32_t i = 0; i < box.body->node_count(); ++i) {
    box.body->set_node_position(
        i, box.body->rest_position(i) + Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng)));
  }
  const ElementRest& rest = box.body->element_rest();
  for (std::size_t e = 0; e < rest.size(); ++e) {
    const Eigen::Matrix3d f = geometry::deformation_gradient(box.body->positions_m().data(),
                                                             rest.tets[e], rest.dm_inv[e]);
    box.inverted += f.determinant() > 0.0 ? 0 : 1;
  }
  return box;
}

// The body's force is minus the gradient of its energy, and its change is
// minus the exact (unprojected) element Hessians assembled: the tangent is
// consistent. Central differences, 1e-8 m on 5 mm cells.
TEST(HyperelasticBody, ForceAndTangentAreTheEnergysDerivatives) {
  int inverted_seen = 0;
  const StableNeoHookean snh(tissue());
  for (unsigned seed = 1; seed <= 4; ++seed) {
    JitteredBox box = jittered_box(30 + seed);
    Body& body = *box.body;
    inverted_seen += box.inverted;
    const auto dofs = 3 * static_cast<Eigen::Index>(body.node_count());
    const Eigen::VectorXd f = elastic_forces(body);
    // The exact stiffness, assembled densely from the element functions.
    const ElementRest& rest = body.element_rest();
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(dofs, dofs);
    for (std::size_t e = 0; e < rest.size(); ++e) {
      const Eigen::Matrix3d fe =
          geometry::deformation_gradient(body.positions_m().data(), rest.tets[e], rest.dm_inv[e]);
      const Matrix12d ke =
          element_stiffness(shape_gradients(rest.dm_inv[e]), rest.volume_m3[e], snh.hessian(fe));
      for (Eigen::Index a = 0; a < 4; ++a) {
        for (Eigen::Index b = 0; b < 4; ++b) {
          k.block<3, 3>(3 * Eigen::Index{rest.tets[e][static_cast<std::size_t>(a)]},
                        3 * Eigen::Index{rest.tets[e][static_cast<std::size_t>(b)]}) +=
              ke.block<3, 3>(3 * a, 3 * b);
        }
      }
    }
    const double step = 1e-8;
    Eigen::VectorXd numeric_f(dofs);
    Eigen::MatrixXd numeric_k(dofs, dofs);
    for (Eigen::Index c = 0; c < dofs; ++c) {
      const auto node = static_cast<std::uint32_t>(c / 3);
      const Eigen::Vector3d at = body.position(node);
      Eigen::Vector3d moved = at;
      moved(c % 3) += step;
      body.set_node_position(node, moved);
      const double e_plus = body.energy().elastic_j;
      const Eigen::VectorXd f_plus = elastic_forces(body);
      moved(c % 3) = at(c % 3) - step;
      body.set_node_position(node, moved);
      const double e_minus = body.energy().elastic_j;
      const Eigen::VectorXd f_minus = elastic_forces(body);
      body.set_node_position(node, at);
      numeric_f(c) = -(e_plus - e_minus) / (2.0 * step);
      numeric_k.col(c) = -(f_plus - f_minus) / (2.0 * step);
    }
    EXPECT_LT((numeric_f - f).norm() / f.norm(), 1e-6) << "seed " << seed;
    EXPECT_LT((numeric_k - k).norm() / k.norm(), 1e-6) << "seed " << seed;
  }
  EXPECT_GT(inverted_seen, 0);  // the jitter does invert elements
}

// A = (1 + h alpha) M + (h beta + h^2) K_t as the body assembles it: K_t is
// the sum of the element-level projected tangents, and positive
// semi-definite however inverted the elements are.
TEST(HyperelasticBody, AssembledTangentIsTheProjectedOneAndPositiveSemiDefinite) {
  const StableNeoHookean snh(tissue());
  for (unsigned seed = 1; seed <= 4; ++seed) {
    JitteredBox box = jittered_box(40 + seed);
    Body& body = *box.body;
    // Assemble and factorise at the current state.
    ASSERT_EQ(body.set_solver(body.settings().solver), "");
    const auto dofs = 3 * static_cast<Eigen::Index>(body.node_count());
    const double h = body.time_step_s();
    const Material& m = body.settings().material;
    Eigen::MatrixXd k = Eigen::MatrixXd(body.system_matrix());
    for (Eigen::Index d = 0; d < dofs; ++d)
      k(d, d) -=
          (1.0 + h * m.rayleigh_mass_per_s) * body.mass_kg()[static_cast<std::size_t>(d / 3)];
    k /= h * m.rayleigh_stiffness_s + h * h;
    const ElementRest& rest = body.element_rest();
    Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(dofs, dofs);
    double exact_norm = 0.0;
    for (std::size_t e = 0; e < rest.size(); ++e) {
      const Eigen::Matrix3d fe =
          geometry::deformation_gradient(body.positions_m().data(), rest.tets[e], rest.dm_inv[e]);
      const Matrix12d ke = element_stiffness(shape_gradients(rest.dm_inv[e]), rest.volume_m3[e],
                                             snh.projected_hessian(fe));
      exact_norm += ke.norm();
      for (Eigen::Index a = 0; a < 4; ++a) {
        for (Eigen::Index b = 0; b < 4; ++b) {
          expected.block<3, 3>(3 * Eigen::Index{rest.tets[e][static_cast<std::size_t>(a)]},
                               3 * Eigen::Index{rest.tets[e][static_cast<std::size_t>(b)]}) +=
              ke.block<3, 3>(3 * a, 3 * b);
        }
      }
    }
    EXPECT_LT((k - expected).norm(), 1e-9 * expected.norm()) << "seed " << seed;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(0.5 * (k + k.transpose()));
    std::printf("[ info ] seed %u: %d of %zu elements inverted, K_t eigenvalues %.3g .. %.3g N/m\n",
                seed, box.inverted, rest.size(), eigen.eigenvalues()(0),
                eigen.eigenvalues()(dofs - 1));
    EXPECT_GE(eigen.eigenvalues()(0), -1e-12 * eigen.eigenvalues()(dofs - 1)) << "seed " << seed;
    EXPECT_GT(exact_norm, 0.0);
  }
}

// The energy of stable_neo_hookean.h written here again from its formula in
// the invariants I = |F|^2, J = det F, with the paper's mapping from E and
// nu (log term on): Psi = mu/2 (I - 3) - mu/2 log((I + 1)/4) +
// lambda/2 (J - alpha)^2 - lambda/2 (1 - alpha)^2 + c20 (I - 2 J - 1)^2.
struct Invariants {
  double mu, lambda, alpha, c20;

  explicit Invariants(const Material& m) {
    const double mu_le = m.youngs_modulus_pa / (2.0 * (1.0 + m.poisson_ratio));
    const double lambda_le = m.youngs_modulus_pa * m.poisson_ratio /
                             ((1.0 + m.poisson_ratio) * (1.0 - 2.0 * m.poisson_ratio));
    mu = 4.0 / 3.0 * mu_le;
    lambda = lambda_le + 5.0 / 6.0 * mu_le;
    alpha = 1.0 + 0.75 * mu / lambda;
    c20 = m.yeoh_c20_over_c10 * mu_le / 2.0;
  }
  double psi_i(double i, double j) const {
    return 0.5 * mu - 0.5 * mu / (i + 1.0) + 2.0 * c20 * (i - 2.0 * j - 1.0);
  }
  double psi_j(double i, double j) const {
    return lambda * (j - alpha) - 4.0 * c20 * (i - 2.0 * j - 1.0);
  }
  // For F = diag(s, t, t): P_11 = dPsi/ds and P_22 = dPsi/dt / 2 (dI/ds =
  // 2 s, dJ/ds = t^2; dI/dt = 4 t, dJ/dt = 2 s t for both lateral stretches).
  double axial(double s, double t) const {
    const double i = s * s + 2.0 * t * t, j = s * t * t;
    return 2.0 * s * psi_i(i, j) + t * t * psi_j(i, j);
  }
  double lateral(double s, double t) const {
    const double i = s * s + 2.0 * t * t, j = s * t * t;
    return 2.0 * t * psi_i(i, j) + s * t * psi_j(i, j);
  }
  // The traction-free lateral stretch: Newton on lateral(s, t) = 0 from
  // t = 1, with the derivative by central differences.
  double lateral_stretch(double s) const {
    double t = 1.0;
    for (int k = 0; k < 50; ++k) {
      const double r = lateral(s, t);
      const double d = 1e-6;
      const double slope = (lateral(s, t + d) - lateral(s, t - d)) / (2.0 * d);
      const double next = t - r / slope;
      if (std::abs(next - t) < 1e-15) return next;
      t = next;
    }
    return t;
  }
};

// Uniaxial compression, quasi-static, traction-free sides: a 10 mm cube
// (4 x 4 x 4 cells) whose two x faces are held (the platens) and moved in
// steps of 5 % to 50 % compression. A free-floating cube under dead
// compressive loads is unstable to a rigid turn (it flips over into
// tension), so the platens move the faces: to the affine state F = diag(s,
// t, t) with t the curve's traction-free lateral stretch. The four sides
// are free; the body is affine, with the curve's stress, only if its
// material is the curve's energy: each level must settle onto the affine
// state, and the x = 10 mm face's reaction per rest area is its nominal
// stress, compared with the curve. The curve's lateral stretch comes from
// Newton's method on the free sides' traction.
TEST(HyperelasticBody, UniaxialCompressionOfACubeFollowsTheStressStretchCurve) {
  const double side = 0.01;
  const BodyMesh mesh = make_box_mesh({4, 4, 4}, Eigen::Vector3d(side, side, side));
  const auto platens = test::nodes_where(
      mesh, [&](const Eigen::Vector3d& p) { return p.x() < 1e-12 || p.x() > side - 1e-12; });
  // Large steps with mass damping: the implicit step settles in a few tens.
  BodySettings settings = settings_for(tissue(), 0.02);
  settings.material.rayleigh_mass_per_s = 20.0;
  auto body = test::make_body(settings, mesh, platens);
  ASSERT_NE(body, nullptr);
  const Invariants curve(settings.material);
  const Eigen::Vector3d centre(0.0, 0.5 * side, 0.5 * side);
  std::printf(
      "| stretch | lateral stretch (curve) | mid-plane lateral stretch | nominal stress Pa "
      "| curve Pa | rel. error | steps |\n|---|---|---|---|---|---|---|\n");
  int steps = 0;
  for (int level = 1; level <= 10; ++level) {
    const double s = 1.0 - 0.05 * level;
    const double t = curve.lateral_stretch(s);
    EXPECT_LT(std::abs(curve.lateral(s, t)), 1e-9 * tissue().youngs_modulus_pa);
    const Eigen::Matrix3d f = Eigen::Vector3d(s, t, t).asDiagonal();
    auto affine = [&](const Eigen::Vector3d& p) {
      return Eigen::Vector3d(centre + f * (p - centre));
    };
    for (const std::uint32_t i : platens) body->set_node_position(i, affine(mesh.nodes_m[i]));
    // Quasi-static: step until the nodes stop (speed below 0.1 um/s).
    double speed = 1.0;
    int k = 0;
    for (; k < 2000 && speed > 1e-7; ++k) {
      const StepReport report = body->step();
      ASSERT_FALSE(report.solve_failed);
      ASSERT_EQ(report.inverted_elements, 0);
      speed = 0.0;
      for (const double v : body->velocities_m_per_s()) speed = std::max(speed, std::abs(v));
    }
    steps += k;
    double largest_off = 0.0;
    double y_top = 0.0, y_bottom = 0.0;
    int n_top = 0, n_bottom = 0;
    for (std::uint32_t i = 0; i < body->node_count(); ++i) {
      const Eigen::Vector3d& p = mesh.nodes_m[i];
      largest_off = std::max(largest_off, (body->position(i) - affine(p)).norm());
      if (std::abs(p.x() - 0.5 * side) > 1e-12) continue;  // the free mid-plane
      if (p.y() > side - 1e-12) y_top += body->position(i).y(), ++n_top;
      if (p.y() < 1e-12) y_bottom += body->position(i).y(), ++n_bottom;
    }
    const double mid_lateral = (y_top / n_top - y_bottom / n_bottom) / side;
    // The x = side face's nodal forces: the elements' push on the platen.
    const Eigen::VectorXd forces = elastic_forces(*body);
    double push = 0.0;
    for (std::uint32_t i = 0; i < body->node_count(); ++i)
      if (mesh.nodes_m[i].x() > side - 1e-12) push -= forces(3 * Eigen::Index{i});
    const double nominal = push / (side * side);
    const double expected = curve.axial(s, t);
    const double error = std::abs(nominal - expected) / std::abs(expected);
    std::printf("| %.2f | %.5f | %.5f | %.1f | %.1f | %.1e | %d |\n", s, t, mid_lateral, nominal,
                expected, error, k);
    EXPECT_LT(error, 0.01) << "s " << s;
    EXPECT_NEAR(mid_lateral, t, 1e-3 * t) << "s " << s;
    EXPECT_LT(largest_off, 1e-6 * side) << "s " << s;
    EXPECT_LT(nominal, 0.0);
  }
  std::printf("[ info ] uniaxial compression to 0.5: %d steps, %llu factorisations\n", steps,
              static_cast<unsigned long long>(body->factorisations()));
}

// Confined compression: every boundary node of the cube is held on the map
// F = diag(1, 1, s) while s goes from 1 to 0.8 in quasi-static steps; the
// interior must follow the affine state and the held z = top face carry the
// nominal stress P_33 = 2 Psi_I s + Psi_J of the energy.
TEST(HyperelasticBody, ConfinedCompressionTo80PercentIsAffineWithTheEnergysStress) {
  const double side = 0.01;
  const BodyMesh mesh = make_box_mesh({4, 4, 4}, Eigen::Vector3d(side, side, side));
  const auto boundary = test::nodes_where(mesh, [&](const Eigen::Vector3d& p) {
    return (p.array() < 1e-12).any() || (p.array() > side - 1e-12).any();
  });
  BodySettings settings = settings_for(tissue(), 0.02);
  settings.material.rayleigh_mass_per_s = 20.0;
  auto body = test::make_body(settings, mesh, boundary);
  ASSERT_NE(body, nullptr);
  const Invariants curve(settings.material);
  int steps = 0;
  for (int level = 1; level <= 10; ++level) {
    const double s = 1.0 - 0.02 * level;
    const Eigen::Matrix3d f = Eigen::Vector3d(1.0, 1.0, s).asDiagonal();
    for (const std::uint32_t i : boundary) body->set_node_position(i, f * mesh.nodes_m[i]);
    double speed = 1.0;
    for (int k = 0; k < 2000 && speed > 1e-7; ++k, ++steps) {
      const StepReport report = body->step();
      ASSERT_FALSE(report.solve_failed);
      ASSERT_EQ(report.inverted_elements, 0);
      speed = 0.0;
      for (const double v : body->velocities_m_per_s()) speed = std::max(speed, std::abs(v));
    }
  }
  const double s = 0.8;
  double largest_off = 0.0;
  for (std::uint32_t i = 0; i < body->node_count(); ++i) {
    const Eigen::Vector3d affine = Eigen::Vector3d(1.0, 1.0, s).asDiagonal() * mesh.nodes_m[i];
    largest_off = std::max(largest_off, (body->position(i) - affine).norm());
  }
  // The top face's nodal forces: the elements' pull on the held nodes, the
  // negative of what holds them.
  const Eigen::VectorXd forces = elastic_forces(*body);
  double top = 0.0;
  for (std::uint32_t i = 0; i < body->node_count(); ++i) {
    if (mesh.nodes_m[i].z() > side - 1e-12) top -= forces(3 * Eigen::Index{i} + 2);
  }
  const double nominal = top / (side * side);
  const double i = 2.0 + s * s, j = s;
  const double expected = 2.0 * curve.psi_i(i, j) * s + curve.psi_j(i, j);
  std::printf(
      "[ info ] confined compression to %.2f: nominal stress %.2f Pa, energy's %.2f Pa; "
      "largest distance from the affine state %.2e m; %d steps, %llu factorisations\n",
      s, nominal, expected, largest_off, steps,
      static_cast<unsigned long long>(body->factorisations()));
  EXPECT_LT(largest_off, 1e-6 * side);
  EXPECT_LT(std::abs(nominal - expected), 1e-4 * std::abs(expected));
  EXPECT_LT(nominal, 0.0);
}

}  // namespace
}  // namespace fahr::fem
