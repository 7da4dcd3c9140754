// Closed forms of the Brazilian test: the isotropic point-load field (Hondros), its mean over a concentric circle,
// and Claesson & Bohloli's approximate centre tension of a transversely isotropic disc. Equations and units in
// theory/disc.hpp.
#include "theory/disc.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace rbdem::theory {

namespace {

constexpr double pi = std::numbers::pi;
constexpr double deg = pi / 180.0;

void check_disc(const char* who, double load, double diameter, double thickness) {
  const std::string w = who;
  if (!(diameter > 0) || !std::isfinite(diameter))
    throw std::invalid_argument(w + ": diameter = " + std::to_string(diameter) + " m; give the positive disc diameter D");
  if (!(thickness > 0) || !std::isfinite(thickness))
    throw std::invalid_argument(w + ": thickness = " + std::to_string(thickness) +
                                " m; give the positive out-of-plane thickness t");
  if (!std::isfinite(load)) throw std::invalid_argument(w + ": the load P is not finite; give it in N");
}

// The field without the checks (the quadrature calls it many times).
DiscStress field(double p, double R, double x, double y) {
  const double a = R - y, b = R + y;  // vertical distances to the upper and lower load points
  const double r1 = x * x + a * a, r2 = x * x + b * b;
  const double q1 = 1.0 / (r1 * r1), q2 = 1.0 / (r2 * r2);
  const double k = 2.0 * p / pi, uniform = p / (pi * R);  // 2p / (pi D)
  DiscStress s;
  s.xx = -k * (a * x * x * q1 + b * x * x * q2) + uniform;
  s.yy = -k * (a * a * a * q1 + b * b * b * q2) + uniform;
  s.xy = k * (a * a * x * q1 - b * b * x * q2);
  return s;
}

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n from the Chebyshev guesses).
std::pair<std::vector<double>, std::vector<double>> gauss_legendre(int n) {
  std::vector<double> x(n), w(n);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(pi * (i + 0.75) / (n + 0.5)), dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double pk = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1, p1 = pk;
      }
      dp = n * (z * p1 - p0) / (z * z - 1);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-16) break;
    }
    x[i] = z;
    w[i] = 2.0 / ((1 - z * z) * dp * dp);
  }
  return {x, w};
}

}  // namespace

double principal_tension(const DiscStress& s) {
  return 0.5 * (s.xx + s.yy) + std::hypot(0.5 * (s.xx - s.yy), s.xy);
}

double brazilian_tensile_strength(double load, double diameter, double thickness) {
  check_disc("brazilian_tensile_strength", load, diameter, thickness);
  return 2.0 * load / (pi * diameter * thickness);
}

DiscStress hondros_stress(double load, double diameter, double thickness, double x, double y) {
  check_disc("hondros_stress", load, diameter, thickness);
  const double R = 0.5 * diameter;
  // A small relative slack lets points computed on the rim (cos, sin of an angle) through.
  if (!(x * x + y * y <= R * R * (1 + 1e-12)))
    throw std::invalid_argument("hondros_stress: the point (" + std::to_string(x) + ", " + std::to_string(y) +
                                ") m lies outside the disc of radius " + std::to_string(R) +
                                " m; give coordinates relative to the disc centre");
  return field(load / thickness, R, x, y);
}

DiscStress hondros_centre_stress(double load, double diameter, double thickness) {
  const double s = brazilian_tensile_strength(load, diameter, thickness);
  return {s, -3.0 * s, 0.0};
}

DiscStress hondros_mean_stress(double load, double diameter, double thickness, double radius) {
  check_disc("hondros_mean_stress", load, diameter, thickness);
  const double R = 0.5 * diameter;
  if (!(radius > 0 && radius < R))
    throw std::invalid_argument("hondros_mean_stress: radius = " + std::to_string(radius) +
                                " m; the averaging circle needs 0 < radius < R = " + std::to_string(R) + " m");
  // The integrand is analytic inside the disc; its singularities (the load points) are at distance >= R - rho
  // from the averaging circle, so both rules converge geometrically: the trapezoidal rule in the angle like
  // (rho / R)^n_theta, Gauss-Legendre in r like 1.9^(-2 n_r) at rho = 0.9 R.
  constexpr int n_r = 48, n_theta = 512;
  static const auto gl = gauss_legendre(n_r);
  const double p = load / thickness;
  DiscStress sum;
  for (int i = 0; i < n_r; ++i) {
    const double r = 0.5 * radius * (gl.first[i] + 1), wr = 0.5 * radius * gl.second[i] * r;
    for (int j = 0; j < n_theta; ++j) {
      const double th = 2 * pi * j / n_theta;
      const DiscStress s = field(p, R, r * std::cos(th), r * std::sin(th));
      sum.xx += wr * s.xx, sum.yy += wr * s.yy, sum.xy += wr * s.xy;
    }
  }
  const double scale = (2 * pi / n_theta) / (pi * radius * radius);
  return {sum.xx * scale, sum.yy * scale, sum.xy * scale};
}

ClaessonBohloliParameters claesson_bohloli_parameters(const ReducedCompliance& a) {
  if (!(a.a11 > 0) || !(a.a22 > 0) || !std::isfinite(a.a11) || !std::isfinite(a.a22) || !std::isfinite(a.a12) ||
      !std::isfinite(a.a66))
    throw std::invalid_argument("claesson_bohloli_parameters: the reduced compliance needs finite a11, a22 > 0 (got a11 = " +
                                std::to_string(a.a11) + ", a22 = " + std::to_string(a.a22) +
                                " 1/Pa); build it with theory::reduced_compliance from admissible constants");
  return {a.a22 / a.a11, (2 * a.a12 + a.a66) / (2 * std::sqrt(a.a11 * a.a22))};
}

double claesson_bohloli_factor(const ReducedCompliance& a, double beta_deg) {
  if (!std::isfinite(beta_deg))
    throw std::invalid_argument("claesson_bohloli_factor: beta is not a finite angle; give the bedding dip in degrees");
  const ClaessonBohloliParameters q = claesson_bohloli_parameters(a);
  // Orientation of the anisotropy term: see theory/disc.hpp, section 2 (the stiffer direction across the load
  // raises the centre tension).
  const double beta = beta_deg * deg;
  return std::pow(q.stiffness_ratio, std::cos(2 * beta) / 4) - std::cos(4 * beta) / 4 * (q.b - 1);
}

double claesson_bohloli_factor(const TIConstants& c, Plane plane, double beta_deg) {
  if (!c.admissible())
    throw std::invalid_argument(
        "claesson_bohloli_factor: the transversely isotropic constants are not admissible (E, E', G' > 0, "
        "-1 < nu < 1, 1 - nu - 2 nu'^2 E/E' > 0); check the units (Pa) and the pairing of E with nu, E' with nu'");
  return claesson_bohloli_factor(reduced_compliance(c, plane), beta_deg);
}

double claesson_bohloli_centre_tension(const TIConstants& c, Plane plane, double beta_deg, double load,
                                       double diameter, double thickness) {
  return claesson_bohloli_factor(c, plane, beta_deg) * brazilian_tensile_strength(load, diameter, thickness);
}

}  // namespace rbdem::theory
