// Verification case: stress concentration at a circular hole in a transversely isotropic plate under uniaxial
// tension, against Lekhnitskii's closed form for the infinite plate (docs/theory.md, section 9). Checks the constitutive model
// of the continuum twin (the same plane stiffness C = S^-1 as continuum/fe_model.hpp) and the FE discretisation.
// This header is deal.II-free (plain C++17); the deal.II model is in hole.cpp.
//
// Problem: hole of radius a at the origin in the square plate [-L, L]^2, far-field tension sigma_xx = p applied as
// a uniform traction on x = +-L, the other sides and the hole traction-free. The bedding trace (material axis 1)
// is at material_angle_deg counter-clockwise from x. When the material axes are aligned with the load (angle a
// multiple of 90 deg, so S16 = S26 = 0) only the quarter [0, L]^2 is modelled, with u_x = 0 on x = 0 and u_y = 0
// on y = 0; otherwise the full plate, with the rigid-body modes removed by three point constraints on the
// traction-free edges y = +-L (they carry no reaction because the load is self-equilibrated).
//
// Closed form, infinite plate, orthotropic axes aligned with the load, global compliance S (Voigt [xx, yy, xy]):
//     SCF = sigma_thetatheta(theta = 90 deg) / p = 1 + sqrt((2 S12 + S66) / S11 + 2 sqrt(S22 / S11))
// which for the load along material axis 1 (angle 0) is docs/theory.md, section 9 with a_ij = theory::reduced_compliance;
// isotropic: 3. The finite plate differs from it by O((a/L)^2) (docs/continuum_hole.md quantifies it).
//
// Mesh: a structured graded polar mesh of quadrilaterals (FE_Q(degree), MappingQ(degree), the hole boundary on a
// PolarManifold). Node (i, j) lies on the ray at angle theta_j at distance r = a (R(theta_j) / a)^(i / n_r) from
// the centre, R(theta) being the distance to the square's edge along the ray; so the elements keep an aspect
// ratio near 1 from the hole (size ~ a dtheta) to the edge (size ~ L dtheta). Refinement level k puts
// n_t = 4 * 2^k elements along the quarter circle and n_r = 2^k round(4 ln(L/a) / (pi/2)) along each ray, so each
// level halves every element: a self-similar sequence for the convergence order.
//
// Hole-edge stress (scf): from the hoop strain. On the traction-free hole sigma_rr = tau_rtheta = 0, so
// eps_thetatheta = S_tt sigma_thetatheta exactly, S_tt being the compliance along the tangent. eps_thetatheta =
// t . grad(u_h) . t is evaluated exactly at the hole-boundary vertex (FEValues at that vertex of the reference
// cell, no extrapolation or projection) and averaged over the cells sharing it. It needs only the tangential
// derivative of the boundary displacement: order 2 for Q1 and about 3.5 for Q2 (docs/continuum_hole.md), against
// O(h^degree) for the full FE stress C eps(u_h) at the vertex, which is reported as scf_pointwise.
// Units: SI (m, Pa); the SCF is dimensionless and independent of a, p and the scale of the moduli.
#pragma once

#include <cstddef>

#include "theory/elasticity.hpp"

namespace rbdem::continuum {

struct HoleOptions {
  int degree = 2;             // 1 (Q1) or 2 (Q2)
  int refinement = 3;         // level k >= 0: 4 * 2^k elements along the quarter hole edge
  double plate_ratio = 40;    // L / a: plate half-width over hole radius (> 2)
  double hole_radius = 0.01;  // a, m
  double applied_stress = 1e6;  // p, Pa, far-field tension along x
  bool full_plate = false;      // model the full plate even when the quarter would do (a check of the full model)
};

struct HoleResult {
  double scf = 0;                  // sigma_thetatheta / p at the top of the hole (theta = 90 deg), from the hoop strain
  double scf_pointwise = 0;        // the same from the full FE stress C eps(u_h) at the vertex (for comparison)
  double scf_max = 0;              // max over the hole-boundary vertices of sigma_thetatheta / p (hoop strain)
  double scf_max_angle_deg = 0;    // where scf_max occurs, counter-clockwise from x
  double scf_closed_form = 0;      // infinite-plate closed form when the axes are aligned, NaN otherwise
  double radial_stress_residual = 0;  // max |sigma_rr| / p at the hole vertices: 0 exactly, a discretisation check
  double hole_element_size = 0;    // m, element edge along the hole, a * dtheta
  bool quarter = true;             // quarter plate with symmetry conditions, or the full plate
  std::size_t dofs = 0, cells = 0;
  double seconds = 0;              // wall time of the whole solve (mesh, assembly, UMFPACK, stress recovery)
};

// Throws std::invalid_argument for a degree other than 1 or 2, a negative refinement, plate_ratio <= 2,
// non-positive radius or stress, or non-admissible constants. Solves with UMFPACK (no MPI needed).
HoleResult solve_hole(const theory::TIConstants& c, double material_angle_deg, theory::Plane plane,
                      const HoleOptions& o = {});

// The infinite-plate closed form above for a global compliance with S16 = S26 = 0 (load along x).
double hole_scf_closed_form(const theory::Compliance3& S);
// Load along material axis 1 (docs/theory.md, section 9): hole_scf_closed_form(rotated_compliance(reduced_compliance(c, plane), 0)).
double lekhnitskii_hole_scf(const theory::TIConstants& c, theory::Plane plane);

}  // namespace rbdem::continuum
