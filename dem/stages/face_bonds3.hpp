// The 3D bond stage's data and kernel: the face bonds' constants as arrays in bond order (structure of arrays), one
// record of kinematics per block with its rotation matrix, and the bond's forces from them. The same kinematics and
// laws as eval_face_bond (face_bond_kernel.hpp), arranged for speed: the rotation of each block is turned into a
// matrix once per step (the block stage writes it), so a bond turns its lever arms by matrix-vector products; the
// strengths are in force units with the bond's Weibull factor folded in when the model is built; the failure test
// reads the undamaged forces the kernel computed. Only round-off separates the two (the products are grouped
// differently); docs/performance.md, "The 3D engine".
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "dem/laws/face_bond.hpp"
#include "dem/laws/linear_contact.hpp"
#include "dem/vec3.hpp"

namespace rbdem::stages {

// One block as the bond stage reads it: centroid, rotation from rest as a quaternion and as the matrix R (R v =
// q v q*), velocity and angular velocity (world). 24 doubles, three cache lines.
struct BlockRecord3 {
  Vec3 x;
  Quat q;
  Mat3 R;
  Vec3 v, omega;
  double pad[2] = {0, 0};
};
static_assert(sizeof(BlockRecord3) == 24 * sizeof(double));

inline BlockRecord3 block_record(Vec3 x, Quat q, Vec3 v, Vec3 omega) { return {x, q, matrix(q), v, omega}; }

// The face bonds' constants, one array of doubles per field, in bond order.
class FaceBondTable {
 public:
  enum Field {
    rix, riy, riz, rjx, rjy, rjz,  // m, the face centroid from i's and j's centroid at rest
    e1x, e1y, e1z, e2x, e2y, e2z, nx, ny, nz,  // the face frame at rest, by rows
    kn, ks, kb1, kb2, kt,  // FaceStiffness
    area, inv_area,        // m^2, 1/m^2
    y1a, y1b, y1c, y2a, y2b, y2c,  // m, the face's vertices from its centroid in (e1, e2)
    bend1, bend2,          // beta_m A / I1, beta_m A / I2 (1/m^2): the bending moments' share of the tensile load
    twist,                 // beta_m A r_max / J (1/m): the twist's share of the shear load
    tension_limit,         // N, sigma_c A w (w the bond's strength factor)
    cohesion_A,            // N, c A w
    tan_phi,               // tan(phi_b)
    mu_bonded, mu_broken,  // the linear part's friction while the bond is intact (+inf: sticks) and once broken
    softening,             // 2 G_f / sigma_c^2 of the material (0: brittle)
    rupture,               // r_u, the failure index at which a softening bond breaks
    count
  };

  void resize(std::size_t n) { n_ = n, data_.assign(std::size_t(count) * n, 0.0); }
  std::size_t size() const { return n_; }
  double* operator[](Field f) { return data_.data() + std::size_t(f) * n_; }
  const double* operator[](Field f) const { return data_.data() + std::size_t(f) * n_; }
  double at(Field f, std::size_t b) const { return data_[std::size_t(f) * n_ + b]; }

