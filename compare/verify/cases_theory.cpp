// Closed-form cases: the rotated compliance against matrix products, Amadei's written-out formula, and Goodman's
// equivalent continuum against Backus's exact layered medium (docs/theory.md, sections 2, 3).
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "theory/elasticity.hpp"
#include "compare/verify/transform.hpp"
#include "compare/verify/verify.hpp"

namespace rbdem::verify {

namespace {

constexpr double dips[] = {0, 15, 30, 45, 60, 75, 90};

// The DEM's measured constants of the paper scene (docs/elastic.md) and a strongly anisotropic rock.
const theory::TIConstants paper_dem{283.10e9, 0.101, 254.43e9, 0.091, 119.58e9};
const theory::TIConstants slate{40e9, 0.25, 10e9, 0.2, 6e9};

CaseResult rotated_compliance(const Context&) {
  CaseResult r;
  r.checks = "the expanded rotated compliance S(theta) (all nine entries, plane strain and stress, seven dips)";
  r.reference = "S = T^T a T by matrix products (T the stress transformation, engineering shear strain)";
  r.unit = "1/Pa";
  double worst = 0;
  for (const auto& [label, c] : {std::pair{"paper_dem", paper_dem}, std::pair{"slate", slate}})
    for (const theory::Plane plane : {theory::Plane::strain, theory::Plane::stress}) {
      const theory::ReducedCompliance a = theory::reduced_compliance(c, plane);
      for (double beta : dips) {
        const theory::Compliance3 S = theory::rotated_compliance(a, beta);
        const theory::Compliance3 R = compliance_by_transformation(a, beta);
        double scale = 0, diff = 0;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            scale = std::max(scale, std::abs(R[i][j]));
            diff = std::max(diff, std::abs(S[i][j] - R[i][j]));
          }
        if (diff / scale >= worst) worst = diff / scale, r.measured = S[1][1], r.reference_value = R[1][1];
        r.table.push_back({{"material", label}, {"plane", plane == theory::Plane::strain ? "strain" : "stress"},
                           {"beta_deg", beta}, {"max_entry_error", diff / scale}});
      }
    }
  r.error = worst;
  r.error_definition = "max over entries, dips, planes and materials of |S - S_ref| / max |S_ref|";
  r.tolerance = 1e-12;
  r.tolerance_source = "round-off of a few dozen operations on O(1) products";
  r.cost = "56 matrices";
  return r;
}

CaseResult amadei(const Context&) {
  CaseResult r;
  r.checks = "the apparent modulus 1 / S22(beta) in plane stress against Amadei's formula written out";
  r.reference = "1/E(beta) = cos^4/E' + sin^4/E + (1/G' - 2 nu'/E') sin^2 cos^2 (Amadei; docs/theory.md, section 2)";
  r.unit = "Pa";
  double worst = 0;
  for (const auto& [label, c] : {std::pair{"paper_dem", paper_dem}, std::pair{"slate", slate}})
    for (double beta : dips) {
      const double E = theory::apparent_modulus(c, beta, theory::Plane::stress);
      const double ref = theory::amadei_plane_stress(c, beta);
      const double err = std::abs(E / ref - 1.0);
      r.table.push_back({{"material", label}, {"beta_deg", beta}, {"modulus_pa", E}, {"amadei_pa", ref},
                         {"error", err}});
      if (err >= worst) worst = err, r.measured = E, r.reference_value = ref;
    }
  r.error = worst;
  r.error_definition = "max |E / E_Amadei - 1| over the seven dips and two materials";
  r.tolerance = 1e-12;
  r.tolerance_source = "round-off";
  r.cost = "14 evaluations";
  return r;
}

// A soft layer of thickness h every s with k_n = (lambda + 2 mu) / h and k_s = mu / h held fixed as h -> 0:
// Backus's exact layered medium tends to Goodman's rock-plus-joint constants, the difference falling as h / s.
CaseResult goodman_backus(const Context&) {
  CaseResult r;
  r.checks = "Goodman's rock-plus-joint constants against the exact (Backus) medium of a thin soft layer";
  r.reference = "Backus average of the layered medium (docs/theory.md, section 3); the difference vanishes as h / s -> 0";
  r.unit = "Pa";
  const double Er = 60e9, nur = 0.2, s = 0.01, kn = 2e12, ks = 0.8e12;
  std::vector<double> errors;
  const std::vector<double> hs = {1e-4, 1e-5, 1e-6};
  for (double h : hs) {
    const double mj = ks * h, lj = kn * h - 2 * mj;
    const double Ej = mj * (3 * lj + 2 * mj) / (lj + mj), nuj = lj / (2 * (lj + mj));
    const theory::TIConstants g = theory::goodman(Er, nur, kn, ks, s);
    const theory::TIConstants b = theory::backus(Er, nur, s - h, Ej, nuj, h);
    const double err = std::max({std::abs(g.E_prime / b.E_prime - 1), std::abs(g.G_prime / b.G_prime - 1),
                                 std::abs(g.E / b.E - 1), std::abs(g.nu - b.nu), std::abs(g.nu_prime - b.nu_prime)});
    errors.push_back(err);
    r.table.push_back({{"h_over_s", h / s}, {"max_error", err}, {"goodman_E_prime_pa", g.E_prime},
                       {"backus_E_prime_pa", b.E_prime}});
    if (h == 1e-5) r.measured = g.E_prime, r.reference_value = b.E_prime, r.error = err;
  }
  const double order = std::log(errors[0] / errors[2]) / std::log(hs[0] / hs[2]);
  r.table.push_back({{"observed_order", order}});
  r.error_definition = "max relative difference of E, E', G' and absolute of nu, nu' at h / s = 1e-3";
  r.tolerance = 3e-3;
  r.tolerance_source = fmt::format("first order in h / s (observed order {:.2f}): 3 h / s", order);
  r.cost = "3 layer thicknesses";
  return r;
}

}  // namespace

std::vector<CaseSpec> theory_cases() {
  return {make_case("theory.rotated_compliance", true, rotated_compliance),
          make_case("theory.amadei_written_out", true, amadei),
          make_case("theory.goodman_vs_backus", true, goodman_backus)};
}

}  // namespace rbdem::verify
