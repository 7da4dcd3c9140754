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

// sin x and cos x. A block turns by far less than 0.01 rad per step, where the Taylor series to x^7 and x^8 are
// exact to round-off (the next terms, x^9 / 9! and x^10 / 10!, are below 3e-24 and 3e-27) and far cheaper than the
// library's calls.
void sin_cos(double x, double& s, double& c) {
  if (std::abs(x) < 1e-2) {
    const double x2 = x * x;
    s = x * (1.0 - x2 * (1.0 / 6.0 - x2 * (1.0 / 120.0 - x2 * (1.0 / 5040.0))));
    c = 1.0 - x2 * (0.5 - x2 * (1.0 / 24.0 - x2 * (1.0 / 720.0 - x2 * (1.0 / 40320.0))));
  } else {
    s = std::sin(x), c = std::cos(x);
  }
}

// The exact torque-free flow of the part L_k^2 / (2 I_k) of the kinetic energy over h: a rotation of the body by
// phi = h L_k / I_k about its axis k, which turns Lb by -phi about the same axis (Euler's equations with only
// omega_k). The quaternion's half angle gives the whole angle's cosine and sine by the double-angle formulas, so
// each axis costs one sine and cosine.
void rotate_about_axis(int k, double moment, double h, Quat& qb, Vec3& Lb) {
  double s2, c2;
  sin_cos(0.5 * h * Lb[k] / moment, s2, c2);
  const double c = 1.0 - 2.0 * s2 * s2, s = 2.0 * s2 * c2;
  const int a = (k + 1) % 3, b = (k + 2) % 3;
  const double la = Lb[a], lb = Lb[b];
  Lb[a] = c * la + s * lb, Lb[b] = -s * la + c * lb;
  // qb (c2, s2 e_k): the product with a quaternion of one vector component.
  const Quat q = qb;
  if (k == 0) qb = {q.w * c2 - q.x * s2, q.x * c2 + q.w * s2, q.y * c2 + q.z * s2, q.z * c2 - q.y * s2};
  else if (k == 1) qb = {q.w * c2 - q.y * s2, q.x * c2 - q.z * s2, q.y * c2 + q.w * s2, q.z * c2 + q.x * s2};
  else qb = {q.w * c2 - q.z * s2, q.x * c2 + q.y * s2, q.y * c2 - q.x * s2, q.z * c2 + q.w * s2};
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
  const double h = 0.5 * dt;
  rotate_about_axis(0, moments.x, h, qb, Lb);
  rotate_about_axis(1, moments.y, h, qb, Lb);
  rotate_about_axis(2, moments.z, dt, qb, Lb);
  rotate_about_axis(1, moments.y, h, qb, Lb);
  rotate_about_axis(0, moments.x, h, qb, Lb);
}

double rigid_step(const RigidBody3& b, RigidState3& s, Vec3 F, Vec3 M, double dt, double alpha) {
  Vec3 Fd, Md;
  for (int k = 0; k < 3; ++k) {
    Fd[k] = -alpha * std::abs(F[k]) * sign(s.v[k]);
    Md[k] = -alpha * std::abs(M[k]) * sign(s.omega[k]);
  }
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
