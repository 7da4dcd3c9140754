// Closed forms of the Brazilian (diametral compression) test: a disc of diameter D = 2R and thickness t loaded by
// two equal and opposite forces P (N) at the ends of its vertical diameter, (0, +R) pushed down and (0, -R)
// pushed up. Coordinates (x, y) in m are relative to the disc centre; stresses in Pa, tension positive.
//
// 1. Isotropic disc, point loads (Hondros 1959; Timoshenko & Goodier, Theory of Elasticity): two Flamant
//    fields plus a uniform biaxial tension. With p = P / t, r1^2 = x^2 + (R - y)^2, r2^2 = x^2 + (R + y)^2:
//      sigma_xx = -(2p/pi) [ (R - y) x^2 / r1^4 + (R + y) x^2 / r2^4 ] + 2p / (pi D)
//      sigma_yy = -(2p/pi) [ (R - y)^3 / r1^4 + (R + y)^3 / r2^4 ] + 2p / (pi D)
//      sigma_xy =  (2p/pi) [ (R - y)^2 x / r1^4 - (R + y)^2 x / r2^4 ]
//    At the centre sigma_xx = 2P / (pi D t) (tension across the loaded diameter), sigma_yy = -6P / (pi D t),
//    sigma_xy = 0. The field does not depend on the elastic constants. The ISRM indirect tensile strength is
//    sigma_t = 2P / (pi D t) with P the failure load.
//
// 2. Transversely isotropic disc: the approximate principal tension at the centre of Claesson & Bohloli (2002,
//    Int J Rock Mech Min Sci 39:991-1004, "reasonably accurate"), printed as
//      sigma_t(0, 0) ~ (2P / (pi D t)) [ (E/E')^(cos(2 theta) / 4) - (cos(4 theta) / 4) (b - 1) ],
//      b = sqrt(E E') / 2 (1/G' - 2 nu'/E'),
//    theta the angle between the load and the plane of isotropy (the bedding). A 2D traction problem depends on the
//    material only through its reduced compliance a (theory/elasticity.hpp), and its stresses only through
//    a22/a11 and (2 a12 + a66) / sqrt(a11 a22) (the roots of a11 mu^4 + (2 a12 + a66) mu^2 + a22 = 0, Lekhnitskii),
//    so the formula is evaluated from a, which serves plane stress and plane strain alike:
//      b = (2 a12 + a66) / (2 sqrt(a11 a22))    (plane stress: the b above; isotropic: 1)
//      factor(beta) = (a22 / a11)^(cos(2 beta) / 4) - (cos(4 beta) / 4) (b - 1),   sigma_t = factor 2P / (pi D t)
//    with beta the dip of the bedding from the horizontal and the load vertical (rbdem's convention), so that
//    theta = 90 deg - beta and cos(4 theta) = cos(4 beta). In plane stress a22 / a11 = E/E' with E along the
//    bedding (TIConstants), and cos(2 beta) = -cos(2 theta): this is the printed formula with the ratio E/E'
//    taken as (modulus normal to the bedding) / (modulus along it). Read the other way (E along the bedding, as
//    TIConstants has it), the printed formula puts the larger tension at beta = 90 (load along the bedding, the
//    soft direction across the load) and grows without bound as E' -> 0 there, where a direction of vanishing
//    stiffness can carry little stress; the FE disc (continuum/fe_disc.hpp, tests/test_disc.cpp) confirms the
//    orientation used here and measures the accuracy of the approximation: 0.2 % for rbdem's default paper constants
//    (E/E' = 1.17), 3.6 % at E/E' = 2, 14-21 % at E/E' = 4 (max over beta, plane stress).
#pragma once

#include "theory/elasticity.hpp"

namespace rbdem::theory {

// In-plane stress (Pa, tension positive).
struct DiscStress {
  double xx = 0, yy = 0, xy = 0;
};

// The larger principal stress (Pa, tension positive) of an in-plane stress: Claesson & Bohloli's sigma_t is the
// principal tension at the centre, which differs from sigma_xx there when sigma_xy != 0 (bedding neither
// horizontal nor vertical).
double principal_tension(const DiscStress& s);

// 2P / (pi D t): the ISRM indirect tensile strength for the failure load P, and the isotropic centre tension.
// P in N, D and t in m, result in Pa. Throws std::invalid_argument for non-positive D or t or a non-finite P.
double brazilian_tensile_strength(double load, double diameter, double thickness);

// The isotropic point-load field at (x, y) from the centre (|(x, y)| <= R; the two load points are singular and
// give infinities). Throws std::invalid_argument for a point outside the disc or bad D, t, P.
DiscStress hondros_stress(double load, double diameter, double thickness, double x, double y);

// Its centre value {2P/(pi D t), -6P/(pi D t), 0}.
DiscStress hondros_centre_stress(double load, double diameter, double thickness);

// Mean of the isotropic field over the concentric circle of the given radius rho (0 < rho < R), by quadrature
// (Gauss-Legendre in r, trapezoidal in the angle, spectrally accurate: relative error below 1e-12 for
// rho <= 0.9 R). Near the centre it is the centre value plus (rho^2 / 8) times the Laplacian of the stress;
// sigma_xx + sigma_yy is harmonic, so its mean equals the centre value 4P/(pi D t) exactly.
DiscStress hondros_mean_stress(double load, double diameter, double thickness, double radius);

// The two parameters of the approximation from the reduced compliance: stiffness_ratio = a22 / a11 (E/E' in
// plane stress) and b = (2 a12 + a66) / (2 sqrt(a11 a22)). Throws std::invalid_argument unless a11, a22 > 0.
struct ClaessonBohloliParameters {
  double stiffness_ratio = 1, b = 1;
};
ClaessonBohloliParameters claesson_bohloli_parameters(const ReducedCompliance& a);

// sigma_t(0, 0) / (2P / (pi D t)) of Claesson & Bohloli's approximation (section 2 above), bedding dipping at
// beta_deg from the horizontal, load vertical.
double claesson_bohloli_factor(const ReducedCompliance& a, double beta_deg);
double claesson_bohloli_factor(const TIConstants& c, Plane plane, double beta_deg);

// The approximate centre tension itself (Pa): factor * 2P / (pi D t).
double claesson_bohloli_centre_tension(const TIConstants& c, Plane plane, double beta_deg, double load,
                                       double diameter, double thickness);

}  // namespace rbdem::theory
