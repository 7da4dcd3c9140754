// Stress concentration at a circular hole (continuum/hole.hpp) against Lekhnitskii's closed form (docs/theory.md, section 9).
//
// The tolerances come from the convergence tables of docs/continuum_hole.md (L/a = 40, isotropic, TI plane
// stress, TI plane strain; reference: Q2 level 6 at the same L/a):
//   - The SCF differs from the infinite-plate closed form by the finite-plate offset (+0.18 %, +0.26 %, +0.25 % at
//     L/a = 40, scaling as (a/L)^2) plus the discretisation error (Q2 level 2: at most 0.15 %). Both measured
//     bounds add up to 0.41 %: tolerance 0.5 %.
//   - With the offset removed by Richardson extrapolation in (a/L)^2 (L/a = 40 and 80), Q2 level 3 matches the
//     closed form to the level-3 discretisation error (at most 1.4e-4; extrapolation residual 1e-5): 3e-4.
//   - The discretisation error (measured by successive differences, so free of the finite-plate offset) of the
//     hoop-strain SCF converges at order 2 for Q1 (1.80 - 1.99 at levels 2-4) and 2.8 - 3.4 for Q2 (levels 1-3):
//     the tests demand 1.6 - 2.4 for Q1 and > 2.5 for Q2.
// The disabled test Hole.DISABLED_ConvergenceTable prints the tables of the doc (about 5 minutes):
//   build/tests/test_hole --gtest_also_run_disabled_tests --gtest_filter=Hole.DISABLED_ConvergenceTable
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "theory/elasticity.hpp"
#include "continuum/hole.hpp"