 private:
  std::size_t n_ = 0;
  std::vector<double> data_;
};

// One bond's forces at the blocks' records I and J.
struct FaceBondOut {
  FaceForces pb;          // the parallel bond's undamaged forces (face frame; failure reads these)
  FaceLinearPart linear;  // the linear part; (fs1, fs2) the new shear history
  Vec3 f, mi, mj;         // the force on j (-f on i) and the moments on i and j about their centroids (world)
  Vec3 ci;                // the bond point from i's centroid
  Vec3 normal;            // the face normal now (world)
};

// Bond b's forces, as eval_face_bond: `keep` (1 - damage, 0 when broken) scales the parallel bond, `mu` is the
// linear part's friction (mu_bonded or mu_broken), (fs1, fs2) its shear history, dt = 0 evaluates without advancing.
[[gnu::always_inline]] inline FaceBondOut face_bond_forces(const FaceBondTable& t, std::size_t b,
                                                           const BlockRecord3& I, const BlockRecord3& J, double dt,
                                                           double fs1, double fs2, double keep, double mu) {
  using F = FaceBondTable;
  FaceBondOut out;
  // The relative rotation (shorter arc) and the mean rotation q_i sqrt(q_i* q_j) the face frame turns with.
  Quat rel = conj(I.q) * J.q;
  if (rel.w < 0) rel = {-rel.w, -rel.x, -rel.y, -rel.z};
  const Mat3 Rm = matrix(I.q * half_rotation(rel));
  const Vec3 a0{t.at(F::e1x, b), t.at(F::e1y, b), t.at(F::e1z, b)};
  const Vec3 a1{t.at(F::e2x, b), t.at(F::e2y, b), t.at(F::e2z, b)};
  const Vec3 a2{t.at(F::nx, b), t.at(F::ny, b), t.at(F::nz, b)};
  const Mat3 frame{{Rm * a0, Rm * a1, Rm * a2}};
  const Vec3 ai = I.R * Vec3{t.at(F::rix, b), t.at(F::riy, b), t.at(F::riz, b)};
  const Vec3 aj = J.R * Vec3{t.at(F::rjx, b), t.at(F::rjy, b), t.at(F::rjz, b)};
  const Vec3 g = (J.x + aj) - (I.x + ai);
  const Vec3 ci = ai + 0.5 * g, cj = aj - 0.5 * g;
  const Vec3 d = frame * g, th = rotation_vector(rel);
  const Vec3 tt{dot(a0, th), dot(a1, th), dot(a2, th)};
  const double kn = t.at(F::kn, b), ks = t.at(F::ks, b);
  out.pb = {-ks * d.x, -ks * d.y, -kn * d.z, -t.at(F::kb1, b) * tt.x, -t.at(F::kb2, b) * tt.y, -t.at(F::kt, b) * tt.z};
  // The linear part on the compressed part of the face; the slip rate at that part's centroid.
  FaceSection sec;
  sec.A = t.at(F::area, b);
  sec.y1 = {t.at(F::y1a, b), t.at(F::y1b, b), t.at(F::y1c, b)};
  sec.y2 = {t.at(F::y2a, b), t.at(F::y2b, b), t.at(F::y2c, b)};
  const FaceOverlap o = face_overlap(sec, d.z, tt.x, tt.y);
  const Vec3 lever = frame.transposed_times({o.c1, o.c2, 0.0});
  const Vec3 vrel = (J.v + cross(J.omega, cj + lever)) - (I.v + cross(I.omega, ci + lever));
  const Vec3 vs = frame * vrel;
  out.linear = face_linear_part({kn, ks, mu, t.at(F::inv_area, b)}, o, vs.x, vs.y, dt, fs1, fs2);
  // The force and the couple about the bond point in the face frame (the linear part's force acts at (c1, c2, 0);
  // the frame is right-handed, so its moment is the cross product there), then to world once each.
  const FaceForces& p = out.pb;
  const FaceLinearPart& l = out.linear;
  const Vec3 f = frame.transposed_times({keep * p.fs1 + l.fs1, keep * p.fs2 + l.fs2, keep * p.fn + l.fn});
  const Vec3 c = frame.transposed_times({keep * p.m1 + o.c2 * l.fn, keep * p.m2 - o.c1 * l.fn,
                                         keep * p.mt + (o.c1 * l.fs2 - o.c2 * l.fs1)});
  out.f = f;
  out.mj = cross(cj, f) + c;
  out.mi = -(cross(ci, f) + c);
  out.ci = ci;
  out.normal = frame.r[2];
  return out;
}

// The failure test's load (BondLoad, force units) from the undamaged forces `pb`: FaceBond::load with the section
// and the strength read from the table.
inline BondLoad face_bond_load(const FaceBondTable& t, std::size_t b, const FaceForces& pb) {
  using F = FaceBondTable;
  const double u1 = -pb.m1 * t.at(F::bend1, b), u2 = pb.m2 * t.at(F::bend2, b);
  const double bend = std::max({u1 * t.at(F::y2a, b) + u2 * t.at(F::y1a, b), u1 * t.at(F::y2b, b) + u2 * t.at(F::y1b, b),
                                u1 * t.at(F::y2c, b) + u2 * t.at(F::y1c, b)});
  const double limit = t.at(F::tension_limit, b);
  const double shear = std::sqrt(pb.fs1 * pb.fs1 + pb.fs2 * pb.fs2) + t.at(F::twist, b) * std::abs(pb.mt);
  return {-pb.fn + bend, limit, shear, t.at(F::cohesion_A, b) - std::min(-pb.fn, limit) * t.at(F::tan_phi, b)};
}

}  // namespace rbdem::stages
