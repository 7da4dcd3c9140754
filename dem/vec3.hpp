// Vectors and unit quaternions of three-dimensional rigid blocks: the small value types the 3D kernels (the face
// bond, dem/stages/face_bond_kernel.hpp; the rigid-block step, dem/rigid3.hpp; the tetrahedron geometry,
// dem/geometry3.hpp) compute with. Plain structs without allocation, so that a kernel over many bonds keeps them
// in registers.
//
// A rotation is a unit quaternion q = (w, x, y, z) = (cos(phi/2), sin(phi/2) a) for the angle phi about the unit
// axis a; it turns a vector v into q v q*. q and -q are the same rotation.
#pragma once

#include <cmath>

namespace rbdem {

struct Vec3 {
  double x = 0, y = 0, z = 0;
  double& operator[](int k) { return k == 0 ? x : (k == 1 ? y : z); }
  double operator[](int k) const { return k == 0 ? x : (k == 1 ? y : z); }
};

inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
inline Vec3 operator*(double s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline Vec3& operator+=(Vec3& a, Vec3 b) { return a = a + b; }
inline Vec3& operator-=(Vec3& a, Vec3 b) { return a = a - b; }
inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double norm(Vec3 a) { return std::sqrt(dot(a, a)); }

// A 3x3 matrix by rows; as a frame, its rows are the frame's axes in world components.
struct Mat3 {
  Vec3 r[3];
  Vec3 operator*(Vec3 v) const { return {dot(r[0], v), dot(r[1], v), dot(r[2], v)}; }
  // M^T v: the world vector of frame components v when the rows are the frame's axes.
  Vec3 transposed_times(Vec3 v) const { return v.x * r[0] + v.y * r[1] + v.z * r[2]; }
};

struct Quat {
  double w = 1, x = 0, y = 0, z = 0;
  Vec3 vec() const { return {x, y, z}; }
};

inline Quat operator*(Quat a, Quat b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}
inline Quat conj(Quat q) { return {q.w, -q.x, -q.y, -q.z}; }
inline double norm(Quat q) { return std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z); }
inline Quat normalized(Quat q) {
  const double s = 1.0 / norm(q);
  return {s * q.w, s * q.x, s * q.y, s * q.z};
}

// q v q*, as v + 2 w (u x v) + 2 u x (u x v) with u the vector part (for a unit q).
inline Vec3 rotate(Quat q, Vec3 v) {
  const Vec3 u = q.vec(), t = 2.0 * cross(u, v);
  return v + q.w * t + cross(u, t);
}
// q* v q: a world vector in the frame q turns the reference axes into.
inline Vec3 rotate_back(Quat q, Vec3 v) { return rotate(conj(q), v); }

// The rotation matrix R of q, by rows: R v = q v q*.
inline Mat3 matrix(Quat q) {
  const double w = q.w, x = q.x, y = q.y, z = q.z;
  return {{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
           {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
           {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
}

// The rotation by the angle |phi| about phi / |phi| (the exponential map of the rotation vector phi).
inline Quat from_rotation_vector(Vec3 phi) {
  const double a = norm(phi);
  if (a < 1e-8) {  // sin(a/2)/a = 1/2 - a^2/48: the next term, a^4/3840, is below 1e-35
    const double s = 0.5 - a * a / 48.0;
    return normalized({1.0 - a * a / 8.0, s * phi.x, s * phi.y, s * phi.z});
  }
  const double s = std::sin(0.5 * a) / a;
  return {std::cos(0.5 * a), s * phi.x, s * phi.y, s * phi.z};
}

// The rotation vector of a unit q (the logarithmic map), on the shorter arc: |phi| <= pi.
inline Vec3 rotation_vector(Quat q) {
  if (q.w < 0) q = {-q.w, -q.x, -q.y, -q.z};
  const Vec3 u = q.vec();
  const double s = norm(u);
  // phi = 2 atan2(s, w) u / s = (2 / w) atan(x) / x u with x = s / w. An intact bond turns by well under 0.01
  // rad (s = sin(phi / 2) < 5e-3), where the series 1 - x^2/3 + x^4/5 - x^6/7 is exact to round-off (the next
  // term, x^8 / 9, is below 1e-19) and far cheaper than atan2.
  const double x2 = s * s / (q.w * q.w);
  const double f = s < 5e-3 ? 2.0 / q.w * (1.0 - x2 * (1.0 / 3.0 - x2 * (1.0 / 5.0 - x2 * (1.0 / 7.0))))
                            : 2.0 * std::atan2(s, q.w) / s;
  return f * u;
}

// The square root of a unit q on the shorter arc: the rotation by half the angle about the same axis,
// (1 + w, u) / sqrt(2 (1 + w)) with w >= 0.
inline Quat half_rotation(Quat q) {
  if (q.w < 0) q = {-q.w, -q.x, -q.y, -q.z};
  const double s = 1.0 / std::sqrt(2.0 * (1.0 + q.w));
  return {s * (1.0 + q.w), s * q.x, s * q.y, s * q.z};
}

}  // namespace rbdem
