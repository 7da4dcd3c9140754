// Transversely isotropic compliance in 3D and Amadei's uniaxial closed forms. See elasticity3.hpp.
#include "theory/elasticity3.hpp"

#include <cmath>
#include <numbers>

namespace rbdem::theory {

namespace {

constexpr double deg = std::numbers::pi / 180.0;

using Tensor2 = std::array<std::array<double, 3>, 3>;
// Voigt index of each component pair.
constexpr int voigt[3][3] = {{0, 5, 4}, {5, 1, 3}, {4, 3, 2}};

// Stress tensor of the Voigt vector with a 1 at position k.
Tensor2 unit_stress(int k) {
  Tensor2 s{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (voigt[i][j] == k) s[i][j] = 1.0;
  return s;
}

// R t R^T (forward = true: global to material) or R^T t R.
Tensor2 turn(const std::array<Vec3, 3>& R, const Tensor2& t, bool forward) {
  Tensor2 out{};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          out[a][b] += forward ? R[a][i] * R[b][j] * t[i][j] : R[i][a] * R[j][b] * t[i][j];
  return out;
}

// eps = S sigma on tensors, S in Voigt form with engineering shear.
Tensor2 apply(const Compliance6& S, const Tensor2& sigma) {
  const std::array<double, 6> s{sigma[0][0], sigma[1][1], sigma[2][2], sigma[1][2], sigma[0][2], sigma[0][1]};
  Tensor2 eps{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const int k = voigt[i][j];
      double e = 0;
      for (int m = 0; m < 6; ++m) e += S[k][m] * s[m];
      eps[i][j] = i == j ? e : 0.5 * e;  // engineering shear -> tensor component
    }
  return eps;
}

double along(const Tensor2& t, const Vec3& d) {
  double v = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) v += d[i] * t[i][j] * d[j];
  return v;
}

}  // namespace

PlaneAxes plane_axes(double dip_deg, double dip_direction_deg) {
  const double sd = std::sin(dip_deg * deg), cd = std::cos(dip_deg * deg);
  const double sa = std::sin(dip_direction_deg * deg), ca = std::cos(dip_direction_deg * deg);
  return {{-sd * ca, -sd * sa, cd}, {-sa, ca, 0.0}, {ca, sa, 0.0}};
}

Compliance6 ti_compliance(const TIConstants& c) {
  Compliance6 S{};
  S[0][0] = S[1][1] = 1.0 / c.E;
  S[2][2] = 1.0 / c.E_prime;
  S[0][1] = S[1][0] = -c.nu / c.E;
  S[0][2] = S[2][0] = S[1][2] = S[2][1] = -c.nu_prime / c.E_prime;
  S[3][3] = S[4][4] = 1.0 / c.G_prime;
  S[5][5] = 2.0 * (1.0 + c.nu) / c.E;
  return S;
}

Compliance6 rotated_compliance(const TIConstants& c, double dip_deg, double dip_direction_deg) {
  const PlaneAxes axes = plane_axes(dip_deg, dip_direction_deg);
  const Vec3& n = axes.normal;
  const Vec3& s = axes.strike;
  // The in-plane dip line p = s x n, so that (p, s, n) is right-handed; at dip direction 0 it is the 2D bedding
  // trace (cos dip, 0, sin dip).
  const Vec3 p{s[1] * n[2] - s[2] * n[1], s[2] * n[0] - s[0] * n[2], s[0] * n[1] - s[1] * n[0]};
  const std::array<Vec3, 3> R{p, s, n};
  const Compliance6 local = ti_compliance(c);
  Compliance6 S{};
  for (int k = 0; k < 6; ++k) {
    const Tensor2 eps = turn(R, apply(local, turn(R, unit_stress(k), true)), false);
    for (int i = 0; i < 3; ++i)
      for (int j = i; j < 3; ++j) S[voigt[i][j]][k] = i == j ? eps[i][j] : 2.0 * eps[i][j];
  }
  return S;
}

Uniaxial3 uniaxial_from_compliance(const TIConstants& c, double dip_deg, double dip_direction_deg) {
  const Compliance6 S = rotated_compliance(c, dip_deg, dip_direction_deg);
  const PlaneAxes axes = plane_axes(dip_deg, dip_direction_deg);
  Tensor2 eps{};  // eps = S e_z, as a tensor
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) eps[i][j] = (i == j ? 1.0 : 0.5) * S[voigt[i][j]][2];
  Uniaxial3 u;
  u.modulus = 1.0 / S[2][2];
  u.strain_strike = along(eps, axes.strike);
  u.strain_dip = along(eps, axes.dip_direction);
  u.poisson_strike = -u.strain_strike / S[2][2];
  u.poisson_dip = -u.strain_dip / S[2][2];
  const Vec3 z{0.0, 0.0, 1.0};
  double zd = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) zd += z[i] * eps[i][j] * axes.dip_direction[j];
  u.shear_dip = 2.0 * zd;
  return u;
}

Uniaxial3 amadei_uniaxial_3d(const TIConstants& c, double dip_deg) {
  const double s = std::sin(dip_deg * deg), co = std::cos(dip_deg * deg);
  const double s2 = s * s, c2 = co * co;
  const double s_zz = s2 * s2 / c.E + c2 * c2 / c.E_prime + s2 * c2 * (1.0 / c.G_prime - 2.0 * c.nu_prime / c.E_prime);
  Uniaxial3 u;
  u.modulus = 1.0 / s_zz;
  u.strain_strike = -(c.nu * s2 / c.E + c.nu_prime * c2 / c.E_prime);
  u.strain_dip = s2 * c2 * (1.0 / c.E + 1.0 / c.E_prime - 1.0 / c.G_prime) - (s2 * s2 + c2 * c2) * c.nu_prime / c.E_prime;
  u.poisson_strike = -u.strain_strike / s_zz;
  u.poisson_dip = -u.strain_dip / s_zz;
  u.shear_dip = 2.0 * s * co *
                (s2 / c.E - c2 / c.E_prime + c.nu_prime * (s2 - c2) / c.E_prime + (c2 - s2) / (2.0 * c.G_prime));
  return u;
}

}  // namespace rbdem::theory
