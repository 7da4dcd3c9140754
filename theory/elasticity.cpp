// Closed-form transversely isotropic elasticity and Jaeger strength. See elasticity.hpp and docs/theory.md.
#include "theory/elasticity.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "common/fault_injection.hpp"

namespace rbdem::theory {

namespace {
constexpr double deg = std::numbers::pi / 180.0;
}

Plane plane_from_string(const std::string& model) {
  if (model == "plane_strain") return Plane::strain;
  if (model == "plane_stress") return Plane::stress;
  throw std::invalid_argument("specimen.model must be \"plane_strain\" or \"plane_stress\", got \"" + model + "\"");
}

TIConstants TIConstants::isotropic(double E, double nu) { return {E, nu, E, nu, E / (2.0 * (1.0 + nu))}; }

bool TIConstants::admissible() const {
  return E > 0 && E_prime > 0 && G_prime > 0 && nu > -1 && nu < 1 &&
         1.0 - nu - 2.0 * nu_prime * nu_prime * E / E_prime > 0;
}

ReducedCompliance reduced_compliance(const TIConstants& c, Plane plane) {
  ReducedCompliance a;
  if (plane == Plane::stress) {
    a.a11 = 1.0 / c.E;
    a.a22 = 1.0 / c.E_prime;
    a.a12 = -c.nu_prime / c.E_prime;
  } else {
    a.a11 = (1.0 - c.nu * c.nu) / c.E;
    a.a22 = (1.0 - c.nu_prime * c.nu_prime * c.E / c.E_prime) / c.E_prime;
    a.a12 = -c.nu_prime * (1.0 + c.nu) / c.E_prime;
  }
  a.a66 = 1.0 / c.G_prime;
  return a;
}

Compliance3 rotated_compliance(const ReducedCompliance& a, double theta_deg) {
  const double c = std::cos(theta_deg * deg), s = std::sin(theta_deg * deg);
  const double c2 = c * c, s2 = s * s, c4 = c2 * c2, s4 = s2 * s2;
  Compliance3 S{};
  S[0][0] = a.a11 * c4 + (2 * a.a12 + a.a66) * s2 * c2 + a.a22 * s4;
  const double a12_in_s22 = fault_injected("compliance_sign") ? -a.a12 : a.a12;
  S[1][1] = a.a11 * s4 + (2 * a12_in_s22 + a.a66) * s2 * c2 + a.a22 * c4;
  S[0][1] = S[1][0] = a.a12 * (s4 + c4) + (a.a11 + a.a22 - a.a66) * s2 * c2;
  S[2][2] = 2 * (2 * a.a11 + 2 * a.a22 - 4 * a.a12 - a.a66) * s2 * c2 + a.a66 * (s4 + c4);
  S[0][2] = S[2][0] = (2 * a.a11 - 2 * a.a12 - a.a66) * s * c2 * c - (2 * a.a22 - 2 * a.a12 - a.a66) * s2 * s * c;
  S[1][2] = S[2][1] = (2 * a.a11 - 2 * a.a12 - a.a66) * s2 * s * c - (2 * a.a22 - 2 * a.a12 - a.a66) * s * c2 * c;
  return S;
}

double apparent_modulus(const ReducedCompliance& a, double beta_deg) {
  return 1.0 / rotated_compliance(a, beta_deg)[1][1];
}

double apparent_modulus(const TIConstants& c, double beta_deg, Plane plane) {
  return apparent_modulus(reduced_compliance(c, plane), beta_deg);
}

double amadei_plane_stress(const TIConstants& c, double beta_deg) {
  const double cb = std::cos(beta_deg * deg), sb = std::sin(beta_deg * deg);
  const double inv = std::pow(cb, 4) / c.E_prime + std::pow(sb, 4) / c.E +
                     (1.0 / c.G_prime - 2.0 * c.nu_prime / c.E_prime) * sb * sb * cb * cb;
  return 1.0 / inv;
}

TIConstants constants_from_compliance(const ReducedCompliance& a, Plane plane) {
  TIConstants c;
  c.G_prime = 1.0 / a.a66;
  if (plane == Plane::stress) {
    c.E = 1.0 / a.a11;
    c.E_prime = 1.0 / a.a22;
    c.nu_prime = -a.a12 * c.E_prime;
    c.nu = c.nu_prime * c.E / c.E_prime;
    return c;
  }
  // Plane strain with nu'/E' = nu/E = p:  a12 = -p (1 + nu),  a11 = 1/E - nu p,  a22 = 1/E' - p^2 E.
  c.nu = -a.a12 / (a.a11 - a.a12);
  const double p = c.nu * a.a11 / (1.0 - c.nu * c.nu);
  c.E = 1.0 / (a.a11 + c.nu * p);
  c.E_prime = 1.0 / (a.a22 + p * p * c.E);
  c.nu_prime = p * c.E_prime;
  return c;
}

TIConstants goodman(double E_r, double nu_r, double k_n, double k_s, double spacing) {
  TIConstants c;
  c.E = E_r;
  c.nu = nu_r;
  c.E_prime = 1.0 / (1.0 / E_r + 1.0 / (k_n * spacing));
  c.nu_prime = nu_r * c.E_prime / E_r;
  c.G_prime = 1.0 / (2.0 * (1.0 + nu_r) / E_r + 1.0 / (k_s * spacing));
  return c;
}

TIConstants backus(double E1, double nu1, double h1, double E2, double nu2, double h2) {
  // Lame constants of each layer; layers normal along 3. Backus (1962) for isotropic constituents.
  const double f1 = h1 / (h1 + h2), f2 = h2 / (h1 + h2);
  auto lame = [](double E, double nu) {
    return std::array<double, 2>{E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))};
  };
  const auto [l1, m1] = lame(E1, nu1);
  const auto [l2, m2] = lame(E2, nu2);
  auto avg = [&](double x1, double x2) { return f1 * x1 + f2 * x2; };
  const double inv_lp2m = avg(1 / (l1 + 2 * m1), 1 / (l2 + 2 * m2));
  const double C33 = 1 / inv_lp2m;
  const double C13 = C33 * avg(l1 / (l1 + 2 * m1), l2 / (l2 + 2 * m2));
  const double C44 = 1 / avg(1 / m1, 1 / m2);
  const double C66 = avg(m1, m2);
  const double C11 = avg(4 * m1 * (l1 + m1) / (l1 + 2 * m1), 4 * m2 * (l2 + m2) / (l2 + 2 * m2)) + C13 * C13 / C33;
  const double C12 = C11 - 2 * C66;
  // Invert the TI stiffness for the engineering constants.
  const double D = (C11 - C12) * ((C11 + C12) * C33 - 2 * C13 * C13);
  const double S11 = (C11 * C33 - C13 * C13) / D;
  const double S12 = -(C12 * C33 - C13 * C13) / D;
  const double S13 = -C13 * (C11 - C12) / D;
  const double S33 = (C11 * C11 - C12 * C12) / D;
  TIConstants c;
  c.E = 1 / S11;
  c.nu = -S12 / S11;
  c.E_prime = 1 / S33;
  c.nu_prime = -S13 / S33;
  c.G_prime = C44;
  return c;
}

