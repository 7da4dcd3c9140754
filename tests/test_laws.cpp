// The contact laws as value types (dem/laws/), each against hand-computed values (docs/theory.md, sections 5 to 7):
// the parallel bond's failure test in tension, bending, shear under compression and under tension, the tension
// cap, the softening branch, the static first-break load factor; the linear contact's Coulomb slip, its energy,
// and the identity of the law in a bond's units with the law per unit area.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "dem/laws/linear_contact.hpp"
#include "dem/laws/parallel_bond.hpp"

namespace rbdem {
namespace {

// A bond of edge L = 1 mm and thickness t = 1 m: A = 1e-3 m^2, I = t L^3 / 12, R = L / 2. Strength sigma_c = 10 MPa,
// c = 20 MPa, phi_b = 30 deg, beta_m = 1. In force units (BondLoad): tension limit sigma_c A = 1e4 N, the moment
// term beta_m |M| 6 / L = 6000 |M| N, shear limit c A - min(-F_n, sigma_c A) tan(phi_b).
constexpr double L = 1e-3, t = 1.0, A = L * t, I = t * L * L * L / 12.0, R = 0.5 * L;
const double tan30 = std::tan(30.0 * std::numbers::pi / 180.0);
BondStrength strength() { return {10e6, 20e6, tan30, 1.0}; }

struct LoadCase {
  std::string name;
  double fn, fs, m;                   // N (compression positive), N, N m
  double tension, shear, shear_limit;  // N, by hand
  BreakMode mode;                     // at the strength (scale 1)
  double index;                       // the failure index
};

class BondFailure : public ::testing::TestWithParam<LoadCase> {};

TEST_P(BondFailure, LoadsLimitsModeAndIndexMatchTheHandValues) {
  const LoadCase& c = GetParam();
  const BondLoad q = BondLoad::of(strength(), c.fn, c.fs, c.m, 1.0 / L, A, 6.0);
  EXPECT_NEAR(q.tension, c.tension, 1e-9 * 1e4);
  EXPECT_NEAR(q.tension_limit, 1e4, 1e-9 * 1e4);
  EXPECT_NEAR(q.shear, c.shear, 1e-9 * 1e4);
  EXPECT_NEAR(q.shear_limit, c.shear_limit, 1e-9 * 1e4);
  EXPECT_EQ(q.failure(), c.mode);
  bool tensile = false;
  EXPECT_NEAR(q.index(tensile), c.index, 1e-12);
  // The stresses of the records agree with the loads: sigma = tension / A, tau = shear / A.
  double sigma = 0, tau = 0;
  strength().stresses(c.fn, c.fs, c.m, A, I, R, sigma, tau);
  EXPECT_NEAR(sigma * A, c.tension, 1e-9 * 1e4);
  EXPECT_NEAR(tau * A, c.shear, 1e-9 * 1e4);
}

const double sl_c20 = 2e4 + 2e4 * tan30;    // 20 MPa compression: c A + 2e4 tan 30 = 31547 N
const double sl_t5 = 2e4 - 5e3 * tan30;     // 5 MPa tension: c A - 5e3 tan 30 = 17113 N
const double sl_cap = 2e4 - 1e4 * tan30;    // sigma_n above sigma_c is capped at sigma_c

INSTANTIATE_TEST_SUITE_P(
    ParallelBond, BondFailure,
    ::testing::Values(
        LoadCase{"tension_below", -9e3, 0, 0, 9e3, 0, 2e4 - 9e3 * tan30, BreakMode::none, 0.9},
        LoadCase{"tension_at_strength", -1e4, 0, 0, 1e4, 0, sl_cap, BreakMode::tensile, 1.0},
        LoadCase{"bending_below", 0, 0, 1.5, 9e3, 0, 2e4, BreakMode::none, 0.9},
        LoadCase{"bending_breaks", 0, 0, -2.0, 1.2e4, 0, 2e4, BreakMode::tensile, 1.2},
        LoadCase{"bending_under_compression", 2e3, 0, 2.0, 1e4, 0, 2e4 + 2e3 * tan30, BreakMode::tensile, 1.0},
        LoadCase{"shear_under_compression_holds", 2e4, 3e4, 0, -2e4, 3e4, sl_c20, BreakMode::none, 3e4 / sl_c20},
        LoadCase{"shear_under_compression_breaks", 2e4, -3.2e4, 0, -2e4, 3.2e4, sl_c20, BreakMode::shear,
                 3.2e4 / sl_c20},
        LoadCase{"shear_under_tension_breaks", -5e3, 1.8e4, 0, 5e3, 1.8e4, sl_t5, BreakMode::shear, 1.8e4 / sl_t5},
        LoadCase{"tension_and_bending_with_shear", -5e3, 1.7e4, 1.0, 5e3 + 6e3, 1.7e4, sl_t5, BreakMode::tensile,
                 1.1},
        LoadCase{"normal_stress_capped_at_sigma_c", -1.2e4, 5e3, 0, 1.2e4, 5e3, sl_cap, BreakMode::tensile, 1.2}),
    [](const ::testing::TestParamInfo<LoadCase>& param) { return param.param.name; });

TEST(ParallelBond, ForcesAreTheStiffnessesTimesTheRelativeDisplacements) {
  const double K = 2e9, Ks = 1e9, KI = K * L * L / 12.0;
  const ParallelBond::Forces f = ParallelBond::forces(K, Ks, KI, -1e-7, 2e-7, 1e-5);
  EXPECT_DOUBLE_EQ(f.fn, 200.0);                 // closing 0.1 um: compression
  EXPECT_DOUBLE_EQ(f.fs, -200.0);
  EXPECT_DOUBLE_EQ(f.m, -KI * 1e-5);
}

TEST(ParallelBond, BrittleBondBreaksAtItsStrength) {
  ParallelBond pb;
  pb.strength = strength();
  double drive = 0.0;
  EXPECT_EQ(pb.advance(BondLoad::of(pb.strength, -9.99e3, 0, 0, 1.0 / L, A, 6.0), 1.0, drive), BreakMode::none);
  EXPECT_EQ(pb.advance(BondLoad::of(pb.strength, -1e4, 0, 0, 1.0 / L, A, 6.0), 1.0, drive), BreakMode::tensile);
  EXPECT_EQ(drive, 0.0);  // a brittle bond keeps no damage history
}

// Softening with r_u = 2: the bond carries (r_u - r) / (r (r_u - 1)) of its elastic forces past the strength, keeps
// the largest index reached, and breaks at r_u.
TEST(ParallelBond, SofteningBranchFollowsTheLargestIndexAndBreaksAtRu) {
  ParallelBond pb;
  pb.strength = strength();
  pb.softening = 1.0;  // any positive value: the branch is on; r_u is passed in
  const double r_u = 2.0;
  double drive = 0.0;
  auto tension = [&](double f) { return BondLoad::of(pb.strength, -f, 0, 0, 1.0 / L, A, 6.0); };
  EXPECT_EQ(pb.advance(tension(1.2e4), r_u, drive), BreakMode::none);
  EXPECT_DOUBLE_EQ(drive, 1.2);
  EXPECT_NEAR(ParallelBond::intact_fraction(drive, r_u), 0.8 / 1.2, 1e-15);
  EXPECT_EQ(pb.advance(tension(1.1e4), r_u, drive), BreakMode::none);  // unloading: the damage stays
  EXPECT_DOUBLE_EQ(drive, 1.2);
  EXPECT_EQ(pb.advance(tension(1.5e4), r_u, drive), BreakMode::none);
  EXPECT_DOUBLE_EQ(drive, 1.5);
  EXPECT_EQ(pb.advance(tension(2.0e4), r_u, drive), BreakMode::tensile);
  EXPECT_DOUBLE_EQ(ParallelBond::intact_fraction(2.0, r_u), 0.0);
  // In shear the index is tau / shear limit.
  double d2 = 0.0;
  EXPECT_EQ(pb.advance(BondLoad::of(pb.strength, 0, 3e4, 0, 1.0 / L, A, 6.0), r_u, d2), BreakMode::none);
  EXPECT_DOUBLE_EQ(d2, 1.5);
  EXPECT_EQ(pb.advance(BondLoad::of(pb.strength, 0, 4.1e4, 0, 1.0 / L, A, 6.0), r_u, d2), BreakMode::shear);
}

TEST(ParallelBond, TooSmallARuptureIndexBreaksAtTheStrength) {
  ParallelBond pb;
  pb.strength = strength();
  pb.softening = 1.0;
  double drive = 0.0;
  EXPECT_EQ(pb.advance(BondLoad::of(pb.strength, -1e4, 0, 0, 1.0 / L, A, 6.0), 0.7, drive), BreakMode::tensile);
}

// The static solve's load factor is exactly where the engine's failure test flips, in every regime.
TEST(ParallelBond, FirstBreakFactorIsWhereTheFailureTestFlips) {
  const BondStrength st = strength();
  const double cases[][3] = {{-1e3, 0, 0}, {0, 0, 0.2}, {2e3, 4e3, 0}, {-500, 1e3, 0.05}, {-1e3, 2e3, 0}};
  for (const auto& c : cases) {
    const double lam = st.first_break_factor(c[0], c[1], c[2], A, I, R);
    ASSERT_TRUE(std::isfinite(lam));
    const auto at = [&](double f) { return BondLoad::of(st, f * c[0], f * c[1], f * c[2], 1.0 / L, A, 6.0).failure(); };
    EXPECT_EQ(at(lam * (1 - 1e-9)), BreakMode::none) << c[0] << " " << c[1] << " " << c[2];
    EXPECT_NE(at(lam * (1 + 1e-9)), BreakMode::none) << c[0] << " " << c[1] << " " << c[2];
  }
  EXPECT_EQ(st.first_break_factor(1e3, 0, 0, A, I, R), std::numeric_limits<double>::infinity());  // compression only
  // Shear under a compression that raises the limit faster than the shear grows never breaks.
  EXPECT_EQ(st.first_break_factor(1e4, 1e3, 0, A, I, R), std::numeric_limits<double>::infinity());
}

// Along an affine path F0 + lambda F1 (axial loading from a confined state) the first break is found exactly on the
// piecewise-linear failure loads: from rest it is the proportional factor, and from a preloaded state it is where a
// fine scan of the very test finds it.
TEST(ParallelBond, AffineBreakFactorMatchesTheProportionalOneAndAScan) {
  const BondStrength st = strength();
  const double sA = st.sigma_c * A, cA = st.cohesion * A;
  auto affine = [&](double fn0, double fs0, double m0, double fn1, double fs1, double m1) {
    return affine_break_factor(sA, cA, st.tan_phi, st.beta_m, 1.0 / L, 6.0, fn0, fs0, m0, fn1, fs1, m1);
  };
  const double proportional[][3] = {{-1e3, 0, 0}, {0, 0, 0.2}, {2e3, 4e3, 0}, {-500, 1e3, 0.05}, {-1e3, 2e3, 0}};
  for (const auto& c : proportional)
    EXPECT_NEAR(affine(0, 0, 0, c[0], c[1], c[2]) / st.first_break_factor(c[0], c[1], c[2], A, I, R), 1.0, 1e-12);
  // Preloaded: a compression (confinement) that raises the shear limit, then shear and bending grow.
  const double paths[][6] = {{5e3, 500, 0.1, 1e3, 3e3, -0.4}, {2e3, -1e3, 0.0, -1e3, 2e3, 0.3}, {1e3, 0, 0, -2e3, 0, 0}};
  for (const auto& p : paths) {
    const double lam = affine(p[0], p[1], p[2], p[3], p[4], p[5]);
    ASSERT_TRUE(std::isfinite(lam));
    auto fails = [&](double l) {
      return BondLoad::of(st, p[0] + l * p[3], p[1] + l * p[4], p[2] + l * p[5], 1.0 / L, A, 6.0).failure() !=
             BreakMode::none;
    };
    EXPECT_FALSE(fails(lam * (1 - 1e-9)));
    EXPECT_TRUE(fails(lam * (1 + 1e-9)));
    for (int k = 0; k < 1000; ++k) EXPECT_FALSE(fails(lam * k / 1000.0 * (1 - 1e-9))) << "an earlier break at " << k;
  }
  EXPECT_EQ(affine(-2e4, 0, 0, 1.0, 0, 0), 0.0);  // already past the strength
  EXPECT_EQ(affine(1e3, 0, 0, 1e3, 0, 0), std::numeric_limits<double>::infinity());  // only more compression
}

TEST(LinearContact, SlidesExactlyAtMuFn) {
  // k_n = k_s = 1e14 Pa/m over a chord of L_ref = 1 mm, t = 1 m: K_s = 1e11 N/m; the increment is K_s ds.
  const LinearContact law = LinearContact::per_area(1e14, 1e14, 0.5, 1e-3, 1.0);
  double fs = 0;
  EXPECT_FALSE(law.update_shear(100.0, 1e-3, -4.9e-10, 1.0, fs));  // K_s ds = 49 N < mu F_n = 50 N
  EXPECT_NEAR(fs, 49.0, 1e-9);
  EXPECT_TRUE(law.update_shear(100.0, 1e-3, -2e-11, 1.0, fs));
  EXPECT_DOUBLE_EQ(fs, 50.0);
  EXPECT_FALSE(law.update_shear(0.0, 1e-3, -1e-12, 1.0, fs));  // no normal force, no shear force
  EXPECT_EQ(fs, 0.0);
  // A partial chord scales the shear stiffness: half the chord, half the increment.
  fs = 0;
  law.update_shear(100.0, 0.5e-3, -2e-10, 1.0, fs);
  EXPECT_NEAR(fs, 10.0, 1e-9);
}

// Patton's dilation: a closed edge slid under a constant normal force first takes mu F_n / K_s elastically and then
// slides; every metre of slip opens it by tan(i), so after a tangential displacement D the opening is
// (D - mu F_n / K_s) tan(i). With tan(i) = 0 the law is the flat one, bit for bit, and never opens.
TEST(LinearContact, SlidingOpensTheContactBySlipTimesTanI) {
  const double L = 1e-3, kn = 1e14, mu = 0.5, tan_i = std::tan(10.0 * std::numbers::pi / 180.0);
  LinearContact law = LinearContact::per_area(kn, kn, mu, L, 1.0);  // K = K_s = 1e11 N/m
  law.tan_dilation = tan_i;
  const double fn = 100.0, ds = 1e-11;  // N, m per step
  double fs = 0, opening = 0, slid = 0;
  int slides = 0;
  for (int step = 0; step < 1000; ++step) {
    slides += law.update_shear(fn, L, -ds, 1.0, fs, opening);
    slid += ds;
  }
  EXPECT_DOUBLE_EQ(fs, mu * fn);
  EXPECT_GT(slides, 900);
  EXPECT_NEAR(opening, (slid - mu * fn / law.Ks) * tan_i, 1e-9 * opening);
  // Sticking opens nothing; nor does a contact without a normal force.
  double stuck_fs = 0, stuck = 0;
  law.update_shear(fn, L, -ds, 1.0, stuck_fs, stuck);
  law.update_shear(0.0, L, -1.0, 1.0, stuck_fs, stuck);
  EXPECT_EQ(stuck, 0.0);
  // The flat law: the forces of the five-argument form, no opening.
  LinearContact flat = law;
  flat.tan_dilation = 0.0;
  double fs_a = 0, fs_b = 0, flat_opening = 0;
  for (int step = 0; step < 100; ++step) {
    EXPECT_EQ(flat.update_shear(fn, L, -ds, 1.0, fs_a, flat_opening), flat.update_shear(fn, L, -ds, 1.0, fs_b));
    EXPECT_EQ(fs_a, fs_b);
  }
  EXPECT_EQ(flat_opening, 0.0);
}

TEST(LinearContact, NormalForceIsTheGradientOfTheOverlapPotential) {
  // w(A) = k_n t A^2 / (2 L_ref); for a whole edge in contact (l_c = L_ref) F_n = dw/d(delta) = k_n t L delta.
  const LinearContact law = LinearContact::per_area(2e14, 1e14, 0.5, 1e-3, 1.0);
  const double delta = 1e-7, area = 1e-3 * delta;
  const double fn = law.normal_force(area, 1e-3);
  EXPECT_NEAR(fn, 2e14 * 1e-3 * delta, 1e-9);
  EXPECT_NEAR(law.strain_energy(fn, 0.0, 1e-3), 0.5 * 2e14 * 1e-3 * delta * delta, 1e-12);
  // A vertex pressed into a face: A_o = chord^2 / 4 (a right-angled corner), F_n = k_n t A_o l_c / L_ref.
  const double chord = 2e-7;
  EXPECT_NEAR(law.normal_force(0.25 * chord * chord, chord), 2e14 * 0.25 * chord * chord * chord / 1e-3, 1e-15);
  // The shear energy of a closed edge: F_s^2 / (2 k_s t L).
  EXPECT_NEAR(law.strain_energy(fn, 50.0, 1e-3) - law.strain_energy(fn, 0.0, 1e-3), 2500.0 / (2 * 1e14 * 1e-3), 1e-15);
}

TEST(EdgeOverlap, FullyCompressedEdgeGivesLTimesDelta) {
  const EdgeOverlap e = edge_overlap(2e-3, -1e-6, 1e-4);  // rotation small enough to keep the edge closed
  EXPECT_NEAR(e.area, 2e-9, 1e-21);
  EXPECT_EQ(e.chord, 2e-3);
  EXPECT_EQ(e.s_c, 0.0);
}

TEST(EdgeOverlap, PartlyOpenEdgeIsATriangleOfTheCompressedPart) {
  // u(s) = -dn + s dth: with dn = 0 and dth > 0 the half s > 0 is compressed, area = dth L^2 / 8.
  const double Le = 2e-3, dth = 1e-3;
  const EdgeOverlap e = edge_overlap(Le, 0.0, dth);
  EXPECT_NEAR(e.area, dth * Le * Le / 8, 1e-18);
  EXPECT_NEAR(e.chord, Le / 2, 1e-15);
  EXPECT_NEAR(e.s_c, Le / 4, 1e-15);
  const EdgeOverlap f = edge_overlap(Le, 0.0, -dth);
  EXPECT_NEAR(f.s_c, -Le / 4, 1e-15);
  EXPECT_EQ(edge_overlap(Le, 1e-6, 0.0).area, 0.0);  // open edge: no linear force (no tension)
}

// The linear part of a bond is the linear contact law on its edge: K = k_n t L, L_ref = L. The law per unit area
// and the law in the bond's units are the same law.
TEST(LinearContact, TheBondsUnitsAndThePerAreaFormAreTheSameLaw) {
  const double kn = 3e14, kappa = 2.0, mu = 0.4, Le = 1.5e-3;
  const LinearContact per_area = LinearContact::per_area(kn, kn / kappa, mu, Le, t);
  const LinearContact bond{kn * t * Le, kn * t * Le / kappa, mu, 1.0 / Le};
  for (const auto& [dn, dth] : {std::pair{-1e-7, 0.0}, std::pair{-1e-7, 5e-5}, std::pair{0.0, 1e-4}}) {
    const EdgeOverlap e = edge_overlap(Le, dn, dth);
    const double fn = bond.normal_force(e.area, e.chord);
    EXPECT_NEAR(fn, per_area.normal_force(e.area, e.chord), 1e-12 * fn);
    // A whole closed edge: F_n = k_n L t delta.
    if (dth == 0.0) {
      EXPECT_NEAR(fn, kn * Le * t * 1e-7, 1e-12 * fn);
    }
    double fs_bond = 0.0, fs_area = 0.0;
    bond.update_shear(fn, e.chord, 1e-3, 1e-8, fs_bond);
    per_area.update_shear(fn, e.chord, 1e-3, 1e-8, fs_area);
    EXPECT_NEAR(fs_bond, fs_area, 1e-12 * std::abs(fs_area));
  }
  double fs = 1.0;
  bond.update_shear(0.0, 0.0, 1.0, 1.0, fs);
  EXPECT_EQ(fs, 0.0);  // an open edge carries no shear
  // mu = +inf never slides (a bonded interface that sticks).
  const LinearContact sticking{1e9, 1e9, std::numeric_limits<double>::infinity(), 1e3};
  fs = 0.0;
  EXPECT_FALSE(sticking.update_shear(1.0, 1e-3, -1.0, 1.0, fs));
  EXPECT_NEAR(fs, 1e9, 1e-3);
}

}  // namespace
}  // namespace rbdem
