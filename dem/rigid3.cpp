// The rigid-block step of dem/rigid3.hpp.
#include "dem/rigid3.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rbdem {

namespace {

Vec3 multiply(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }

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
  std::int64_t regular = 1;
  rigid3::free_rotation<true>(moments, dt, qb, Lb, regular);
}

double rigid_step(const RigidBody3& b, RigidState3& s, Vec3 F, Vec3 M, double dt, double alpha) {
  std::int64_t regular = 1;
  return rigid3::step<true>(b, s, F, M, dt, alpha, regular);
}

double BlockStiffness3::critical_step(const RigidBody3& b) const {
  double dt = std::numeric_limits<double>::infinity();
  if (translational > 0) dt = std::sqrt(b.mass / translational);
  const double i_min = std::min({b.moments.x, b.moments.y, b.moments.z});
  if (rotational > 0) dt = std::min(dt, std::sqrt(i_min / rotational));
  return dt;
}

}  // namespace rbdem
