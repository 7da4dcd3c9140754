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

#include <cmath>
#include <cstdint>

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

// The step's arithmetic, inline for the engine's block stage, which runs it in vector lanes.
namespace rigid3 {

// In doubles only (no integer difference of the comparisons), so that the vector lanes stay as wide as a double.
inline double sign(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

// sin x and cos x. A block turns by far less than 1e-4 rad per step, where the Taylor series to x^5 and x^4 are
// exact to round-off (the next terms, x^7 / 7! and x^6 / 6!, are below 2e-32 and 2e-27) and far cheaper than the
// library's calls. Exact = false (the vector lanes) takes the series always and sets `regular` to 0 beyond it.
// `regular` is 64 bits wide, as the doubles are: a vector loop's lanes are as many as its narrowest type's, so a
// 32-bit flag would spread each double over two registers.
template <bool Exact>
[[gnu::always_inline]] inline void sin_cos(double x, double& s, double& c, std::int64_t& regular) {
  const double x2 = x * x;
  s = x * (1.0 - x2 * (1.0 / 6.0 - x2 * (1.0 / 120.0)));
  c = 1.0 - x2 * (0.5 - x2 * (1.0 / 24.0));
  if constexpr (Exact) {
    if (!(std::abs(x) < 1e-4)) s = std::sin(x), c = std::cos(x);
  } else {
    regular &= std::int64_t(std::abs(x) < 1e-4);
  }
}

// The exact torque-free flow of the part L_k^2 / (2 I_k) of the kinetic energy over h: a rotation of the body by
// phi = h L_k / I_k about its axis k, which turns Lb by -phi about the same axis (Euler's equations with only
// omega_k). The quaternion's half angle gives the whole angle's cosine and sine by the double-angle formulas, so
// each axis costs one sine and cosine. half_rate = h / (2 I_k): phi / 2 = half_rate L_k; la, lb are L's components
// on the next two axes (k + 1, k + 2 mod 3).
template <bool Exact, int K>
[[gnu::always_inline]] inline void rotate_about_axis(double half_rate, Quat& qb, double lk, double& la, double& lb,
                                                     std::int64_t& regular) {
  double s2, c2;
  sin_cos<Exact>(half_rate * lk, s2, c2, regular);
  const double c = 1.0 - 2.0 * s2 * s2, s = 2.0 * s2 * c2;
  const double a0 = la, b0 = lb;
  la = c * a0 + s * b0, lb = -s * a0 + c * b0;
  // qb (c2, s2 e_k): the product with a quaternion of one vector component.
  const Quat q = qb;
  if constexpr (K == 0) qb = {q.w * c2 - q.x * s2, q.x * c2 + q.w * s2, q.y * c2 + q.z * s2, q.z * c2 - q.y * s2};
  if constexpr (K == 1) qb = {q.w * c2 - q.y * s2, q.x * c2 - q.z * s2, q.y * c2 + q.w * s2, q.z * c2 + q.x * s2};
  if constexpr (K == 2) qb = {q.w * c2 - q.z * s2, q.x * c2 + q.y * s2, q.y * c2 - q.x * s2, q.z * c2 + q.w * s2};
}

template <bool Exact>
[[gnu::always_inline]] inline void free_rotation(Vec3 moments, double dt, Quat& qb, Vec3& Lb,
                                                 std::int64_t& regular) {
  // phi / 2 = h L_k / (2 I_k) per axis, h = dt / 2 but for the middle one: the divisions before the chain.
  const double r1 = 0.25 * dt / moments.x, r2 = 0.25 * dt / moments.y, r3 = 0.5 * dt / moments.z;
  rotate_about_axis<Exact, 0>(r1, qb, Lb.x, Lb.y, Lb.z, regular);
  rotate_about_axis<Exact, 1>(r2, qb, Lb.y, Lb.z, Lb.x, regular);
  rotate_about_axis<Exact, 2>(r3, qb, Lb.z, Lb.x, Lb.y, regular);
  rotate_about_axis<Exact, 1>(r2, qb, Lb.y, Lb.z, Lb.x, regular);
  rotate_about_axis<Exact, 0>(r1, qb, Lb.x, Lb.y, Lb.z, regular);
}

// rigid_step: Exact = true is it; Exact = false the same operations without branches, which sets `regular` to 0
// where a half angle is beyond the series (the block then needs the exact form; elsewhere the two agree bit for bit).
template <bool Exact>
[[gnu::always_inline]] inline double step(const RigidBody3& b, RigidState3& s, Vec3 F, Vec3 M, double dt,
                                          double alpha, std::int64_t& regular) {
  const Vec3 Fd{-alpha * std::abs(F.x) * sign(s.v.x), -alpha * std::abs(F.y) * sign(s.v.y),
                -alpha * std::abs(F.z) * sign(s.v.z)};
  const Vec3 Md{-alpha * std::abs(M.x) * sign(s.omega.x), -alpha * std::abs(M.y) * sign(s.omega.y),
                -alpha * std::abs(M.z) * sign(s.omega.z)};
  const double work = (dot(Fd, s.v) + dot(Md, s.omega)) * dt;
  // Translation: the central difference.
  s.v += (dt / b.mass) * (F + Fd);
  s.x += dt * s.v;
  // Rotation: kick L, rotate freely with it, and read omega back at the new rotation. In the principal axes at the
  // step's start, L = I omega + dt (M + M_d).
  Quat qb = s.q * b.axes;
  const Mat3 R = matrix(qb);  // body to world: R^T turns a world vector into the principal axes
  const Vec3 wb = R.transposed_times(s.omega);
  Vec3 Lb = Vec3{b.moments.x * wb.x, b.moments.y * wb.y, b.moments.z * wb.z} + R.transposed_times(dt * (M + Md));
  free_rotation<Exact>(b.moments, dt, qb, Lb, regular);
  qb = normalized(qb);  // round-off only: each factor is a unit quaternion
  s.q = qb * conj(b.axes);
  s.omega = matrix(qb) * Vec3{Lb.x / b.moments.x, Lb.y / b.moments.y, Lb.z / b.moments.z};
  return work;
}

}  // namespace rigid3

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
