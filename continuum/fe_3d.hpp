// The FE twin in 3D: deal.II transversely isotropic linear elasticity on the very TetMesh the 3D DEM uses (one
// deal.II cell per tetrahedron, one vertex per node), loaded in uniaxial compression between two platens. This
// header is deal.II-free (plain C++) so that callers do not pay deal.II's compile cost.
//
// The material is homogeneous: C = S^-1 with S = theory::rotated_compliance(c, dip, dip direction)
// (theory/elasticity3.hpp; docs/theory.md, "The layered cylinder in 3D"), its plane of isotropy along the joint
// planes. The specimen stands on z = zmin with its top at z = zmax, H = zmax - zmin; the platens are the boundary
// faces at those heights (tolerance 1e-6 of the largest extent).
//   frictionless: top u_z = -delta, bottom u_z = 0, tangential displacements free. The rigid modes left (the two
//                 horizontal translations and the rotation about z) are removed by pinning u_x and u_y at one
//                 bottom node and u_y at the bottom node farthest from it in x: rigid motions only, so any
//                 homogeneous strain (the shears of a tilted material included) stays possible.
//   bonded:       top u = (0, 0, -delta), bottom u = 0.
// Units: SI (m, Pa, N).
#pragma once

#include <cstddef>

#include "continuum/fe_model.hpp"
#include "mesh/tetmesh.hpp"
#include "theory/elasticity3.hpp"

namespace rbdem::continuum {

struct Fe3Options {
  int degree = 1;  // 1 or 2 (FE_SimplexP<3>)
  Platens platens = Platens::frictionless;
  Solver solver = Solver::automatic;  // automatic: UMFPACK below direct_dof_limit DoFs, CG+AMG above
  double platen_displacement = 1e-5;  // m, downward displacement of the top platen (> 0 = compression)
  // UMFPACK's fill grows fast on tetrahedra: at 11,800 P1 DoFs it takes 2.3 s where CG+AMG takes a fraction of
  // that (docs/continuum.md, "The 3D twin"), so the direct solver is for small meshes only.
  std::size_t direct_dof_limit = 3000;
  double cg_tolerance = 1e-10;  // CG stops at |r| <= cg_tolerance |b|
};

// The specimen's response. The axial force F follows from the stresses exactly (for any solution of the discrete
// equations F H = the integral of sigma_zz over the volume V: the displacement z e_z is a discrete test function).
// Two moduli:
//   apparent_modulus = <sigma_zz> / (delta / H), the platens' reading, with the mean axial stress
//     <sigma_zz> = F H / V (the force over the mean section V / H). On a prism it is 1/S'_33; on the meshed cylinder
//     it differs from the ideal cylinder's by the faceting of the side, whose facets are chords of the curved
//     surface and not vertical (docs/theory.md gives the measured size of this).
//   mean_strain_modulus = <sigma_zz> / <eps_zz>, with volume means. Between frictionless platens the mean stress
//     of any body is exactly uniaxial (<sigma> = (1/V) sum of x (x) reaction over the loaded nodes, and the
//     reactions are vertical and balanced in moment), so in a homogeneous material <eps> = S' <sigma> exactly:
//     1/S'_33 whatever the shape of the section or of its side.
// The lateral strains are the volume means of the horizontal strains along the joints' strike and dip direction
// (tension positive); the apparent Poisson's ratios are -<eps_lateral> / <eps_zz>.
struct Fe3Result {
  double apparent_modulus = 0;     // Pa, <sigma_zz> / (delta / H)
  double mean_strain_modulus = 0;  // Pa, <sigma_zz> / <eps_zz>
  double mean_axial_strain = 0;    // <eps_zz> (compression negative); -delta / H on a prism
  double axial_force = 0;       // N, compression positive
  double volume = 0;            // m^3, of the mesh
  double strain_strike = 0, strain_dip = 0;    // volume means, tension positive
  double poisson_strike = 0, poisson_dip = 0;  // -<eps_lateral> / <eps_zz>
  std::size_t dofs = 0, cells = 0;
  unsigned iterations = 0;                 // CG iterations (0 for the direct solver)
  Solver solver_used = Solver::automatic;  // direct or cg_amg
  double setup_seconds = 0;                // triangulation, DoFs, sparsity pattern, constraints
  double assemble_seconds = 0;             // element matrices, boundary values
  double solve_seconds = 0;                // factorisation or AMG setup, plus the solve
  double post_seconds = 0;                 // the force and mean strains
};

// Homogeneous TI material with its plane of isotropy along planes of the given dip and dip direction (degrees).
// Throws std::invalid_argument for inputs a user can get wrong (empty mesh, a tetrahedron of non-positive volume,
// non-admissible constants, degree other than 1 or 2, non-positive displacement).
Fe3Result solve_elastic_3d(const TetMesh& mesh, const theory::TIConstants& c, double dip_deg,
                           double dip_direction_deg, const Fe3Options& options = {});

}  // namespace rbdem::continuum
