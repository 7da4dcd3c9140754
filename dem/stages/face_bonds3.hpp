// The 3D bond stage's data and kernel: the face bonds' constants in tiles of 64 bonds, one record of kinematics per
// block, and the bond's forces from them. The same kinematics and laws as eval_face_bond (face_bond_kernel.hpp),
// arranged for speed: the strengths are in force units with the bond's Weibull factor folded in when the model is
// built; the failure test reads the undamaged forces the kernel computed. Only round-off separates the two (the
// products are grouped differently); docs/performance.md, "The 3D engine".
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "dem/laws/face_bond.hpp"
#include "dem/laws/linear_contact.hpp"
#include "dem/vec3.hpp"

namespace rbdem::stages {

// One block as the bond stage reads it: centroid, rotation from rest, velocity and angular velocity (world). 16
// doubles, two cache lines.
struct alignas(64) BlockRecord3 {
  Vec3 x;
  Quat q;
  Vec3 v, omega;
  double pad[3] = {0, 0, 0};
};
static_assert(sizeof(BlockRecord3) == 16 * sizeof(double));

inline BlockRecord3 block_record(Vec3 x, Quat q, Vec3 v, Vec3 omega) { return {x, q, v, omega}; }

// The face bonds' constants in tiles of kTile bonds: a tile holds each field's kTile values side by side (field f
// of the tile's k-th bond at f kTile + k), and the tiles follow in bond order. A chunk of the kernel is one tile,
// so it reads one contiguous stretch of memory, which the hardware prefetcher follows, where one array per field
// made 38 streams at once, more than it tracks.
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
  static constexpr std::size_t kTile = 64;  // bonds per tile: the kernel's chunk

  void resize(std::size_t n) { n_ = n, data_.assign(std::size_t(count) * kTile * ((n + kTile - 1) / kTile), 0.0); }
  std::size_t size() const { return n_; }
  double& at(Field f, std::size_t b) { return data_[index(f, b)]; }
  double at(Field f, std::size_t b) const { return data_[index(f, b)]; }
  // The first value of the tile of bond b (a multiple of kTile for the chunk that starts there).
  const double* tile(std::size_t b) const { return data_.data() + (b / kTile) * std::size_t(count) * kTile; }

 private:
  static std::size_t index(Field f, std::size_t b) {
    return (b / kTile) * std::size_t(count) * kTile + std::size_t(f) * kTile + b % kTile;
  }
  std::size_t n_ = 0;
  std::vector<double> data_;
};

// One bond's forces at the blocks' records I and J.
// Plain doubles, each stored on its own: a vectorised loop takes no copies of aggregates.
struct FaceBondOut {
  FaceForces pb;                     // the parallel bond's undamaged forces (face frame; failure reads these)
  double fn_lin, fs1_lin, fs2_lin;   // the linear part (face frame); (fs1, fs2) the new shear history
  Vec3 f, mi, mj;         // the force on j (-f on i) and the moments on i and j about their centroids (world)
  Vec3 ci;                // the bond point from i's centroid
  Vec3 normal;            // the face normal now (world)
};

// What the gather reads of one bond: the force on j (-f on i) and the moments on i and j (world).
struct FaceBondSlot {
  Vec3 f, mi, mj;
};

// dst = v member by member.
[[gnu::always_inline]] inline void store(Vec3& dst, Vec3 v) { dst.x = v.x, dst.y = v.y, dst.z = v.z; }

// One tile of the table as a base and its stride, for a kernel to index without reloading the table: field f of
// the tile's k-th bond is base[f kTile + k], an address the vectoriser follows lane by lane. `of` gives bond b's
// tile; the bond is then at k = lane(b).
struct FaceBondColumns {
  const double* base;
  static FaceBondColumns of(const FaceBondTable& t, std::size_t b) { return {t.tile(b)}; }
  static std::size_t lane(std::size_t b) { return b % FaceBondTable::kTile; }
  double operator()(FaceBondTable::Field f, std::size_t k) const {
    return base[std::size_t(f) * FaceBondTable::kTile + k];
  }
};

// FaceBond::intact_fraction without branches (a kernel's vector lanes call it): the same numbers.
inline double intact_fraction(double r, double r_u) {
  const double partial = (r_u - r) / (r * (r_u - 1.0));
  return r <= 1.0 ? 1.0 : (r >= r_u ? 0.0 : partial);
}

