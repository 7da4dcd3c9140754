// Factors of a Weibull distribution of modulus m scaled to mean 1, F(w) = 1 - exp(-(w Gamma(1 + 1/m))^m), checked
// against it: a Kolmogorov-Smirnov test at the 1 % level, the mean within five standard errors and the coefficient
// of variation within 10 % of sqrt(Gamma(1 + 2/m) / Gamma(1 + 1/m)^2 - 1).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace rbdem {

inline void expect_weibull_factors(std::vector<double> w, double m) {
  const double n = double(w.size());
  ASSERT_GT(n, 1000);
  std::sort(w.begin(), w.end());
  const double g1 = std::tgamma(1 + 1 / m), g2 = std::tgamma(1 + 2 / m);
  double ks = 0, sum = 0, sum2 = 0;
  for (std::size_t k = 0; k < w.size(); ++k) {
    const double F = 1 - std::exp(-std::pow(w[k] * g1, m));
    ks = std::max({ks, std::abs(F - double(k) / n), std::abs(F - double(k + 1) / n)});
    sum += w[k], sum2 += w[k] * w[k];
  }
  EXPECT_LT(ks, 1.63 / std::sqrt(n));
  const double mean = sum / n, cv = std::sqrt(sum2 / n - mean * mean) / mean;
  const double cv_exact = std::sqrt(g2 / (g1 * g1) - 1);  // 0.363 at m = 3, 0.428 at 2.5
  EXPECT_NEAR(mean, 1.0, 5 * cv_exact / std::sqrt(n));
  EXPECT_NEAR(cv, cv_exact, 0.1 * cv_exact);
}

}  // namespace rbdem
