// The parallel bond of the linear parallel bond model (docs/theory.md, sections 5 and 6): the finite, bonded,
// linear elastic interface that carries force and moment until it breaks. Small value types, no I/O, no
// allocation; the bond's history (the largest failure index reached, `drive`) is passed in explicitly. Every user
// calls these functions: the engine's bond stage (dem/stages/bonds.cpp), the static solve's first-break load
// (dem/static_solve.cpp), the diagnostics and the unit tests (tests/test_laws.cpp).
//
// Stiffness (per bond of edge length L, thickness t, centroid distance d along the normal, kind of modulus E*
// and stiffness ratio kappa): K = (E*/d) L t on the normal opening (N/m), K / kappa on the shear, K L^2 / 12 on
// the relative rotation (N m), i.e. kb_n A, kb_s A and kb_n I with A = L t, I = t L^3 / 12.
// Forces in the co-rotated frame (total formulation, docs/model.md), compression positive:
//     F_n = -K delta_n,   F_s = -(K / kappa) delta_s,   M = -(K L^2 / 12) dtheta
// Peripheral stresses (tension positive): sigma = -F_n/A + beta_m |M| (L/2) / I, tau = |F_s| / A.
// Failure: tensile when sigma >= sigma_c (tested first, as in PFC); shear when
//     tau >= c - min(sigma_n, sigma_c) tan(phi_b),   sigma_n = -F_n / A,
// i.e. compression raises the shear strength, tension lowers it, and sigma_n is capped at sigma_c.
// The test runs in force units without divisions (BondLoad): sigma A = -F_n + beta_m |M| 6 / L, tau A = |F_s|.
// Softening (fracture_energy > 0): the failure index r = max(sigma / sigma_c, tau / shear limit) of the
// undamaged forces; past r = 1 the bond carries (1 - D) = (r_u - r) / (r (r_u - 1)) of its elastic forces and
// breaks at r_u = 2 G_f E* / (sigma_c^2 d) (crack band, docs/model.md "Softening bonds").
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace rbdem {

enum class BreakMode : std::uint8_t { none = 0, tensile = 1, shear = 2 };

struct BondStrength {
  double sigma_c = 0;    // Pa, tensile strength
  double cohesion = 0;   // Pa
  double tan_phi = 0;    // tan of the bond friction angle phi_b
  double beta_m = 1.0;   // moment contribution factor

  // Peripheral stresses (Pa) of a bond with force fn (N, compression positive), shear fs (N), moment m (N m);
  // area A (m^2), inertia I (m^4), radius R = L/2 (m). For records and diagnostics; the test is BondLoad.
  void stresses(double fn, double fs, double m, double A, double I, double R, double& sigma, double& tau) const {
    const double sigma_n = -fn / A;
    sigma = sigma_n + beta_m * std::abs(m) * R / I;
    tau = std::abs(fs) / A;
  }

  // The load factor lambda >= 0 at which a bond loaded proportionally (lambda fn, lambda fs, lambda m) reaches
  // its strength; +inf when it never does. The static solve's first-break load (dem/static_solve.cpp).
  double first_break_factor(double fn, double fs, double m, double A, double I, double R) const {
    double sigma = 0, tau = 0;
    stresses(fn, fs, m, A, I, R, sigma, tau);
    const double sn = -fn / A;
    double lam = std::numeric_limits<double>::infinity();
    if (sigma > 0) lam = std::min(lam, sigma_c / sigma);
    // shear: lam tau = c - min(lam sn, sigma_c) tan(phi)
    const double den = tau + sn * tan_phi;
    if (den > 0) {
      const double l1 = cohesion / den;
      if (l1 * sn <= sigma_c) lam = std::min(lam, l1);
    }
    if (tau > 0 && cohesion - sigma_c * tan_phi > 0) {
      const double l2 = (cohesion - sigma_c * tan_phi) / tau;
      if (l2 * sn > sigma_c) lam = std::min(lam, l2);
    }
    return lam;
  }
};

// The failure test in force units: the tensile load sigma A and its limit sigma_c A, the shear load tau A and its
// limit (c - min(sigma_n, sigma_c) tan(phi_b)) A (N).
struct BondLoad {
  double tension = 0, tension_limit = 0, shear = 0, shear_limit = 0;

  // From the bond's undamaged forces (fn compression positive), 1 / L, A = L t and the moment's lever factor
  // `arm` = A R / I x L (ParallelBond::moment_arm, 6 for the rectangular section).
  static BondLoad of(const BondStrength& st, double fn, double fs, double m, double inv_L, double A, double arm) {
    return of(st.sigma_c * A, st.cohesion * A, st.tan_phi, st.beta_m, fn, fs, m, inv_L, arm);
  }
  // The same with the strength already in force units: sigma_c A and c A (N). Written without branches: the bond
  // kernel (dem/stages/bonds.cpp) calls it in vector lanes.
  static BondLoad of(double sigma_c_A, double cohesion_A, double tan_phi, double beta_m, double fn, double fs,
                     double m, double inv_L, double arm) {
    return {-fn + beta_m * std::abs(m) * arm * inv_L, sigma_c_A, std::abs(fs),
            cohesion_A - std::min(-fn, sigma_c_A) * tan_phi};
  }

  // 1 when the failure index reaches `scale` (1: the strength; a softened bond's largest index so far), else 0,
  // without branches: the bond kernel's test, and failure()'s.
  int exceeds(double scale) const {
    return int(tension >= scale * tension_limit) | int(shear >= scale * shear_limit);
  }
  // Fails when the failure index reaches `scale`: tensile when the tensile load does, else shear.
  BreakMode failure(double scale = 1.0) const {
    if (!exceeds(scale)) return BreakMode::none;
    return tension >= scale * tension_limit ? BreakMode::tensile : BreakMode::shear;
  }

  // The failure index: the larger of sigma / sigma_c and tau / (c - min(sigma_n, sigma_c) tan phi_b); 1 at the
  // strength (+inf when the shear limit is not positive, where failure() breaks too). `tensile` tells which.
  double index(bool& tensile) const {
    const double ft = tension / tension_limit;
    const double fs = shear_limit > 0.0 ? shear / shear_limit : std::numeric_limits<double>::infinity();
    tensile = ft >= fs;
    return tensile ? ft : fs;
  }
};

// The smallest lambda >= 0 at which a bond under the forces F0 + lambda F1 (an affine load path, e.g. axial loading
// from a confined state; fn compression positive) reaches its strength by BondLoad's test; +inf when it never does.
// Both failure loads are piecewise linear in lambda (|M|, |F_s| and the cap of the normal stress at sigma_c each
// bend them once), so every piece is solved exactly. With F0 = 0 it is BondStrength::first_break_factor.
inline double affine_break_factor(double sigma_c_A, double cohesion_A, double tan_phi, double beta_m, double inv_L,
                                  double arm, double fn0, double fs0, double m0, double fn1, double fs1, double m1) {
  auto margin = [&](double lam, double& tension, double& shear) {
    const BondLoad q = BondLoad::of(sigma_c_A, cohesion_A, tan_phi, beta_m, fn0 + lam * fn1, fs0 + lam * fs1,
                                    m0 + lam * m1, inv_L, arm);
    tension = q.tension - q.tension_limit, shear = q.shear - q.shear_limit;
  };
  double points[4] = {0.0, 0.0, 0.0, 0.0};
  int n = 1;
  auto add = [&](double num, double den) {
    if (den != 0.0 && num / den > 0.0 && std::isfinite(num / den)) points[n++] = num / den;
  };
  add(-m0, m1), add(-fs0, fs1), add(-sigma_c_A - fn0, fn1);
  for (int i = 1; i < n; ++i)  // sort the (at most four) points
    for (int j = i; j > 0 && points[j - 1] > points[j]; --j) std::swap(points[j - 1], points[j]);
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < n && !(best < std::numeric_limits<double>::infinity()); ++k) {
    const double a = points[k];
    const bool tail = k + 1 == n;
    const double b = tail ? a + std::max(1.0, a) : points[k + 1];  // on the tail the margins are linear
    double ta = 0, sa = 0, tb = 0, sb = 0;
    margin(a, ta, sa);
    if (ta >= 0.0 || sa >= 0.0) return a;
    margin(b, tb, sb);
    for (const auto& [ga, gb] : {std::pair{ta, tb}, std::pair{sa, sb}})
      if (gb > ga && (tail || gb >= 0.0)) {
        const double root = a + (b - a) * (-ga) / (gb - ga);
        if (root >= a && (tail || root <= b)) best = std::min(best, root);
      }
  }
  return best;
}

