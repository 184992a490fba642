// Rotation invariance and inversion handling of the corotated element.
#include "fahr/fem/corotation.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "scenes.h"

namespace fahr::fem {
namespace {

TEST(Corotation, RigidRotationGivesZeroElasticForce) {
  const BodyMesh mesh = test::bar_mesh(2);
  BodySettings settings;
  auto body = test::make_body(settings, mesh, {});
  ASSERT_NE(body, nullptr);
  // Force scale: E times a face area of an element, the force of unit strain.
  const double cell = 0.005;
  const double scale = settings.material.youngs_modulus_pa * cell * cell;
  const Eigen::Vector3d translation(0.3, -1.2, 0.7);
  std::vector<double> forces(3 * body->node_count());
  for (const double degrees : {30.0, 90.0, 135.0, 179.0, 180.0, 270.0}) {
    for (const Eigen::Vector3d& axis :
         {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.3, -0.8, 0.52).normalized()}) {
      const Eigen::Matrix3d rotation =
          Eigen::AngleAxisd(degrees * M_PI / 180.0, axis).toRotationMatrix();
      for (std::uint32_t i = 0; i < body->node_count(); ++i) {
        body->set_node_position(i, rotation * mesh.nodes_m[i] + translation);
      }
      body->elastic_forces(forces);
      double largest = 0.0;
      for (const double f : forces) largest = std::max(largest, std::abs(f));
      EXPECT_LT(largest / scale, 1e-9) << degrees << " degrees";
    }
  }
}

TEST(Corotation, InvertedDeformationGivesProperRotation) {
  // A reflection through the x = 0 plane: det F = -1.
  Eigen::Matrix3d f = Eigen::Vector3d(-1.0, 1.0, 1.0).asDiagonal();
  const Corotation c = rotation_from_deformation(f);
  EXPECT_TRUE(c.inverted);
  EXPECT_NEAR(c.rotation.determinant(), 1.0, 1e-12);
  EXPECT_NEAR((c.rotation * c.rotation.transpose() - Eigen::Matrix3d::Identity()).norm(), 0.0,
              1e-12);
  // A flat element (det 0) still gives a rotation.
  f = Eigen::Vector3d(1.0, 1.0, 0.0).asDiagonal();
  EXPECT_NEAR(rotation_from_deformation(f).rotation.determinant(), 1.0, 1e-12);
  // A stretched rotation: Newton's path recovers the rotation.
  const Eigen::Matrix3d q =
      Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d s = Eigen::Vector3d(1.5, 0.7, 1.1).asDiagonal();
  EXPECT_NEAR((rotation_from_deformation(q * s).rotation - q).norm(), 0.0, 1e-10);
}

TEST(Corotation, InvertedBodyRecovers) {
  // Every node of a free-floating bar mirrored through its mid-plane y: all
  // elements start inside out. Without gravity the bar must unfold to its
  // rest shape (up to a rigid motion; checked on edge lengths).
  const BodyMesh mesh = test::bar_mesh(2);
  BodySettings settings;
  settings.gravity_m_per_s2.setZero();
  settings.time_step = std::chrono::milliseconds(5);
  auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
  ASSERT_NE(body, nullptr);
  for (std::uint32_t i = 0; i < body->node_count(); ++i) {
    Eigen::Vector3d p = mesh.nodes_m[i];
    if (!body->fixed(i)) p.y() = 0.01 - p.y() - 0.01;  // fold below the fixed face
    body->set_node_position(i, p);
  }
  StepReport first = body->step();
  EXPECT_GT(first.inverted_elements, 0);
  StepReport last;
  for (int k = 0; k < 600; ++k) last = body->step();
  ASSERT_TRUE(test::all_finite(*body));
  EXPECT_EQ(last.inverted_elements, 0);
  EXPECT_LT(test::max_displacement(*body), 1e-4);
}

}  // namespace
}  // namespace fahr::fem
