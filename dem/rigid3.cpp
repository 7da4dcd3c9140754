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

// The exact torque-free flow of the part L_k^2 / (2 I_k) of the kinetic energy over h: a rotation of the body by
// phi = h L_k / I_k about its axis k, which turns Lb by -phi about the same axis (Euler's equations with only
// omega_k).
void rotate_about_axis(int k, double moment, double h, Quat& qb, Vec3& Lb) {
  const double phi = h * Lb[k] / moment, c = std::cos(phi), s = std::sin(phi);
  const int a = (k + 1) % 3, b = (k + 2) % 3;
  const double la = Lb[a], lb = Lb[b];
  Lb[a] = c * la + s * lb, Lb[b] = -s * la + c * lb;
  Quat r{std::cos(0.5 * phi), 0, 0, 0};
  (k == 0 ? r.x : (k == 1 ? r.y : r.z)) = std::sin(0.5 * phi);
  qb = qb * r;
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
  // Rotation: kick L, rotate freely with it, and read omega back at the new rotation.
  Quat qb = s.q * b.axes;
  const Vec3 L = angular_momentum(b, s) + dt * (M + Md);
  Vec3 Lb = rotate_back(qb, L);
  free_rotation(b.moments, dt, qb, Lb);
  qb = normalized(qb);  // round-off only: each factor is a unit quaternion
  s.q = qb * conj(b.axes);
  s.omega = rotate(qb, divide(Lb, b.moments));
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