// The parallel bond of one bond kind (rock or joint): stiffness ratio, inertia factor, strength and softening.
// Per-bond values (K, L) come from the bond frame.
struct ParallelBond {
  double inv_kappa = 1.0;              // 1 / kappa = k_s / k_n
  // The section's second moment I = A L^2 / inertia_divisor (12 for the rectangle of an edge of length L in a slice;
  // common/fault_injection.hpp plants 6), and its reciprocal, with which the per-bond rotational stiffness of the
  // kernel is formed.
  double inertia_divisor = 12.0;
  double inertia_factor = 1.0 / 12.0;
  BondStrength strength;
  // Softening: 2 G_f / (sigma_c^2 t) (m / N x N/m ...): r_u = softening K / L for a bond of stiffness K and edge L;
  // 0 = brittle.
  double softening = 0;

  // Forces in the co-rotated frame from the normal opening dn (m), shear displacement ds (m) and relative
  // rotation dth (rad) of a bond with normal stiffness K (N/m), shear stiffness Ks = K / kappa and rotational
  // stiffness KI = K L^2 x inertia_factor (precomputed per bond).
  struct Forces {
    double fn, fs, m;  // N, N, N m (compression positive; m acts on block j)
  };

  // The section of a bond on an edge of length L (m) in a slice of thickness t (m): area A = L t, second moment
  // I = A L^2 / 12 and the distance R = L / 2 of its outer fibre, which the peripheral stresses use.
  struct Section {
    double A, I, R;  // m^2, m^4, m
  };
  Section section(double L, double t) const {
    const double A = L * t;
    return {A, A * L * L / inertia_divisor, 0.5 * L};
  }
  // A R / I x L: the lever of the moment in the tensile load sigma A = -F_n + beta_m |M| moment_arm / L (6).
  double moment_arm() const { return 0.5 * inertia_divisor; }
  // The rotational stiffness K L^2 / 12 (N m) of a bond of normal stiffness K (N/m) and edge L (m): the linearised
  // form (the static solve, the stability estimate, the energies).
  double rotational(double K, double L) const { return K * L * L / inertia_divisor; }
  // The per-bond constants the kernel reads (Model's BondFrames): K / kappa and K L^2 / 12 formed with the
  // reciprocals inv_kappa and inertia_factor. They equal the linearised forms to the last bit or differ in it; both
  // stay as they are, since the stored results (the default table among them) were computed with them.
  double kernel_shear(double K) const { return K * inv_kappa; }
  double kernel_rotational(double K, double L) const { return K * L * L * inertia_factor; }
  static Forces forces(double K, double Ks, double KI, double dn, double ds, double dth) {
    return {-K * dn, -Ks * ds, -KI * dth};
  }

