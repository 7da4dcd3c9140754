// The signals of a compression test (dem/driver/signals.hpp) on hand-built curves, crack logs and topologies whose
// answers are known in closed form: volumetric strain, Poisson's ratio at half the peak, the crack initiation and
// crack damage stresses, the residual strength, crack orientations, the crack rate and the fragments.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "dem/driver/signals.hpp"

namespace rbdem {
namespace {

CurvePoint point(double strain, double stress, double lateral = 0.0) {
  CurvePoint p;
  p.strain = strain;
  p.stress_top = p.stress_bottom = stress;
  p.lateral_strain = lateral;
  return p;
}

Crack crack_at(double strain, int bond = 0) {
  Crack c;
  c.strain = strain;
  c.bond = bond;
  return c;
}

TEST(Signals, VolumetricStrainIsAxialPlusLateral) {
  EXPECT_DOUBLE_EQ(volumetric_strain(point(1e-3, 0, -3e-4)), 7e-4);
  EXPECT_DOUBLE_EQ(volumetric_strain(point(1e-3, 0, -6e-4)), 4e-4);
}

// A linear elastic branch eps_l = -nu eps_a up to the peak at strain 1e-3, stress E eps_a: the tangent ratio is nu.
// Samples outside 40-60 % of the peak carry another slope and must not enter the fit.
TEST(Signals, PoissonRatioIsTheTangentSlopeAtHalfThePeak) {
  std::vector<CurvePoint> c = {point(0, 0)};
  const double E = 50e9, nu = 0.23, peak = 50e6;
  for (int k = 0; k < 100; ++k) {  // samples at 0.5, 1.5, ... 99.5 % of the peak: none on the window's edges
    const double e = 1e-5 * (k + 0.5);
    const bool inside = k >= 40 && k < 60;
    c.push_back(point(e, E * e, inside ? -nu * e + 1e-5 : -0.5 * e));  // an offset does not change a tangent
  }
  c.push_back(point(1e-3, peak, -0.5e-3));
  c.push_back(point(1.1e-3, 0.5 * peak, -1e-3));  // post-peak, at half the peak again: ignored
  EXPECT_NEAR(poisson_ratio_at_half_peak(c, peak, 1e-3), nu, 1e-9);
  // On a confined curve the window is on the deviator: sigma_3 = 10 MPa shifts every stress.
  for (auto& p : c) p.stress_top += 10e6, p.stress_bottom += 10e6;
  EXPECT_NEAR(poisson_ratio_at_half_peak(c, peak + 10e6, 1e-3, 10e6), nu, 1e-9);
}

TEST(Signals, PoissonRatioIsUndefinedWithoutTwoSamplesInTheWindow) {
  const std::vector<CurvePoint> c = {point(0, 0), point(1e-3, 0.5e6, -2e-4), point(2e-3, 1e6)};
  EXPECT_TRUE(std::isnan(poisson_ratio_at_half_peak(c, 1e6, 2e-3)));
  EXPECT_TRUE(std::isnan(poisson_ratio_at_half_peak({}, 1e6, 2e-3)));
  EXPECT_TRUE(std::isnan(poisson_ratio_at_half_peak(c, 0.0, 2e-3)));
}

// Stress = 1e10 x strain up to the peak of 10 MPa at strain 1e-3. Two isolated cracks early (at 10 and 30 % of the
// peak), then one crack in every 2 % bin from 62 % to the peak: initiation is the first crack of that run, 62 %.
TEST(Signals, CrackInitiationIsTheOnsetOfUninterruptedCracking) {
  std::vector<CurvePoint> c;
  for (int k = 0; k <= 1000; ++k) c.push_back(point(1e-6 * k, 1e4 * k));
  const double peak = 1e7, at = 1e-3;
  std::vector<Crack> cracks = {crack_at(1.0e-4), crack_at(3.0e-4)};
  for (int b = 31; b < 50; ++b) {
    cracks.push_back(crack_at((0.02 * b + 0.004) * at));
    cracks.push_back(crack_at((0.02 * b + 0.012) * at));
  }
  cracks.push_back(crack_at(1.2e-3));  // after the peak: ignored
  EXPECT_NEAR(crack_initiation_stress(c, cracks, peak, at) / peak, 0.624, 1e-9);
  // A gap at 80-82 % moves the onset above it.
  std::vector<Crack> gap;
  for (const auto& k : cracks)
    if (!(k.strain > 0.80 * at && k.strain < 0.82 * at)) gap.push_back(k);
  EXPECT_NEAR(crack_initiation_stress(c, gap, peak, at) / peak, 0.824, 1e-9);
  EXPECT_TRUE(std::isnan(crack_initiation_stress(c, {crack_at(1.2e-3)}, peak, at)));
  EXPECT_THROW(crack_initiation_stress(c, cracks, peak, at, 0.0), std::invalid_argument);
}

// A crack that breaks during a stress drop counts at the loading level reached before the drop (the running
// maximum), not at the momentary stress.
TEST(Signals, CrackInitiationUsesTheLoadingLevelNotAMomentaryDrop) {
  const std::vector<CurvePoint> c = {point(0, 0), point(1e-4, 8e6), point(1.1e-4, 2e6), point(2e-4, 10e6)};
  EXPECT_NEAR(crack_initiation_stress(c, {crack_at(1.1e-4)}, 10e6, 2e-4), 8e6, 1e-3);
}

// eps_v = eps_a + eps_l with eps_l = -0.25 eps_a up to strain 1e-3 (stress 10 MPa), then the lateral strain grows
// faster, eps_l = -0.25e-3 - 2 (eps_a - 1e-3): eps_v peaks at eps_a = 1e-3 and falls after. Crack damage is 10 MPa.
TEST(Signals, CrackDamageIsTheStressAtTheVolumetricStrainReversal) {
  std::vector<CurvePoint> c;
  for (int k = 0; k <= 20; ++k) {
    const double e = 1e-4 * k;
    const double lat = k <= 10 ? -0.25 * e : -0.25e-3 - 2.0 * (e - 1e-3);
    c.push_back(point(e, 1e10 * e * (k <= 10 ? 1.0 : 1.0 - 0.1 * (e - 1e-3) / 1e-3), lat));  // still rising
  }
  EXPECT_NEAR(crack_damage_stress(c, c[20].strain), c[10].stress(), 1e-3);
  EXPECT_NEAR(c[10].stress(), 10e6, 1e-3);
  // No reversal before the peak: eps_v largest at the last pre-peak sample.
  EXPECT_TRUE(std::isnan(crack_damage_stress(c, c[10].strain)));
  EXPECT_TRUE(std::isnan(crack_damage_stress({point(0, 0), point(1, 1)}, 1.0)));
}

// After the peak at strain 1e-3 the stress falls to a plateau of 4 MPa from strain 1.5e-3 to 2e-3: the mean of the
// last fifth of the post-peak range (1.8e-3 to 2e-3) is 4 MPa. A run stopped by the stress drop has no residual.
TEST(Signals, ResidualIsTheMeanStressAtTheEndOfThePostPeakRange) {
  std::vector<CurvePoint> c;
  for (int k = 0; k <= 10; ++k) c.push_back(point(1e-4 * k, 1e10 * 1e-4 * k));
  for (int k = 11; k <= 20; ++k) c.push_back(point(1e-4 * k, k < 15 ? 10e6 - 1.5e6 * (k - 10) : 4e6));
  const double at = c[10].strain;
  EXPECT_NEAR(residual_stress(c, at, "post_peak_strain"), 4e6, 1e-6);
  EXPECT_NEAR(residual_stress(c, at, "max_strain"), 4e6, 1e-6);
  // With the whole post-peak range (tail 1): the mean of samples 11..20.
  double mean = 0;
  for (int k = 11; k <= 20; ++k) mean += c[std::size_t(k)].stress() / 10.0;
  EXPECT_NEAR(residual_stress(c, at, "post_peak_strain", 1.0), mean, 1e-6);
  EXPECT_TRUE(std::isnan(residual_stress(c, at, "post_peak")));
  EXPECT_TRUE(std::isnan(residual_stress(c, at, "watchdog")));
  // The post-peak range must reach a fifth of the strain at the peak.
  c.resize(12);
  EXPECT_TRUE(std::isnan(residual_stress(c, at, "max_strain")));
  EXPECT_THROW(residual_stress(c, at, "max_strain", 0.0), std::invalid_argument);
}

TEST(Signals, EdgeOrientationIsTheEdgeAngleFromTheHorizontalIn0To180) {
  EXPECT_NEAR(edge_orientation_deg(0, 1), 0.0, 1e-12);     // horizontal edge (normal up)
  EXPECT_NEAR(edge_orientation_deg(0, -1), 0.0, 1e-12);    // the same edge seen from the other block
  EXPECT_NEAR(edge_orientation_deg(1, 0), 90.0, 1e-12);    // vertical edge
  EXPECT_NEAR(edge_orientation_deg(-1, 0), 90.0, 1e-12);
  const double r = std::sqrt(0.5);
  EXPECT_NEAR(edge_orientation_deg(-r, r), 45.0, 1e-12);   // normal at 135 deg: edge at 45 deg
  EXPECT_NEAR(edge_orientation_deg(r, -r), 45.0, 1e-12);
  EXPECT_NEAR(edge_orientation_deg(r, r), 135.0, 1e-12);
  // A joint at dip 60 deg: its trace runs at 60 deg, its normal at 150 deg.
  const double a = 150.0 * std::numbers::pi / 180.0;
  EXPECT_NEAR(edge_orientation_deg(std::cos(a), std::sin(a)), 60.0, 1e-9);
}

TEST(Signals, CrackRateCountsCracksPerUnitStrainInEqualBins) {
  const std::vector<Crack> c = {crack_at(0.1e-3), crack_at(0.2e-3), crack_at(0.7e-3), crack_at(1e-3),
                                crack_at(2e-3)};  // the last lies beyond the end: not counted
  const auto bins = crack_rate(c, 1e-3, 4);
  ASSERT_EQ(bins.size(), 4u);
  EXPECT_EQ(bins[0].cracks, 2);
  EXPECT_EQ(bins[1].cracks, 0);
  EXPECT_EQ(bins[2].cracks, 1);
  EXPECT_EQ(bins[3].cracks, 1);  // the crack at the end counts in the last bin
  EXPECT_NEAR(bins[0].rate, 2 / 0.25e-3, 1e-6);
  EXPECT_NEAR(bins[3].strain_high, 1e-3, 0);
  EXPECT_TRUE(crack_rate(c, 0.0).empty());
  EXPECT_THROW(crack_rate(c, 1e-3, 0), std::invalid_argument);
}

// Six unit-area blocks in a row, 0-1-2-3-4-5, bonds b between blocks b and b+1, and a bond 0-2 (a triangle 0,1,2).
// Breaking bonds 2 (2-3) and 4 (4-5) leaves fragments {0,1,2}, {3,4}, {5}; breaking 0 (0-1) too changes nothing:
// 0 and 1 stay joined through 2.
Specimen row_of_blocks() {
  Specimen t;
  for (int b = 0; b < 6; ++b) {
    t.blocks.centroid.insert(t.blocks.centroid.end(), {b + 0.5, 0.5});
    t.blocks.measure.push_back(b == 5 ? 2.0 : 1.0);
    t.blocks.layer.push_back(0);
  }
  for (int b = 0; b < 5; ++b) t.bonds.i.push_back(b), t.bonds.j.push_back(b + 1);
  t.bonds.i.push_back(0), t.bonds.j.push_back(2);
  return t;
}

TEST(Signals, FragmentsAreTheBlocksJoinedByIntactBonds) {
  const Specimen t = row_of_blocks();
  const auto whole = fragments(t, {});
  ASSERT_EQ(whole.size(), 1u);
  EXPECT_EQ(whole[0].blocks, 6);
  EXPECT_DOUBLE_EQ(whole[0].measure, 7.0);
  const auto f = fragments(t, {crack_at(0, 2), crack_at(0, 4), crack_at(0, 0)});
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0].blocks, 3);  // {0, 1, 2}: area 3, centroid x = 1.5
  EXPECT_DOUBLE_EQ(f[0].measure, 3.0);
  EXPECT_DOUBLE_EQ(f[0].cx, 1.5);
  EXPECT_EQ(f[1].blocks, 2);  // {3, 4} (area 2) before {5} (area 2): equal areas keep the order of lowest block
  EXPECT_DOUBLE_EQ(f[1].cx, 4.0);
  EXPECT_EQ(f[2].blocks, 1);
  EXPECT_DOUBLE_EQ(f[2].measure, 2.0);
  EXPECT_DOUBLE_EQ(f[2].cx, 5.5);
  // Every bond broken: every block alone.
  std::vector<Crack> all;
  for (int b = 0; b < 6; ++b) all.push_back(crack_at(0, b));
  EXPECT_EQ(fragments(t, all).size(), 6u);
}

TEST(Signals, FragmentsRefuseACrackOfAnUnknownBond) {
  const Specimen t = row_of_blocks();
  EXPECT_THROW(fragments(t, {crack_at(0, 6)}), std::invalid_argument);
  EXPECT_THROW(fragments(t, {crack_at(0, -1)}), std::invalid_argument);
}

}  // namespace
}  // namespace rbdem