TIConstants add_joints(const TIConstants& c, double k_n, double k_s, double spacing) {
  TIConstants j = c;
  j.E_prime = 1.0 / (1.0 / c.E_prime + 1.0 / (k_n * spacing));
  j.nu_prime = c.nu_prime * j.E_prime / c.E_prime;  // S13 = -nu'/E' is not changed by the joints
  j.G_prime = 1.0 / (1.0 / c.G_prime + 1.0 / (k_s * spacing));
  return j;
}

TIConstants interbedded(double E1, double nu1, double h1, double E2, double nu2, double h2, double k_n, double k_s,
                        double spacing) {
  return add_joints(backus(E1, nu1, h1, E2, nu2, h2), k_n, k_s, spacing);
}

double jaeger_sliding_strength(const JaegerInput& in, double beta_deg) {
  const double mu = std::tan(in.friction_deg * deg);
  if (!(beta_deg > in.friction_deg) || !(beta_deg < 90.0)) return std::numeric_limits<double>::infinity();
  const double b = beta_deg * deg;
  const double denom = (1.0 - mu / std::tan(b)) * std::sin(2.0 * b);
  if (!(denom > 0)) return std::numeric_limits<double>::infinity();
  return in.confinement + 2.0 * (in.cohesion + mu * in.confinement) / denom;
}

double jaeger_strength(const JaegerInput& in, double beta_deg) {
  return std::min(jaeger_sliding_strength(in, beta_deg), in.intact_strength);
}

double jaeger_min_angle_deg(double friction_deg) { return 45.0 + 0.5 * friction_deg; }

double jaeger_min_uniaxial_strength(double cohesion, double friction_deg) {
  const double p = friction_deg * deg;
  return 2.0 * cohesion * std::cos(p) / (1.0 - std::sin(p));
}

}  // namespace rbdem::theory