namespace rbdem::continuum {
namespace {

using theory::Plane;

const theory::TIConstants isotropic = theory::TIConstants::isotropic(40e9, 0.25);
const theory::TIConstants layered{40e9, 0.25, 10e9, 0.2, 6e9};  // E/E' = 4

HoleOptions options(int degree, int refinement, double plate_ratio = 40) {
  HoleOptions o;
  o.degree = degree;
  o.refinement = refinement;
  o.plate_ratio = plate_ratio;
  return o;
}

double relative_error(const HoleResult& r) { return (r.scf - r.scf_closed_form) / r.scf_closed_form; }

TEST(Hole, ClosedFormIsThreeForIsotropicMaterial) {
  EXPECT_NEAR(lekhnitskii_hole_scf(isotropic, Plane::stress), 3.0, 1e-12);
  EXPECT_NEAR(lekhnitskii_hole_scf(isotropic, Plane::strain), 3.0, 1e-12);
  // Plane stress by hand (docs/theory.md, section 9): a11 = 1/E, a22 = 1/E', a12 = -nu'/E', a66 = 1/G'.
  const double a11 = 1 / 40e9, a22 = 1 / 10e9, a12 = -0.2 / 10e9, a66 = 1 / 6e9;
  EXPECT_NEAR(lekhnitskii_hole_scf(layered, Plane::stress),
              1 + std::sqrt((2 * a12 + a66) / a11 + 2 * std::sqrt(a22 / a11)), 1e-12);
}

using Material = std::tuple<std::string, theory::TIConstants, Plane>;
class HoleScf : public ::testing::TestWithParam<Material> {};

TEST_P(HoleScf, QuadraticElementsMatchLekhnitskiiWithinHalfAPercent) {
  const auto& [name, c, plane] = GetParam();
  const HoleResult r = solve_hole(c, 0.0, plane, options(2, 2));
  EXPECT_TRUE(r.quarter);
  EXPECT_NEAR(relative_error(r), 0.0, 0.005) << name << ": SCF " << r.scf << " vs " << r.scf_closed_form;
  EXPECT_DOUBLE_EQ(r.scf_max, r.scf) << name << ": the maximum hoop stress is at the top of the hole";
  EXPECT_NEAR(r.scf_max_angle_deg, 90.0, 1e-9) << name;
}

TEST_P(HoleScf, FinitePlateOffsetRemovedByRichardsonMatchesLekhnitskii) {
  const auto& [name, c, plane] = GetParam();
  const HoleResult r40 = solve_hole(c, 0.0, plane, options(2, 3, 40));
  const HoleResult r80 = solve_hole(c, 0.0, plane, options(2, 3, 80));
  // The offset is O((a/L)^2) (docs/continuum_hole.md: halving a/L divides it by 4.01 - 4.19 at Q2 level 4).
  const double extrapolated = (4 * r80.scf - r40.scf) / 3;
  EXPECT_NEAR(extrapolated / r40.scf_closed_form - 1, 0.0, 3e-4) << name << ": " << extrapolated;
  std::printf("%s: Richardson (L/a = 40, 80) SCF %.6f, closed form %.6f, relative error %+.1e\n", name.c_str(),
              extrapolated, r40.scf_closed_form, extrapolated / r40.scf_closed_form - 1);
}

// Observed order from three successive levels: the differences cancel the finite-plate offset.
double observed_order(const theory::TIConstants& c, Plane plane, int degree, int first_level) {
  double scf[3];
  for (int i = 0; i < 3; ++i) scf[i] = solve_hole(c, 0.0, plane, options(degree, first_level + i)).scf;
  return std::log2(std::abs((scf[1] - scf[0]) / (scf[2] - scf[1])));
}

TEST_P(HoleScf, LinearElementsConvergeAtSecondOrder) {
  const auto& [name, c, plane] = GetParam();
  const double p = observed_order(c, plane, 1, 2);
  EXPECT_GT(p, 1.6) << name;
  EXPECT_LT(p, 2.4) << name;
}

TEST_P(HoleScf, QuadraticElementsConvergeFasterThanSecondOrder) {
  const auto& [name, c, plane] = GetParam();
  EXPECT_GT(observed_order(c, plane, 2, 1), 2.5) << name;
}

INSTANTIATE_TEST_SUITE_P(Materials, HoleScf,
                         ::testing::Values(Material{"isotropic", isotropic, Plane::stress},
                                           Material{"ti_plane_stress", layered, Plane::stress},
                                           Material{"ti_plane_strain", layered, Plane::strain}),
                         [](const ::testing::TestParamInfo<Material>& p) { return std::get<0>(p.param); });

TEST(Hole, FullPlateEqualsQuarterPlateForAlignedAxes) {
  HoleOptions full = options(2, 1);
  full.full_plate = true;
  const HoleResult q = solve_hole(layered, 0.0, Plane::strain, options(2, 1));
  const HoleResult f = solve_hole(layered, 0.0, Plane::strain, full);
  EXPECT_FALSE(f.quarter);
  EXPECT_EQ(f.cells, 4 * q.cells);
  EXPECT_NEAR(f.scf, q.scf, 1e-9 * q.scf);  // the same mesh mirrored: equal up to the direct solver's round-off
  EXPECT_NEAR(f.scf_max, q.scf_max, 1e-9 * q.scf);
}

TEST(Hole, LoadAlongMaterialAxisTwoSwapsTheAxesOfTheClosedForm) {
  const HoleResult r = solve_hole(layered, 90.0, Plane::stress, options(2, 3));
  EXPECT_TRUE(r.quarter);
  const auto a = theory::reduced_compliance(layered, Plane::stress);
  EXPECT_NEAR(r.scf_closed_form, 1 + std::sqrt((2 * a.a12 + a.a66) / a.a22 + 2 * std::sqrt(a.a11 / a.a22)), 1e-12);
  EXPECT_NEAR(relative_error(r), 0.0, 0.005) << r.scf << " vs " << r.scf_closed_form;
  std::printf("bedding 90 deg, Q2 level 3, L/a = 40: SCF %.6f, closed form %.6f, relative error %+.1e\n", r.scf,
              r.scf_closed_form, relative_error(r));
}

TEST(Hole, ObliqueBeddingUsesTheFullPlate) {
  const HoleResult r = solve_hole(layered, 30.0, Plane::stress, options(1, 1));
  EXPECT_FALSE(r.quarter);
  EXPECT_TRUE(std::isnan(r.scf_closed_form));
  EXPECT_GT(r.scf_max, 1.0);
  std::printf("bedding 30 deg, Q1 level 1 (full plate, %zu DoFs): max SCF %.3f at %.1f deg\n", r.dofs, r.scf_max,
              r.scf_max_angle_deg);
}

TEST(Hole, RejectsBadOptions) {
  EXPECT_THROW(solve_hole(isotropic, 0.0, Plane::stress, options(3, 1)), std::invalid_argument);
  EXPECT_THROW(solve_hole(isotropic, 0.0, Plane::stress, options(1, -1)), std::invalid_argument);
  EXPECT_THROW(solve_hole(isotropic, 0.0, Plane::stress, options(1, 1, 1.5)), std::invalid_argument);
  EXPECT_THROW(solve_hole(theory::TIConstants{}, 0.0, Plane::stress, options(1, 1)), std::invalid_argument);
}

// ---- The table of docs/continuum_hole.md ---------------------------------------------------------------------------

TEST(Hole, DISABLED_ConvergenceTable) {
  const std::vector<Material> materials{{"isotropic", isotropic, Plane::stress},
                                        {"TI plane stress", layered, Plane::stress},
                                        {"TI plane strain", layered, Plane::strain}};
  auto order = [](double coarse, double fine) {
    return std::isnan(coarse) ? std::string() : std::to_string(std::log2(std::abs(coarse / fine))).substr(0, 4);
  };
  for (const auto& [name, c, plane] : materials) {
    // Reference for the discretisation error: Q2 level 6 at the same L/a (its own error is below 1e-6).
    const HoleResult ref = solve_hole(c, 0.0, plane, options(2, 6));
    std::printf("\n%s: closed form SCF %.6f; L/a = 40, h -> 0 (Q2 level 6, %zu DoFs, %.1f s): %.6f\n", name.c_str(),
                lekhnitskii_hole_scf(c, plane), ref.dofs, ref.seconds, ref.scf);
    std::printf("| degree | level | h/a | DoFs | SCF | error vs closed form | discretisation error | order | "
                "SCF pointwise | its discretisation error | order | max abs sigma_rr/p | wall s |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int degree = 1; degree <= 2; ++degree) {
      double prev = NAN, prev_pw = NAN;
      for (int k = 0; k <= 5; ++k) {
        const HoleResult r = solve_hole(c, 0.0, plane, options(degree, k));
        const double err = relative_error(r), disc = (r.scf - ref.scf) / ref.scf;
        const double disc_pw = (r.scf_pointwise - ref.scf) / ref.scf;
        std::printf("| Q%d | %d | %.4f | %zu | %.6f | %+.2e | %+.2e | %s | %.6f | %+.2e | %s | %.1e | %.2f |\n",
                    degree, k, r.hole_element_size / 0.01, r.dofs, r.scf, err, disc, order(prev, disc).c_str(),
                    r.scf_pointwise, disc_pw, order(prev_pw, disc_pw).c_str(), r.radial_stress_residual, r.seconds);
        prev = disc, prev_pw = disc_pw;
      }
    }
  }
  // The finite-plate offset: Q2 level 4 at several plate sizes, and Richardson extrapolation in (a/L)^2.
  std::printf("\nFinite-plate effect, Q2 level 4\n| material | L/a | DoFs | SCF | error vs closed form | "
              "offset ratio to 2L | Richardson (L, 2L) | its error |\n|---|---|---|---|---|---|---|---|\n");
  for (const auto& [name, c, plane] : materials) {
    const std::vector<double> ratios{10, 20, 40, 80, 160};
    std::vector<HoleResult> r;
    for (double ratio : ratios) r.push_back(solve_hole(c, 0.0, plane, options(2, 4, ratio)));
    for (std::size_t i = 0; i < r.size(); ++i) {
      std::string offset_ratio, richardson, richardson_err;
      if (i + 1 < r.size()) {
        offset_ratio = std::to_string(relative_error(r[i]) / relative_error(r[i + 1])).substr(0, 5);
        const double ext = (4 * r[i + 1].scf - r[i].scf) / 3;
        richardson = std::to_string(ext).substr(0, 8);
        char buf[32];
        std::snprintf(buf, sizeof buf, "%+.1e", (ext - r[i].scf_closed_form) / r[i].scf_closed_form);
        richardson_err = buf;
      }
      std::printf("| %s | %.0f | %zu | %.6f | %+.2e | %s | %s | %s |\n", name.c_str(), ratios[i], r[i].dofs, r[i].scf,
                  relative_error(r[i]), offset_ratio.c_str(), richardson.c_str(), richardson_err.c_str());
    }
  }
}

}  // namespace
}  // namespace rbdem::continuum