// face_overlap (dem/laws/face_bond.hpp) without branches, for the vector lanes: the overlap u_k = -(dn + t1 y2_k -
// t2 y1_k) at the vertices, the triangle (area A, centroid at the origin) clipped to u >= 0. A partly open face has
// one vertex whose sign differs from the other two's; the line u = 0 cuts the corner triangle at it, of area
// t_b t_c A (t = u_a / (u_a - u_k) along its two edges) and centroid (P_a + Q_b + Q_c) / 3. The compressed part is
// that corner when that vertex is the closed one, else the face less the corner. The same area and centroid as the
// clipped polygon to round-off.
[[gnu::always_inline]] inline FaceOverlap face_overlap_lanes(double A, const double y1[3], const double y2[3],
                                                            double dn, double t1, double t2) {
  const double u0 = -(dn + t1 * y2[0] - t2 * y1[0]), u1 = -(dn + t1 * y2[1] - t2 * y1[1]);
  const double u2 = -(dn + t1 * y2[2] - t2 * y1[2]);
  const bool s0 = u0 >= 0, s1 = u1 >= 0, s2 = u2 >= 0;
  const bool closed = s0 & s1 & s2, open = !(s0 | s1 | s2);
  // The lone vertex a and the next two, b and c.
  const bool l0 = (s0 != s1) & (s0 != s2), l1 = (s1 != s0) & (s1 != s2);
  const double ua = l0 ? u0 : (l1 ? u1 : u2), ub = l0 ? u1 : (l1 ? u2 : u0), uc = l0 ? u2 : (l1 ? u0 : u1);
  const double pa1 = l0 ? y1[0] : (l1 ? y1[1] : y1[2]), pa2 = l0 ? y2[0] : (l1 ? y2[1] : y2[2]);
  const double pb1 = l0 ? y1[1] : (l1 ? y1[2] : y1[0]), pb2 = l0 ? y2[1] : (l1 ? y2[2] : y2[0]);
  const double pc1 = l0 ? y1[2] : (l1 ? y1[0] : y1[1]), pc2 = l0 ? y2[2] : (l1 ? y2[0] : y2[1]);
  const double tb = ua / (ua - ub), tc = ua / (ua - uc);
  const double corner = tb * tc * A;
  const double g1 = (3.0 * pa1 + tb * (pb1 - pa1) + tc * (pc1 - pa1)) / 3.0;
  const double g2 = (3.0 * pa2 + tb * (pb2 - pa2) + tc * (pc2 - pa2)) / 3.0;
  const bool lone_closed = ua >= 0;
  const double rest = A - corner, w = -corner / rest;  // the face less the corner: its centroid -corner g / rest
  const double area = closed ? A : (open ? 0.0 : (lone_closed ? corner : rest));
  const double c1 = closed | open ? 0.0 : (lone_closed ? g1 : w * g1);
  const double c2 = closed | open ? 0.0 : (lone_closed ? g2 : w * g2);
  const double uc0 = -(dn + t1 * c2 - t2 * c1);
  const double volume = closed ? -dn * A : area * (uc0 > 0.0 ? uc0 : 0.0);
  return {volume, area, c1, c2};
}

