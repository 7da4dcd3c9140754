// The rigid-block step of dem/rigid3.hpp.
#include "dem/rigid3.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rbdem {

namespace {

Vec3 divide(Vec3 a, Vec3 b) { return {a.x / b.x, a.y / b.y, a.z / b.z}; }
Vec3 multiply(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
double sign(double v) { return double((v > 0) - (v < 0)); }
Vec3 transposed(const Mat3& R, Vec3 v) { return R.transposed_times(v); }

// sin x and cos x. A block turns by far less than 1e-4 rad per step, where the Taylor series to x^5 and x^4 are
// exact to round-off (the next terms, x^7 / 7! and x^6 / 6!, are below 2e-32 and 2e-27) and far cheaper than the
// library's calls.
[[gnu::always_inline]] inline void sin_cos(double x, double& s, double& c) {
  if (std::abs(x) < 1e-4) {
    const double x2 = x * x;
    s = x * (1.0 - x2 * (1.0 / 6.0 - x2 * (1.0 / 120.0)));
    c = 1.0 - x2 * (0.5 - x2 * (1.0 / 24.0));
  } else {
    s = std::sin(x), c = std::cos(x);
  }
}

// The exact torque-free flow of the part L_k^2 / (2 I_k) of the kinetic energy over h: a rotation of the body by
// phi = h L_k / I_k about its axis k, which turns Lb by -phi about the same axis (Euler's equations with only
// omega_k). The quaternion's half angle gives the whole angle's cosine and sine by the double-angle formulas, so
// each axis costs one sine and cosine. half_rate = h / (2 I_k): phi / 2 = half_rate L_k; la, lb are L's components
// on the next two axes (k + 1, k + 2 mod 3).
template <int K>
[[gnu::always_inline]] inline void rotate_about_axis(double half_rate, Quat& qb, double lk, double& la, double& lb) {
  double s2, c2;
  sin_cos(half_rate * lk, s2, c2);
  const double c = 1.0 - 2.0 * s2 * s2, s = 2.0 * s2 * c2;
  const double a0 = la, b0 = lb;
  la = c * a0 + s * b0, lb = -s * a0 + c * b0;
  // qb (c2, s2 e_k): the product with a quaternion of one vector component.
  const Quat q = qb;
  if constexpr (K == 0) qb = {q.w * c2 - q.x * s2, q.x * c2 + q.w * s2, q.y * c2 + q.z * s2, q.z * c2 - q.y * s2};
  if constexpr (K == 1) qb = {q.w * c2 - q.y * s2, q.x * c2 - q.z * s2, q.y * c2 + q.w * s2, q.z * c2 + q.x * s2};
  if constexpr (K == 2) qb = {q.w * c2 - q.z * s2, q.x * c2 + q.y * s2, q.y * c2 - q.x * s2, q.z * c2 + q.w * s2};
}

}  // namespace

Vec3 angular_momentum(const RigidBody3& b, const RigidState3& s) {
  const Quat qb = s.q * b.axes;
  return rotate(qb, multiply(b.moments, rotate_back(qb, s.omega)));
}

double kinetic_energy(const RigidBody3& b, const RigidState3& s) {
  const Vec3 wb = rotate_back(s.q * b.axes, s.omega);
  return 0.5 * (b.mass * dot(s.v, s.v) + dot(wb, multiply(b.moments, wb)));
}

void free_rotation(Vec3 moments, double dt, Quat& qb, Vec3& Lb) {
  // phi / 2 = h L_k / (2 I_k) per axis, h = dt / 2 but for the middle one: the divisions before the chain.
  const double r1 = 0.25 * dt / moments.x, r2 = 0.25 * dt / moments.y, r3 = 0.5 * dt / moments.z;
  rotate_about_axis<0>(r1, qb, Lb.x, Lb.y, Lb.z);
  rotate_about_axis<1>(r2, qb, Lb.y, Lb.z, Lb.x);
  rotate_about_axis<2>(r3, qb, Lb.z, Lb.x, Lb.y);
  rotate_about_axis<1>(r2, qb, Lb.y, Lb.z, Lb.x);
  rotate_about_axis<0>(r1, qb, Lb.x, Lb.y, Lb.z);
}

double rigid_step(const RigidBody3& b, RigidState3& s, Vec3 F, Vec3 M, double dt, double alpha) {
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
  Vec3 Lb = multiply(b.moments, transposed(R, s.omega)) + transposed(R, dt * (M + Md));
  free_rotation(b.moments, dt, qb, Lb);
  qb = normalized(qb);  // round-off only: each factor is a unit quaternion
  s.q = qb * conj(b.axes);
  s.omega = matrix(qb) * divide(Lb, b.moments);
  return work;
}

double BlockStiffness3::critical_step(const RigidBody3& b) const {
  double dt = std::numeric_limits<double>::infinity();
  if (translational > 0) dt = std::sqrt(b.mass / translational);
  const double i_min = std::min({b.moments.x, b.moments.y, b.moments.z});
  if (rotational > 0) dt = std::min(dt, std::sqrt(i_min / rotational));
  return dt;
}

}  // namespace rbdem
