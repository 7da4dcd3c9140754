// The linear parallel bond on a triangular face: the three-dimensional bond of two tetrahedral blocks
// (docs/theory.md, "The face bond in 3D"). The same law as the edge bond of dem/laws/parallel_bond.hpp one
// dimension up, with the face's exact section; small value types, no I/O, the history passed in. The kinematics
// (the relative motion of the two blocks in the co-rotated face frame) is dem/stages/face_bond_kernel.hpp.
//
// Face frame (e1, e2, n): n from block i to block j, e1 and e2 the in-plane principal axes through the face's
// centroid (dem/geometry3.hpp: area A, second moments I1 = int y2^2 dA, I2 = int y1^2 dA, polar J = I1 + I2).
// With kb_n = E*/d (d the centroid distance along n) and kb_s = kb_n / kappa per unit area, the relative motion
// (opening delta_n, slip delta_1, delta_2, rotations theta_1, theta_2 about e1, e2, twist theta_n) gives
//     F_n = -kb_n A delta_n  (compression positive),  F_s,k = -kb_s A delta_k,
//     M_k = -kb_n I_k theta_k  (bending),             M_t = -kb_s J theta_n  (twist),
// the gradients of the bond's energy 1/2 int (kb_n w^2 + kb_s |s|^2) dA over the face, w(y) = delta_n +
// theta_1 y2 - theta_2 y1 the opening and s the slip at y.
// Peripheral stresses (tension positive). The normal stress is linear over the face,
//     sigma(y) = -F_n / A - M_1 y2 / I1 + M_2 y1 / I2,
// so its largest value is at a vertex: sigma = -F_n / A + beta_m max_k (-M_1 y2_k / I1 + M_2 y1_k / I2), exact for
// the triangle (the 2D bond's |M| R / I is the same maximum over the edge's two ends). Shear with twist, at the
// face's extreme fibre r_max (the largest centroid-to-vertex distance, as PFC's R for a disc):
//     tau = |F_s| / A + beta_m |M_t| r_max / J.
// Failure as in 2D (BondLoad, in force units): tensile when sigma >= sigma_c, shear when
// tau >= c - min(sigma_n, sigma_c) tan(phi_b) with sigma_n = -F_n / A. Softening by the fracture energy as in 2D:
// r_u = 2 G_f E* / (sigma_c^2 d) = softening K / A with softening = 2 G_f / sigma_c^2.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "dem/geometry3.hpp"
#include "dem/laws/linear_contact.hpp"
#include "dem/laws/parallel_bond.hpp"

namespace rbdem {

// A face bond's stiffnesses: kb_n A, kb_s A (N/m) on the opening and the slip, kb_n I1, kb_n I2 on the bending
// about e1 and e2 and kb_s J on the twist (N m).
struct FaceStiffness {
  double kn = 0, ks = 0, kb1 = 0, kb2 = 0, kt = 0;
};

// The section the law reads: A, I1, I2, J, r_max and the vertices (y1, y2) from the face's centroid.
struct FaceSection {
  double A = 0, I1 = 0, I2 = 0, J = 0, r_max = 0;
  std::array<double, 3> y1{}, y2{};
  static FaceSection of(const Face& f) { return {f.area, f.I1, f.I2, f.J, f.r_max, f.y1, f.y2}; }
};

// The relative motion of the pair in the face frame and the bond's undamaged forces there (compression positive;
// force and moments act on block j).
struct FaceMotion {
  double d1 = 0, d2 = 0, dn = 0;  // slip along e1, e2 and opening (m)
  double t1 = 0, t2 = 0, tn = 0;  // rotation of j relative to i about e1, e2, n (rad)
};
struct FaceForces {
  double fs1 = 0, fs2 = 0, fn = 0;  // N
  double m1 = 0, m2 = 0, mt = 0;    // N m
};

struct FaceBond {
  double inv_kappa = 1.0;  // k_s / k_n
  BondStrength strength;   // sigma_c, c, tan(phi_b), beta_m as the 2D bond's
  double softening = 0;    // 2 G_f / sigma_c^2 (m^3 / N); 0 = brittle

  FaceStiffness stiffness(double modulus, double d, const FaceSection& s) const {
    const double kn = modulus / d, ks = kn * inv_kappa;
    return {kn * s.A, ks * s.A, kn * s.I1, kn * s.I2, ks * s.J};
  }
  static FaceForces forces(const FaceStiffness& k, const FaceMotion& u) {
    return {-k.ks * u.d1, -k.ks * u.d2, -k.kn * u.dn, -k.kb1 * u.t1, -k.kb2 * u.t2, -k.kt * u.tn};
  }

  // The elastic energy (J) the parallel bond stores at the forces f: 1/2 (F_n^2 / K_n + |F_s|^2 / K_s + M_1^2 /
  // kb_1 + M_2^2 / kb_2 + M_t^2 / kb_t).
  static double strain_energy(const FaceStiffness& k, const FaceForces& f) {
    return 0.5 * (f.fn * f.fn / k.kn + (f.fs1 * f.fs1 + f.fs2 * f.fs2) / k.ks + f.m1 * f.m1 / k.kb1 +
                  f.m2 * f.m2 / k.kb2 + f.mt * f.mt / k.kt);
  }