// The forces of the bond at lane k of the tile t, as eval_face_bond: `keep` (1 - damage, 0 when broken) scales the
// parallel bond, `mu` is the linear part's friction (mu_bonded or mu_broken), (fs1, fs2) its shear history, dt = 0
// evaluates without advancing.
//
// Exact = true is the whole law. Exact = false is the same arithmetic without branches, for the vector lanes, where
// the relative rotation is below the series' bound (rotation_vector, dem/vec3.hpp); elsewhere it sets `regular` to
// 0 and the bond needs the exact form. Where it does not, both give the same numbers bit for bit (the same
// operations in the same order), so which one computed a bond never shows. Both clip the face by
// face_overlap_lanes.
template <bool Exact>
[[gnu::always_inline]] inline FaceBondOut face_bond_forces(const FaceBondColumns& t, std::size_t k,
                                                           const BlockRecord3& I, const BlockRecord3& J, double dt,
                                                           double fs1, double fs2, double keep, double mu,
                                                           std::int64_t& regular) {
  using F = FaceBondTable;
  // The relative rotation (shorter arc) and the mean rotation q_i sqrt(q_i* q_j) the face frame turns with.
  const Quat r0 = conj(I.q) * J.q;
  const double sg = r0.w < 0 ? -1.0 : 1.0;
  const Quat rel{sg * r0.w, sg * r0.x, sg * r0.y, sg * r0.z};
  const double hs = 1.0 / std::sqrt(2.0 * (1.0 + rel.w));  // half_rotation
  const Mat3 Rm = matrix(I.q * Quat{hs * (1.0 + rel.w), hs * rel.x, hs * rel.y, hs * rel.z});
  const Vec3 a0{t(F::e1x, k), t(F::e1y, k), t(F::e1z, k)};
  const Vec3 a1{t(F::e2x, k), t(F::e2y, k), t(F::e2z, k)};
  const Vec3 a2{t(F::nx, k), t(F::ny, k), t(F::nz, k)};
  const Mat3 frame{{Rm * a0, Rm * a1, Rm * a2}};
  const Vec3 ai = rotate(I.q, {t(F::rix, k), t(F::riy, k), t(F::riz, k)});
  const Vec3 aj = rotate(J.q, {t(F::rjx, k), t(F::rjy, k), t(F::rjz, k)});
  const Vec3 g = (J.x + aj) - (I.x + ai);
  const Vec3 ci = ai + 0.5 * g, cj = aj - 0.5 * g;
  const Vec3 d = frame * g;
  // rotation_vector(rel): the series below s = 5e-3, atan2 above (Exact only).
  const double s = norm(rel.vec()), x2 = s * s / (rel.w * rel.w);
  const double series = 2.0 / rel.w * (1.0 - x2 * (1.0 / 3.0 - x2 * (1.0 / 5.0 - x2 * (1.0 / 7.0))));
  double scale = series;
  if constexpr (Exact) {
    if (!(s < 5e-3)) scale = 2.0 * std::atan2(s, rel.w) / s;
  } else {
    regular &= std::int64_t(s < 5e-3);
  }
  const Vec3 th = scale * rel.vec();
  const Vec3 tt{dot(a0, th), dot(a1, th), dot(a2, th)};
  const double kn = t(F::kn, k), ks = t(F::ks, k);
  const FaceForces p{-ks * d.x, -ks * d.y, -kn * d.z, -t(F::kb1, k) * tt.x, -t(F::kb2, k) * tt.y, -t(F::kt, k) * tt.z};
  // The linear part on the compressed part of the face; the slip rate at that part's centroid.
  const double A = t(F::area, k);
  const double y1[3] = {t(F::y1a, k), t(F::y1b, k), t(F::y1c, k)}, y2[3] = {t(F::y2a, k), t(F::y2b, k), t(F::y2c, k)};
  const FaceOverlap o = face_overlap_lanes(A, y1, y2, d.z, tt.x, tt.y);
  const Vec3 lever = frame.transposed_times({o.c1, o.c2, 0.0});
  const Vec3 vrel = (J.v + cross(J.omega, cj + lever)) - (I.v + cross(I.omega, ci + lever));
  const Vec3 vs = frame * vrel;
  const FaceLinearPart l = face_linear_part({kn, ks, mu, t(F::inv_area, k)}, o, vs.x, vs.y, dt, fs1, fs2);
  // The force and the couple about the bond point in the face frame (the linear part's force acts at (c1, c2, 0);
  // the frame is right-handed, so its moment is the cross product there), then to world once each.
  const Vec3 f = frame.transposed_times({keep * p.fs1 + l.fs1, keep * p.fs2 + l.fs2, keep * p.fn + l.fn});
  const Vec3 c = frame.transposed_times({keep * p.m1 + o.c2 * l.fn, keep * p.m2 - o.c1 * l.fn,
                                         keep * p.mt + (o.c1 * l.fs2 - o.c2 * l.fs1)});
  return {p, l.fn, l.fs1, l.fs2, f, -(cross(ci, f) + c), cross(cj, f) + c, ci, frame.r[2]};
}

// The failure test's load (BondLoad, force units) of the bond at lane k of t from its undamaged forces `pb`:
// FaceBond::load with the section and the strength read from the table. Without branches.
inline BondLoad face_bond_load(const FaceBondColumns& t, std::size_t k, const FaceForces& pb) {
  using F = FaceBondTable;
  const double u1 = -pb.m1 * t(F::bend1, k), u2 = pb.m2 * t(F::bend2, k);
  const double v0 = u1 * t(F::y2a, k) + u2 * t(F::y1a, k), v1 = u1 * t(F::y2b, k) + u2 * t(F::y1b, k);
  const double v2 = u1 * t(F::y2c, k) + u2 * t(F::y1c, k);
  const double v01 = v0 > v1 ? v0 : v1, bend = v01 > v2 ? v01 : v2;
  const double limit = t(F::tension_limit, k), tension = -pb.fn;
  const double shear = std::sqrt(pb.fs1 * pb.fs1 + pb.fs2 * pb.fs2) + t(F::twist, k) * std::abs(pb.mt);
  return {tension + bend, limit, shear, t(F::cohesion_A, k) - (tension < limit ? tension : limit) * t(F::tan_phi, k)};
}

}  // namespace rbdem::stages
