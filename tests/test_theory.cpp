// Closed-form theory against itself and against independent limits (docs/theory.md, sections 2-4).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "theory/elasticity.hpp"
#include "theory/elasticity3.hpp"

namespace rbdem::theory {
namespace {

const TIConstants layered{60e9, 0.2, 25e9, 0.12, 9e9};

TEST(Amadei, IsotropicLimitIsConstant) {
  const auto iso = TIConstants::isotropic(50e9, 0.25);
  for (double beta = 0; beta <= 90; beta += 7.5) {
    EXPECT_NEAR(apparent_modulus(iso, beta, Plane::stress), 50e9, 1e-13 * 50e9);
    EXPECT_NEAR(apparent_modulus(iso, beta, Plane::strain), 50e9 / (1 - 0.25 * 0.25), 1e-13 * 50e9);
  }
}

TEST(Amadei, RotatedComplianceEqualsWrittenOutFormulaInPlaneStress) {
  for (double beta = 0; beta <= 90; beta += 5)
    EXPECT_NEAR(apparent_modulus(layered, beta, Plane::stress), amadei_plane_stress(layered, beta),
                1e-12 * layered.E);
  EXPECT_NEAR(apparent_modulus(layered, 0, Plane::stress), layered.E_prime, 1e-3);
  EXPECT_NEAR(apparent_modulus(layered, 90, Plane::stress), layered.E, 1e-3);
}

TEST(Amadei, ConstantsRecoveredFromTheirCompliance) {
  for (Plane plane : {Plane::stress, Plane::strain}) {
    // Plane strain recovery assumes nu'/E' = nu/E, which Goodman's constants satisfy.
    const TIConstants c = goodman(60e9, 0.22, 3e12, 1e12, 0.01);
    const TIConstants back = constants_from_compliance(reduced_compliance(c, plane), plane);
    EXPECT_NEAR(back.E_prime, c.E_prime, 1e-9 * c.E_prime);
    EXPECT_NEAR(back.G_prime, c.G_prime, 1e-9 * c.G_prime);
    EXPECT_NEAR(back.nu_prime, c.nu_prime, 1e-9);
    EXPECT_NEAR(back.E, c.E, 1e-9 * c.E);
    EXPECT_NEAR(back.nu, c.nu, 1e-9);
  }
}

TEST(Amadei, AdmissibilityRejectsNonPositiveCompliance) {
  EXPECT_TRUE(layered.admissible());
  TIConstants bad = layered;
  bad.nu_prime = 0.9;  // 1 - nu - 2 nu'^2 E/E' < 0
  EXPECT_FALSE(bad.admissible());
}

TEST(Goodman, AgreesWithBackusForAThinSoftLayer) {
  // A soft layer of thickness h every s with k_n = (lambda_j + 2 mu_j)/h and k_s = mu_j/h held fixed as h -> 0:
  // Backus's exact layered medium tends to Goodman's rock-plus-joint constants.
  const double Er = 60e9, nur = 0.2, s = 0.01, kn = 2e12, ks = 0.8e12;
  for (double h : {1e-4, 1e-5, 1e-6}) {
    const double mj = ks * h, lj = kn * h - 2 * mj;
    const double Ej = mj * (3 * lj + 2 * mj) / (lj + mj), nuj = lj / (2 * (lj + mj));
    const TIConstants g = goodman(Er, nur, kn, ks, s);
    const TIConstants b = backus(Er, nur, s - h, Ej, nuj, h);
    const double tol = 3 * h / s;  // the differences vanish linearly with h/s
    EXPECT_NEAR(g.E_prime / b.E_prime, 1.0, tol) << h;
    EXPECT_NEAR(g.G_prime / b.G_prime, 1.0, tol) << h;
    EXPECT_NEAR(g.E / b.E, 1.0, tol) << h;
    EXPECT_NEAR(g.nu, b.nu, tol) << h;
    EXPECT_NEAR(g.nu_prime, b.nu_prime, tol) << h;
  }
}

TEST(Backus, IdenticalLayersAreIsotropic) {
  const TIConstants b = backus(40e9, 0.25, 1.0, 40e9, 0.25, 3.0);
  EXPECT_NEAR(b.E, 40e9, 1e-3);
  EXPECT_NEAR(b.E_prime, 40e9, 1e-3);
  EXPECT_NEAR(b.nu, 0.25, 1e-12);
  EXPECT_NEAR(b.nu_prime, 0.25, 1e-12);
  EXPECT_NEAR(b.G_prime, 16e9, 1e-3);
}

TEST(Salamon, JointsOnAnIsotropicRockAreGoodman) {
  const TIConstants j = add_joints(TIConstants::isotropic(60e9, 0.2), 2e12, 0.8e12, 0.01);
  const TIConstants g = goodman(60e9, 0.2, 2e12, 0.8e12, 0.01);
  EXPECT_NEAR(j.E / g.E, 1.0, 1e-14);
  EXPECT_NEAR(j.E_prime / g.E_prime, 1.0, 1e-14);
  EXPECT_NEAR(j.nu_prime / g.nu_prime, 1.0, 1e-14);
  EXPECT_NEAR(j.G_prime / g.G_prime, 1.0, 1e-14);
}

TEST(Salamon, EqualBedsAreTheSingleRockWithItsJoints) {
  const TIConstants b = interbedded(40e9, 0.25, 0.005, 40e9, 0.25, 0.005, 3e12, 1e12, 0.005);
  const TIConstants g = goodman(40e9, 0.25, 3e12, 1e12, 0.005);
  EXPECT_NEAR(b.E / g.E, 1.0, 1e-12);
  EXPECT_NEAR(b.nu, g.nu, 1e-12);
  EXPECT_NEAR(b.E_prime / g.E_prime, 1.0, 1e-12);
  EXPECT_NEAR(b.nu_prime, g.nu_prime, 1e-12);
  EXPECT_NEAR(b.G_prime / g.G_prime, 1.0, 1e-12);
}

TEST(Salamon, UnjointedBedsWithoutPoissonEffectAreTheSeriesAndParallelLimits) {
  // nu = 0 decouples the directions: the beds are springs in series normal to them (E_perp = 1 / <1/E>, G' = 1 /
  // <1/G>) and in parallel along them (E_par = <E>).
  const double E1 = 60e9, E2 = 20e9, h1 = 0.003, h2 = 0.007, f1 = h1 / (h1 + h2), f2 = h2 / (h1 + h2);
  const double inf = std::numeric_limits<double>::infinity();
  const TIConstants b = interbedded(E1, 0.0, h1, E2, 0.0, h2, inf, inf, 0.005);
  EXPECT_NEAR(b.E_prime / (1.0 / (f1 / E1 + f2 / E2)), 1.0, 1e-12);
  EXPECT_NEAR(b.E / (f1 * E1 + f2 * E2), 1.0, 1e-12);
  EXPECT_NEAR(b.G_prime / (1.0 / (f1 / (0.5 * E1) + f2 / (0.5 * E2))), 1.0, 1e-12);
  EXPECT_NEAR(b.nu, 0.0, 1e-15);
  EXPECT_NEAR(b.nu_prime, 0.0, 1e-15);
  // Joints add 1/(k_n s) to 1/E' and 1/(k_s s) to 1/G'.
  const TIConstants j = interbedded(E1, 0.0, h1, E2, 0.0, h2, 4e12, 1e12, 0.005);
  EXPECT_NEAR(1.0 / j.E_prime, f1 / E1 + f2 / E2 + 1.0 / (4e12 * 0.005), 1e-12 / j.E_prime);
  EXPECT_NEAR(1.0 / j.G_prime, f1 / (0.5 * E1) + f2 / (0.5 * E2) + 1.0 / (1e12 * 0.005), 1e-12 / j.G_prime);
  EXPECT_EQ(j.E, b.E);
}

TEST(Jaeger, MinimumAt45PlusHalfPhiWithClosedFormValue) {
  const JaegerInput in{6e6, 30.0, 50e6, 0.0};
  double best = 1e300, best_beta = 0;
  for (double beta = 30.5; beta < 90; beta += 0.01) {
    const double s = jaeger_sliding_strength(in, beta);
    if (s < best) best = s, best_beta = beta;
  }
  EXPECT_NEAR(best_beta, jaeger_min_angle_deg(30.0), 0.02);
  EXPECT_NEAR(best, jaeger_min_uniaxial_strength(6e6, 30.0), 1e-6 * best);
  EXPECT_NEAR(best, 2 * 6e6 * std::cos(M_PI / 6) / (1 - 0.5), 1.0);
}

TEST(Jaeger, IntactStrengthOutsideTheSlidingRange) {
  const JaegerInput in{6e6, 30.0, 50e6, 0.0};
  EXPECT_EQ(jaeger_strength(in, 0.0), 50e6);
  EXPECT_EQ(jaeger_strength(in, 25.0), 50e6);
  EXPECT_EQ(jaeger_strength(in, 90.0), 50e6);
  EXPECT_LT(jaeger_strength(in, 60.0), 50e6);
}

// ---- 3D: the rotated TI compliance (theory/elasticity3.hpp; docs/theory.md, "The layered cylinder in 3D") --------

// The tensor rotation of the compliance against Amadei's written-out formulas, at dips and dip directions all round:
// the uniaxial response depends on the dip alone.
TEST(Amadei3D, RotatedComplianceEqualsWrittenOutFormulas) {
  for (double dip = 0; dip <= 90; dip += 7.5)
    for (double dd : {0.0, 30.0, 90.0, 137.0, 250.0}) {
      const Uniaxial3 tensor = uniaxial_from_compliance(layered, dip, dd), closed = amadei_uniaxial_3d(layered, dip);
      EXPECT_NEAR(tensor.modulus, closed.modulus, 1e-12 * layered.E) << dip << " " << dd;
      EXPECT_NEAR(tensor.strain_strike, closed.strain_strike, 1e-12 / layered.E) << dip << " " << dd;
      EXPECT_NEAR(tensor.strain_dip, closed.strain_dip, 1e-12 / layered.E) << dip << " " << dd;
      EXPECT_NEAR(tensor.shear_dip, closed.shear_dip, 1e-12 / layered.E) << dip << " " << dd;
    }
  // Loading normal to the bedding (dip 0) gives E' and nu'; along it (dip 90) E, with nu along the strike and
  // nu' E/E' across the bedding.
  const Uniaxial3 flat = amadei_uniaxial_3d(layered, 0), upright = amadei_uniaxial_3d(layered, 90);
  EXPECT_NEAR(flat.modulus, layered.E_prime, 1e-3);
  EXPECT_NEAR(flat.poisson_strike, layered.nu_prime, 1e-14);
  EXPECT_NEAR(flat.poisson_dip, layered.nu_prime, 1e-14);
  EXPECT_NEAR(upright.modulus, layered.E, 1e-3);
  EXPECT_NEAR(upright.poisson_strike, layered.nu, 1e-14);
  EXPECT_NEAR(upright.poisson_dip, layered.nu_prime * layered.E / layered.E_prime, 1e-14);
}

// At dip direction 0 the x-z section is the 2D slice: the x, z and xz rows and columns of the 3D compliance are the
// 2D plane-stress compliance rotated by the same dip (an independent code path: theory/elasticity.cpp).
TEST(Amadei3D, ZeroDipDirectionSectionIsThePlaneStressCompliance) {
  constexpr int pick[3] = {0, 2, 4};  // 3D Voigt xx, zz, xz <-> 2D xx, yy, xy
  for (double dip = 0; dip <= 90; dip += 15) {
    const Compliance6 S = rotated_compliance(layered, dip, 0.0);
    const Compliance3 S2 = theory::rotated_compliance(reduced_compliance(layered, Plane::stress), dip);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(S[pick[i]][pick[j]], S2[i][j], 1e-12 / layered.E) << dip;
  }
}

TEST(Amadei3D, IsotropicLimitIsTheSameAtEveryOrientation) {
  const auto iso = TIConstants::isotropic(50e9, 0.25);
  const Compliance6 S0 = ti_compliance(iso);
  for (double dip = 0; dip <= 90; dip += 15)
    for (double dd : {0.0, 45.0, 200.0}) {
      const Compliance6 S = rotated_compliance(iso, dip, dd);
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) EXPECT_NEAR(S[i][j], S0[i][j], 1e-14 / 50e9);
    }
}

TEST(Amadei3D, PlaneAxesAreOrthonormalAndMatchThe2DNormal) {
  for (double dip : {0.0, 30.0, 90.0})
    for (double dd : {0.0, 60.0}) {
      const PlaneAxes a = plane_axes(dip, dd);
      auto dot = [](const Vec3& u, const Vec3& v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
      EXPECT_NEAR(dot(a.normal, a.normal), 1.0, 1e-15);
      EXPECT_NEAR(dot(a.normal, a.strike), 0.0, 1e-15);
      EXPECT_NEAR(dot(a.strike, a.dip_direction), 0.0, 1e-15);
    }
  // Dip direction 0: the normal in the x-z plane is the 2D joints' normal (-sin beta, cos beta).
  const PlaneAxes a = plane_axes(30.0, 0.0);
  EXPECT_NEAR(a.normal[0], -0.5, 1e-15);
  EXPECT_NEAR(a.normal[1], 0.0, 1e-15);
  EXPECT_NEAR(a.normal[2], std::sqrt(3.0) / 2, 1e-15);
}

}  // namespace
}  // namespace rbdem::theory
