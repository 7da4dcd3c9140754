// The rotated compliance by matrix products, S = T^T a T (T the stress transformation into the material frame,
// engineering shear strain), as an independent reference for the expanded formulas of compare/theory.
#pragma once

#include <cmath>
#include <numbers>

#include "theory/elasticity.hpp"

namespace rbdem::verify {

inline theory::Compliance3 compliance_by_transformation(const theory::ReducedCompliance& a, double theta_deg) {
  const double q = theta_deg * std::numbers::pi / 180.0, c = std::cos(q), s = std::sin(q);
  // sigma' = T sigma, Voigt [xx, yy, xy], the primed axes rotated by theta counter-clockwise.
  const double T[3][3] = {{c * c, s * s, 2 * c * s}, {s * s, c * c, -2 * c * s}, {-c * s, c * s, c * c - s * s}};
  const double A[3][3] = {{a.a11, a.a12, 0}, {a.a12, a.a22, 0}, {0, 0, a.a66}};
  theory::Compliance3 S{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double v = 0;
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) v += T[k][i] * A[k][l] * T[l][j];
      S[std::size_t(i)][std::size_t(j)] = v;
    }
  return S;
}

}  // namespace rbdem::verify
