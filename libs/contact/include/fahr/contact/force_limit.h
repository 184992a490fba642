// The ForceCommand never asks for more than the device can render now
// (never a force above the limit). Past the limit the proxy has
// lost track and the coupling spring (or a rigid obstacle) would ask for
// more; the command is scaled to the limit along the same direction, as the
// gateway would, and the local stiffness becomes the Jacobian of that scaled
// force, so the gateway's F_k - K_k (x - x_k) stays a first-order model of
// what it renders: for F_s = L F/|F| with u = F/|F|,
// dF_s/dx = (L/|F|) (I - u u^T) dF/dx, symmetrised as (L/|F|) P K P with
// P = I - u u^T (symmetric PSD, and <= K because L/|F| < 1).
#pragma once

#include <Eigen/Core>

namespace fahr::contact {

// Returns true when the force was above limit_n (>= 0) and was scaled.
bool limit_force(double limit_n, Eigen::Vector3d& force_n, Eigen::Matrix3d& stiffness_npm);

}  // namespace fahr::contact
