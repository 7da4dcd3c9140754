// The motion of one three-dimensional rigid block: its rotation as a unit quaternion, its inertia as principal
// moments in body axes, and one explicit step (docs/theory.md, "The face bond in 3D", rigid blocks). The 3D
// analogue of the integrator stage's per-block update (dem/stages/integrator.cpp); it sees a force and a moment,
// never a law.
//
// The step is the central difference in leapfrog form for the translation, as in 2D, and for the rotation the
// symplectic splitting of Dullweber, Leimkuhler and McLachlan (1997) (the NO_SQUISH scheme of Miller et al.,
// 2002): a kick of the world angular momentum L by dt (M + M_d), then the torque-free rotation over dt split into
// exact rotations about the body's principal axes, in the order 1, 2, 3, 2, 1 with half steps but for the middle
// one. Each of those keeps L (in world axes) unchanged, so the torque-free block keeps |L| and L to round-off and
// its kinetic energy to O(dt^2) without drift (the scheme is symplectic and time-reversible).
#pragma once

#include "dem/vec3.hpp"

namespace rbdem {

// A rigid block's inertia: mass, principal moments about the centroid and the rotation `axes` that turns the world
// axes into its principal axes at rest (Principal::rotation, dem/geometry3.hpp).
struct RigidBody3 {
  double mass = 1;  // kg
  Vec3 moments{1, 1, 1};  // kg m^2
  Quat axes;
};

// A block's state at a step: the centroid x and the rotation q from rest at step n; the velocity v and angular
// velocity omega (world) of the half step before it, as the 2D integrator keeps them. omega is tied to the angular
// momentum by the inertia at q: L = R I_0 R^T omega.
struct RigidState3 {
  Vec3 x, v;
  Quat q;
  Vec3 omega;
};

Vec3 angular_momentum(const RigidBody3& b, const RigidState3& s);
double kinetic_energy(const RigidBody3& b, const RigidState3& s);

// The torque-free rotation over dt of the body-axes rotation qb (world to principal axes) with the angular
// momentum Lb in those axes: both updated, L = qb Lb qb* unchanged.
void free_rotation(Vec3 moments, double dt, Quat& qb, Vec3& Lb);

// One step of the free block under the force F and moment M (world, at step n) with Cundall's local damping
// alpha: F_d = -alpha |F_k| sign(v_k) on each translational component and M_d = -alpha |M_k| sign(omega_k) on each
// rotational one (world axes, with the velocities of the half step before). Returns the work of the damping over
// the step (J, not positive), as the 2D integrator books it.
double rigid_step(const RigidBody3& b, RigidState3& s, Vec3 F, Vec3 M, double dt, double alpha);

// The block-wise critical time step in 3D, the 2D estimate (docs/theory.md, section 8.2) one dimension up:
// dt = min(sqrt(m / k_t), sqrt(I_min / k_r)) with k_t the sum of the normal and shear stiffnesses on the block and
// k_r a bound on the largest eigenvalue of its rotational stiffness, summed over its bonds: for a bond of
// stiffnesses (K_n, K_s) at the arm r from the centroid with normal n, and bending and twist stiffnesses kb,
//     max(kb_1, kb_2, kb_t) + K_s |r|^2 + max(K_n - K_s, 0) |r x n|^2,
// the largest eigenvalue of the bond's own rotational stiffness plus that of [r]x^T K [r]x. I_min is the smallest
// principal moment.
struct BlockStiffness3 {
  double translational = 0;  // N/m
  double rotational = 0;     // N m

  void add(double kn, double ks, double kb_max, Vec3 r, Vec3 n) {
    translational += kn + ks;
    const double rn = norm(cross(r, n));
    rotational += kb_max + ks * dot(r, r) + (kn > ks ? (kn - ks) * rn * rn : 0.0);
  }
  double critical_step(const RigidBody3& b) const;
};

}  // namespace rbdem
