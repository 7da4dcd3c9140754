// Closed-form theory in three dimensions (docs/theory.md, section "The layered cylinder in 3D"): the transversely
// isotropic compliance rotated to a joint plane of any dip and dip direction, and Amadei's apparent modulus and
// lateral strains of a specimen under a uniaxial stress between frictionless platens.
//
// Axes: x and y horizontal (y the depth axis), z vertical (the load axis). A joint plane dips by `dip_deg` from the
// horizontal; `dip_direction_deg` turns its strike about z from the y axis: at 0 the strike runs along y and the
// x-z section is the 2D specimen's slice through the dip, with the same bedding trace (the plane rises towards +x
// at dip < 90 deg). The plane's unit normal is n = (-sin(dip) cos(dd), -sin(dip) sin(dd), cos(dip)).
#pragma once

#include <array>

#include "theory/elasticity.hpp"

namespace rbdem::theory {

using Vec3 = std::array<double, 3>;
// Voigt order [xx, yy, zz, yz, xz, xy] with engineering shear strains: eps = S sigma.
using Compliance6 = std::array<std::array<double, 6>, 6>;

// The joint plane's axes: its unit normal, the horizontal strike direction (-sin dd, cos dd, 0) and the horizontal
// dip direction (cos dd, sin dd, 0), the direction of the horizontal section through the dip.
struct PlaneAxes {
  Vec3 normal, strike, dip_direction;
};
PlaneAxes plane_axes(double dip_deg, double dip_direction_deg);

// The compliance in the material frame (axes 1, 2 in the plane of isotropy, 3 along its normal): S11 = S22 = 1/E,
// S33 = 1/E', S12 = -nu/E, S13 = S23 = -nu'/E', S44 = S55 = 1/G', S66 = 2 (1 + nu) / E.
Compliance6 ti_compliance(const TIConstants& c);
// The same material in the global axes, its plane of isotropy along the joint plane: the tensor S_ijkl turned by
// the rotation whose rows are the strike, the in-plane dip line and the normal (numerically, as a tensor).
Compliance6 rotated_compliance(const TIConstants& c, double dip_deg, double dip_direction_deg);

// A uniaxial stress sigma_zz = 1 Pa between frictionless platens (the stress is uniform): the apparent modulus
// 1 / S_33 and the horizontal strains along the strike and along the dip direction, per unit axial stress (1/Pa;
// tension positive). `poisson_*` are the apparent Poisson's ratios -eps_lateral / eps_zz.
struct Uniaxial3 {
  double modulus = 0;
  double strain_strike = 0, strain_dip = 0;
  double poisson_strike = 0, poisson_dip = 0;
  double shear_dip = 0;  // engineering shear strain gamma_zd = 2 z . eps . d per unit axial stress, 1/Pa
};
// From the rotated compliance: eps = S e_z, read along the two horizontal axes.
Uniaxial3 uniaxial_from_compliance(const TIConstants& c, double dip_deg, double dip_direction_deg);
// Amadei's closed forms with theta = dip, the angle between the load axis and the normal (independent of the
// dip direction): 1/E_z = sin^4/E + cos^4/E' + sin^2 cos^2 (1/G' - 2 nu'/E'); eps_strike = -(nu sin^2 / E +
// nu' cos^2 / E'); eps_dip = sin^2 cos^2 (1/E + 1/E' - 1/G') - (sin^4 + cos^4) nu'/E'.
Uniaxial3 amadei_uniaxial_3d(const TIConstants& c, double dip_deg);

}  // namespace rbdem::theory
