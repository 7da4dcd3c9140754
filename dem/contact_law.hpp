// Contact laws of the linear parallel bond model (THEORY.md 4 and 4b). Small value types, one function each,
// no I/O, history passed in explicitly.
//
// LinearContact: the infinitesimal, no-tension, frictional part. Normal force from the overlap area through
// Feng, Han and Owen's potential w(A_o) = k_n t A_o^2 / (2 L_ref):
//   F_n = w'(A_o) l_c = k_n t A_o l_c / L_ref    (k_n = E*/d in Pa/m; A_o overlap area, m^2; l_c the chord)
//   dF_s = -k_s t l_c ds,  |F_s| <= mu F_n.
// For a whole edge in contact l_c = L_ref = L and F_n = k_n t A_o = k_n L t delta, THEORY.md 4b's law. Where the
// edge is only partly closed, or a vertex touches a face, the l_c / L_ref factor makes the force the gradient of
// w: the plain k_n t A_o law at the chord midpoint is not conservative there, and its non-symmetric tangent made
// the explicit scheme diverge at 0.6 x the linear stability limit (docs/model.md).
// It is the same law for the linear part of an intact bond (A_o from the bond's own kinematics: the compressed
// part of the edge) and for every later contact (A_o from polygon clipping), so a bond breaking under
// compression hands its linear force over without a jump.
//
// ParallelBond: the finite bonded interface, total co-rotated formulation (see docs/model.md):
//   F_n = -kb_n A delta_n,  F_s = -kb_s A delta_s,  M = -kb_n I dtheta    (A = L t, I = t L^3 / 12)
//   sigma = -F_n/A + beta_m |M| R / I,   tau = |F_s| / A                    (tension positive)
//   tensile break: sigma >= sigma_c;  shear break: tau >= c - min(sigma_n, sigma_c) tan(phi_b), sigma_n = -F_n/A.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace rbdem {

enum class BreakMode : std::uint8_t { none = 0, tensile = 1, shear = 2 };

struct LinearContact {
  double kn = 0;    // Pa/m, normal stiffness per unit area (E*/d)
  double ks = 0;    // Pa/m, shear stiffness per unit area (kn / kappa)
  double mu = 0;    // Coulomb coefficient
  double lref = 1;  // m, reference chord L_ref of the potential (the edge length for a bond)

  // Normal force (compression positive) for an overlap area per unit thickness (m^2), chord (m), thickness t.
  double normal_force(double area, double chord, double t) const { return kn * t * area * chord / lref; }

  // Updates the shear force `fs` (N, along the tangent) for a tangential displacement increment `ds` (m) over a
  // chord `chord` (m) under normal force `fn`. Returns true when the contact slides.
  bool update_shear(double fn, double chord, double t, double ds, double& fs) const {
    if (!(fn > 0.0)) {
      fs = 0.0;
      return false;
    }
    fs -= ks * t * chord * ds;
    const double limit = mu * fn;
    if (std::abs(fs) > limit) {
      fs = std::copysign(limit, fs);
      return true;
    }
    return false;
  }
};

struct BondStrength {
  double sigma_c = 0;    // Pa, tensile strength
  double cohesion = 0;   // Pa
  double tan_phi = 0;    // tan of the bond friction angle
  double beta_m = 1.0;   // moment contribution factor

  // Peripheral stresses of a bond with force fn (compression positive), shear fs, moment m; area A, inertia I,
  // radius R. Returns the failure mode (tensile first, as in PFC) or none.
  BreakMode check(double fn, double fs, double m, double A, double I, double R, double& sigma, double& tau) const {
    const double sigma_n = -fn / A;
    sigma = sigma_n + beta_m * std::abs(m) * R / I;
    tau = std::abs(fs) / A;
    if (sigma >= sigma_c) return BreakMode::tensile;
    if (tau >= cohesion - std::min(sigma_n, sigma_c) * tan_phi) return BreakMode::shear;
    return BreakMode::none;
  }
};

// The macroscopic Mohr-Coulomb envelope tau = c + sigma tan(phi) of a bonded interface (compression positive),
// for comparing a joint of bonds with Jaeger's plane of weakness. In compression the linear part and the parallel
// bond share the traction in proportion to their stiffnesses, which are equal here (same E* and kappa), so the
// bond sees half of it. Sticking linear part: the bond fails at tau/2 = c + (sigma/2) tan(phi_b), i.e.
// tau = 2c + sigma tan(phi_b). Linear part sliding at mu: it carries mu sigma/2 of the shear and the bond fails
// at tau - mu sigma/2 = c + (sigma/2) tan(phi_b), i.e. tau = c + sigma (mu + tan(phi_b))/2.
struct MohrCoulomb {
  double cohesion = 0;  // Pa
  double tan_phi = 0;
};
inline MohrCoulomb interface_envelope(double cohesion, double tan_phi_bond, double mu, bool slip_when_bonded) {
  if (!slip_when_bonded) return {2.0 * cohesion, tan_phi_bond};
  return {cohesion, 0.5 * (mu + tan_phi_bond)};
}

// Overlap of the linear part of an intact bond from its kinematics: the edge of length L, centre opening
// delta_n (positive when opening) and relative rotation dtheta. Along the edge s in [-L/2, L/2] the overlap is
// u(s) = -delta_n + s dtheta; A_o is the integral of max(u, 0), the chord the compressed interval, and
// `s_c` the chord's midpoint (the contact point, as in the clipped contact).
struct EdgeOverlap {
  double area = 0, chord = 0, s_c = 0;
};
inline EdgeOverlap edge_overlap(double L, double delta_n, double dtheta) {
  const double h = 0.5 * L;
  const double u0 = -delta_n - h * dtheta, u1 = -delta_n + h * dtheta;  // overlap at s = -L/2 and s = +L/2
  EdgeOverlap e;
  if (u0 >= 0.0 && u1 >= 0.0) {
    e.area = -delta_n * L;
    e.chord = L;
    return e;
  }
  if (u0 <= 0.0 && u1 <= 0.0) return e;
  // Partly compressed: the overlap is a triangle from the zero crossing s0 to the compressed end.
  const double s0 = delta_n / dtheta;  // u(s0) = 0
  if (u1 > 0.0) {
    e.chord = h - s0;
    e.area = 0.5 * u1 * e.chord;
    e.s_c = 0.5 * (s0 + h);
  } else {
    e.chord = s0 + h;
    e.area = 0.5 * u0 * e.chord;
    e.s_c = 0.5 * (s0 - h);
  }
  return e;
}

}  // namespace rbdem
