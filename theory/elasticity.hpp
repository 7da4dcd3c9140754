// Closed-form theory (docs/theory.md): transversely isotropic elasticity (sections 2, 3) and Jaeger's plane of
// weakness (section 3). Plain functions of plain values, SI units, angles in degrees at the interface.
//
// Convention: beta is the dip of the bedding / joints from the horizontal, the load is vertical. The bedding
// trace makes the angle theta = beta with the x axis, so the apparent modulus under a vertical uniaxial stress
// with platens free to slide is E_app(beta) = 1 / S22(theta = beta).
#pragma once

#include <array>
#include <string>

namespace rbdem::theory {

enum class Plane { strain, stress };
Plane plane_from_string(const std::string& model);  // "plane_strain" | "plane_stress"

// The five constants: E, nu in the plane of isotropy (the bedding), E', nu' for stress normal to it,
// G' for shear in planes normal to the bedding. Pa and dimensionless.
struct TIConstants {
  double E = 0, nu = 0, E_prime = 0, nu_prime = 0, G_prime = 0;

  static TIConstants isotropic(double E, double nu);
  bool admissible() const;  // positive definite compliance
};

// 2D reduced compliance in the material frame (x' along the bedding trace, y' normal to it):
// eps' = a sigma' with Voigt order [xx, yy, xy] and engineering shear strain.
struct ReducedCompliance {
  double a11 = 0, a22 = 0, a12 = 0, a66 = 0;
};
ReducedCompliance reduced_compliance(const TIConstants& c, Plane plane);

// Global compliance S (3x3, Voigt [xx, yy, xy]) with the bedding trace at theta degrees counter-clockwise from x.
using Compliance3 = std::array<std::array<double, 3>, 3>;
Compliance3 rotated_compliance(const ReducedCompliance& a, double theta_deg);

// Apparent modulus under a vertical uniaxial stress with frictionless platens: 1 / S22(beta).
double apparent_modulus(const ReducedCompliance& a, double beta_deg);
double apparent_modulus(const TIConstants& c, double beta_deg, Plane plane);
// Amadei's plane-stress formula written out (docs/theory.md, section 2), kept separate as an independent check.
double amadei_plane_stress(const TIConstants& c, double beta_deg);

// Recovers the constants from a measured 2D reduced compliance. Plane stress: E = 1/a11, E' = 1/a22,
// nu' = -a12 E', G' = 1/a66, and nu (which 2D cannot see) = nu' E / E'. Plane strain: four equations for five
// unknowns, closed by the jointed-rock relation nu'/E' = nu/E (Goodman's), which gives nu = -a12 / (a11 - a12).
TIConstants constants_from_compliance(const ReducedCompliance& a, Plane plane);

// Goodman's equivalent continuum of intact rock (E_r, nu_r) with one joint set of normal and shear stiffness
// per unit area k_n, k_s (Pa/m) at spacing s (m).
TIConstants goodman(double E_r, double nu_r, double k_n, double k_s, double spacing);

// Backus average of a periodic stack of two isotropic layers (thickness h1, h2): the exact long-wave
// constants of the layered medium, for checking Goodman's formula with a thin soft layer.
TIConstants backus(double E1, double nu1, double h1, double E2, double nu2, double h2);

// A TI medium with the layering normal along 3 (the constants `c`) cut by one set of joints parallel to the
// layering, of normal and shear stiffness per unit area k_n, k_s (Pa/m, +inf = no joints) at spacing s (m): the
// joints deform in series with the medium normal to them and are not engaged along them (Amadei and Goodman, 1981):
// 1/E' += 1/(k_n s), 1/G' += 1/(k_s s), nu'/E' and E, nu unchanged. goodman() is this on an isotropic rock.
TIConstants add_joints(const TIConstants& c, double k_n, double k_s, double spacing);

// Salamon's (1968) equivalent medium of interbedded rocks with joints: the Backus average of the periodic stack of
// two isotropic rocks (E1, nu1) and (E2, nu2) of thicknesses h1, h2 per period, cut by joints at `spacing` parallel
// to the beds (add_joints). Equal rocks give goodman(E1, nu1, ...).
TIConstants interbedded(double E1, double nu1, double h1, double E2, double nu2, double h2, double k_n, double k_s,
                        double spacing);

// Jaeger's single plane of weakness (docs/theory.md, section 4). Angles in degrees; returns the axial strength in Pa.
struct JaegerInput {
  double cohesion = 0;       // c_j, Pa
  double friction_deg = 0;   // phi_j
  double intact_strength = 0;  // strength where sliding does not govern (e.g. the beta = 90 strength), Pa
  double confinement = 0;    // sigma_3 (compression positive), Pa
};
double jaeger_sliding_strength(const JaegerInput& in, double beta_deg);  // +inf where sliding is impossible
double jaeger_strength(const JaegerInput& in, double beta_deg);          // min(sliding, intact)
double jaeger_min_angle_deg(double friction_deg);                        // 45 + phi_j / 2
double jaeger_min_uniaxial_strength(double cohesion, double friction_deg);  // 2 c cos(phi) / (1 - sin(phi))

}  // namespace rbdem::theory
