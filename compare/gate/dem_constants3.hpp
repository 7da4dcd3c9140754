// The 3D DEM's five elastic constants, measured by virtual tests: the static solve of the face-bond network
// (dem/static3.hpp) on prisms, unjointed and jointed at 0, 45 and 90 deg, between frictionless platens, with the
// axial and both lateral strains read from the fitted strain of the blocks' centroids (docs/continuum.md, "The 3D
// DEM's static moduli"):
//   unjointed prism: E_r = <sigma_zz> / -eps_zz, nu_r = the mean of the two lateral Poisson's ratios;
//   dip 0 (load along the joints' normal): E' and nu' (the mean of the two lateral ratios, both in the joint plane);
//   dip 90 (load in the joint plane): E and nu (the lateral strain along the strike, the other in-plane axis);
//   dip 45: Amadei's 1/E_45 = (1/E + 1/E' + 1/G' - 2 nu'/E') / 4 gives G'.
// Goodman's constants beside them: the unjointed prism's E_r and nu_r cut by joints of the bonds' extra compliance
// at the joint bonds' mean centroid distance (compare/gate/dem_constants.hpp, goodman_estimate).
// Goodman's on the jointed mesh: the mesher makes the tetrahedra conform to the joint planes, a fabric that makes
// the jointed mesh stiffer across the planes before any joint is weakened (docs/theory.md, "The 3D network against
// its continuum"). So the jointed prisms are also solved with rock bonds across the planes (E*_j = E*_r, kappa_j =
// kappa_r): their five constants are the rock as the jointed mesh carries it, and the same joints' compliance added
// to them (theory::add_joints: 1/E' += 1/(k_n s), 1/G' += 1/(k_s s)) is Goodman's estimate from that baseline.
#pragma once

#include <vector>

#include "compare/gate/dem_constants.hpp"
#include "dem/scene.hpp"
#include "dem/specimen_mesh3.hpp"
#include "dem/static3.hpp"
#include "theory/elasticity.hpp"

namespace rbdem::compare {

// One virtual test: the prism's dip and what the static solve read (the displacements dropped).
struct VirtualTest3 {
  double dip_deg = 0;
  double modulus = 0;                          // Pa, fit modulus (the body's own strain)
  double platen_modulus = 0;                   // Pa
  double poisson_strike = 0, poisson_dip = 0;  // -
  double joint_d_mean = 0;                     // m, area-weighted mean centroid distance of the joint bonds
  std::size_t blocks = 0, joint_bonds = 0, dofs = 0;
  double seconds = 0;                          // meshing and solve
};
VirtualTest3 virtual_test3(const Static3Result& r, double dip_deg, double seconds = 0);

// The bond materials of a scene for the static solve: rock and joint E* and kappa.
Static3Options static3_options(const Scene& scene);

// Isotropic constants of an unjointed network: E = the fit modulus, nu = the mean of the two lateral ratios.
theory::TIConstants isotropic_constants3(const VirtualTest3& unjointed);
// The five constants from the jointed prisms at 0, 45 and 90 deg (see above).
theory::TIConstants ti_constants3(const VirtualTest3& at0, const VirtualTest3& at45, const VirtualTest3& at90);

struct DemConstants3 {
  theory::TIConstants dem;       // measured (the intact rock's, isotropic, without joints)
  VirtualTest3 intact;           // the unjointed prism
  std::vector<VirtualTest3> tests;  // the jointed prisms at 0, 45, 90 deg (none without joints)
  GoodmanEstimate goodman;       // Goodman's constants from intact and the scene's bonds
  // The jointed prisms at 0, 45, 90 deg with rock bonds across the planes, their constants, and Goodman's from
  // them (the joints' k_n, k_s, spacing of `goodman`); empty and zero without joints.
  std::vector<VirtualTest3> fabric_tests;
  theory::TIConstants fabric;
  theory::TIConstants goodman_fabric;
  SpecimenGeometry3 prism;       // the prism they were measured on
  double seconds = 0;
};

// The prism the constants are measured on: the scene's prism, or a cylinder's bounding prism (diameter x diameter
// x height), with the scene's first joint set at dip direction 0 (the prism's faces along the strike).
SpecimenGeometry3 constants_prism(const Scene& scene);
// Meshes the prisms at mesh.size (one after the other: gmsh is one global model) and solves them on up to `threads`
// threads side by side (0 = the hardware's; each solve is independent, so the numbers do not depend on it). One
// joint set: the scene's joint_set (joint_set2 is refused by the caller). Throws SceneError for a scene that is not
// 3D.
DemConstants3 measure_dem_constants3(const Scene& scene, int threads = 1);

}  // namespace rbdem::compare