  // The failure index at which a softening bond of stiffness K and edge L breaks: r_u = softening K / L.
  double rupture_index(double K, double L) const { return softening * K / L; }

  // Linear softening in the failure index r (the largest reached): the fraction (1 - D) of its elastic forces a
  // bond still carries, from 1 at r = 1 to 0 at r = r_u. For r_u <= 1 the bond is brittle.
  static double intact_fraction(double r, double r_u) {
    if (r <= 1.0) return 1.0;
    if (r >= r_u) return 0.0;
    return (r_u - r) / (r * (r_u - 1.0));
  }

  // The outcome of the failure test of one bond at one step. `drive` is the bond's largest failure index so far
  // (0 while undamaged) and is updated; returns the mode when the bond breaks now, BreakMode::none otherwise.
  // Brittle bonds break when the load reaches the strength; softening bonds start to soften there and break at
  // r_u.
  BreakMode advance(const BondLoad& q, double r_u, double& drive) const {
    BreakMode mode = q.failure(drive > 0.0 ? drive : 1.0);
    if (mode != BreakMode::none && softening > 0.0) {
      bool tensile = false;
      const double r = std::max({drive, 1.0, q.index(tensile)});
      drive = r;
      mode = r >= std::max(r_u, 1.0) ? (tensile ? BreakMode::tensile : BreakMode::shear) : BreakMode::none;
    }
    return mode;
  }
};

// The macroscopic Mohr-Coulomb envelope tau = c + sigma tan(phi) of a bonded interface (compression positive),
// for comparing a joint of bonds with Jaeger's plane of weakness (docs/theory.md, section 4). In compression the
// linear part and the parallel bond share the traction in proportion to their stiffnesses, which are equal here
// (same E* and kappa), so the bond sees half of it. Sticking linear part: the bond fails at
// tau/2 = c + (sigma/2) tan(phi_b), i.e. tau = 2c + sigma tan(phi_b). Linear part sliding at mu: it carries
// mu sigma/2 of the shear and the bond fails at tau - mu sigma/2 = c + (sigma/2) tan(phi_b), i.e.
// tau = c + sigma (mu + tan(phi_b))/2.
struct MohrCoulomb {
  double cohesion = 0;  // Pa
  double tan_phi = 0;
};
inline MohrCoulomb interface_envelope(double cohesion, double tan_phi_bond, double mu, bool slip_when_bonded) {
  if (!slip_when_bonded) return {2.0 * cohesion, tan_phi_bond};
  return {cohesion, 0.5 * (mu + tan_phi_bond)};
}

}  // namespace rbdem