  // The largest bending stress times A over the face's vertices: A max_k (-M_1 y2_k / I1 + M_2 y1_k / I2) (N).
  static double bending_load(const FaceSection& s, double m1, double m2) {
    double top = -std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k)
      top = std::max(top, -m1 * s.y2[std::size_t(k)] / s.I1 + m2 * s.y1[std::size_t(k)] / s.I2);
    return s.A * top;
  }
  // The failure test in force units (BondLoad of dem/laws/parallel_bond.hpp): tension sigma A, shear tau A and
  // their limits, from the undamaged forces.
  BondLoad load(const FaceSection& s, const FaceForces& f) const {
    const BondStrength& st = strength;
    const double sigma_c_A = st.sigma_c * s.A;
    const double shear = std::sqrt(f.fs1 * f.fs1 + f.fs2 * f.fs2) + st.beta_m * s.A * std::abs(f.mt) * s.r_max / s.J;
    return {-f.fn + st.beta_m * bending_load(s, f.m1, f.m2), sigma_c_A, shear,
            st.cohesion * s.A - std::min(-f.fn, sigma_c_A) * st.tan_phi};
  }
  // Peripheral stresses (Pa): sigma (tension positive) and tau.
  void stresses(const FaceSection& s, const FaceForces& f, double& sigma, double& tau) const {
    const BondLoad q = load(s, f);
    sigma = q.tension / s.A, tau = q.shear / s.A;
  }

  // The failure index at which a softening bond of normal stiffness K = kb_n A breaks: r_u = softening K / A.
  double rupture_index(double K, double A) const { return softening * K / A; }
  // Softening and breakage exactly as the 2D bond's (ParallelBond::advance: brittle, or linear softening in the
  // failure index to r_u), with the face's load.
  BreakMode advance(const BondLoad& q, double r_u, double& drive) const {
    ParallelBond rule;  // advance reads only `softening`
    rule.softening = softening;
    return rule.advance(q, r_u, drive);
  }
  static double intact_fraction(double r, double r_u) { return ParallelBond::intact_fraction(r, r_u); }
};

// The compressed part of a face of the linear part: the overlap u(y) = -w(y) = -(delta_n + theta_1 y2 -
// theta_2 y1) clipped to u >= 0 over the triangle. `volume` = int max(u, 0) dA (m^3), `area` the compressed area
// (m^2) and (c1, c2) its centroid (m), where the linear part's force acts.
struct FaceOverlap {
  double volume = 0, area = 0, c1 = 0, c2 = 0;
};
inline FaceOverlap face_overlap(const FaceSection& s, double dn, double t1, double t2) {
  auto u = [&](double y1, double y2) { return -(dn + t1 * y2 - t2 * y1); };
  std::array<double, 3> uk;
  for (int k = 0; k < 3; ++k) uk[std::size_t(k)] = u(s.y1[std::size_t(k)], s.y2[std::size_t(k)]);
  FaceOverlap o;
  if (uk[0] >= 0 && uk[1] >= 0 && uk[2] >= 0) return {-dn * s.A, s.A, 0.0, 0.0};  // closed: the exact section
  // The triangle clipped by u >= 0 (Sutherland-Hodgman on one plane): at most four vertices.
  double p1[4], p2[4];
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    const std::size_t a = std::size_t(k), b = std::size_t((k + 1) % 3);
    if (uk[a] >= 0) p1[n] = s.y1[a], p2[n] = s.y2[a], ++n;
    if ((uk[a] >= 0) != (uk[b] >= 0)) {
      const double f = uk[a] / (uk[a] - uk[b]);
      p1[n] = s.y1[a] + f * (s.y1[b] - s.y1[a]), p2[n] = s.y2[a] + f * (s.y2[b] - s.y2[a]), ++n;
    }
  }
  if (n < 3) return o;
  // Area and centroid by the shoelace formula, from the first vertex; the overlap is linear, so its integral is
  // the area times its value at the centroid.
  double a2 = 0, cx = 0, cy = 0;
  for (int k = 1; k + 1 < n; ++k) {
    const double ax = p1[k] - p1[0], ay = p2[k] - p2[0], bx = p1[k + 1] - p1[0], by = p2[k + 1] - p2[0];
    const double t = ax * by - ay * bx;
    a2 += t, cx += t * (p1[0] + p1[k] + p1[k + 1]), cy += t * (p2[0] + p2[k] + p2[k + 1]);
  }
  if (!(std::abs(a2) > 0)) return o;
  o.area = 0.5 * std::abs(a2), o.c1 = cx / (3.0 * a2), o.c2 = cy / (3.0 * a2);
  o.volume = o.area * std::max(0.0, u(o.c1, o.c2));
  return o;
}

// The linear part's forces on the compressed part of the face: the linear contact law (dem/laws/linear_contact.hpp)
// one dimension up, the potential k_n V^2 / (2 A) of the overlap volume V over the face of area A, so
// F_n = K V A_c / A^2 (K = kb_n A; a closed face gives kb_n A (-delta_n), the parallel bond's normal stiffness),
// and the incremental shear dF_s = -K_s (A_c / A) v_s dt as a vector in the face plane, Coulomb-limited to
// |F_s| <= mu F_n (scaled back along itself), none without a normal force.
struct FaceLinearPart {
  double fn = 0, fs1 = 0, fs2 = 0;  // N
  bool slides = false;
};
inline FaceLinearPart face_linear_part(const LinearContact& law, const FaceOverlap& o, double vs1, double vs2,
                                       double dt, double fs1, double fs2) {
  FaceLinearPart out;
  out.fn = law.normal_force(o.volume, o.area);  // K V A_c / A^2: inv_lref is 1 / A here
  const double c = -law.Ks * o.area * law.inv_lref * dt;
  const double t1 = fs1 + c * vs1, t2 = fs2 + c * vs2, mag = std::sqrt(t1 * t1 + t2 * t2), limit = law.mu * out.fn;
  const double scale = mag > limit ? limit / mag : 1.0;
  out.slides = out.fn > 0.0 && mag > limit;
  out.fs1 = out.fn > 0.0 ? scale * t1 : 0.0, out.fs2 = out.fn > 0.0 ? scale * t2 : 0.0;
  return out;
}

}  // namespace rbdem
