// The continuum's closed-form helpers, deal.II-free: the plane stiffness the FE models assemble
// (continuum/fe_model.hpp) and the hole's infinite-plate stress concentration (continuum/hole.hpp). Compiled into
// both the front library rbdem_continuum and the deal.II module (continuum/CMakeLists.txt), so that callers of
// these helpers never load deal.II.
#include <cmath>

#include "continuum/fe_model.hpp"
#include "continuum/hole.hpp"

namespace rbdem::continuum {

namespace {

// C = S^-1 by cofactors (S is a 3 x 3 compliance, symmetric positive definite for admissible constants).
Stiffness3 invert(const theory::Compliance3& S) {
  const double det = S[0][0] * (S[1][1] * S[2][2] - S[1][2] * S[2][1]) -
                     S[0][1] * (S[1][0] * S[2][2] - S[1][2] * S[2][0]) +
                     S[0][2] * (S[1][0] * S[2][1] - S[1][1] * S[2][0]);
  Stiffness3 C{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      // cofactor of S[j][i]
      const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
      C[i][j] = (S[r0][c0] * S[r1][c1] - S[r0][c1] * S[r1][c0]) / det;
    }
  return C;
}

}  // namespace

Stiffness3 stiffness_voigt(const theory::TIConstants& c, double bedding_deg, theory::Plane plane) {
  return invert(theory::rotated_compliance(theory::reduced_compliance(c, plane), bedding_deg));
}

double hole_scf_closed_form(const theory::Compliance3& S) {
  return 1 + std::sqrt((2 * S[0][1] + S[2][2]) / S[0][0] + 2 * std::sqrt(S[1][1] / S[0][0]));
}

double lekhnitskii_hole_scf(const theory::TIConstants& c, theory::Plane plane) {
  return hole_scf_closed_form(theory::rotated_compliance(theory::reduced_compliance(c, plane), 0.0));
}

}  // namespace rbdem::continuum
