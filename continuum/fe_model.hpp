// Continuum twin of the DEM specimen: deal.II transversely isotropic linear elasticity on the very TriMesh the
// DEM uses (one deal.II cell per triangle, one vertex per node), loaded in uniaxial compression between two
// platens. This header is deal.II-free (plain C++17) so that callers do not pay deal.II's compile cost.
//
// The material is homogeneous: the TI stiffness C = S^-1 with S = theory::rotated_compliance(
// theory::reduced_compliance(c, plane), bedding_deg) (docs/theory.md, section 2), bedding trace at bedding_deg counter-clockwise
// from x. The specimen occupies the mesh bounding box [xmin, xmax] x [ymin, ymax]; W = xmax - xmin, H = ymax - ymin.
// Platens (boundary nodes identified by coordinate, tolerance 1e-6 max(W, H)):
//   frictionless: top u_y = -delta, bottom u_y = 0, u_x free on both except one pin u_x = 0 at the bottom-left
//                 node (removes the rigid x-translation only, so the S16/S26 shear u_x = gamma y stays possible).
//                 The stress is uniform and E_app = 1 / S22 exactly: a patch test.
//   bonded:       top u = (0, -delta), bottom u = (0, 0). The end restraint stiffens the specimen.
// Units: SI (m, Pa, N). Forces are for the given out-of-plane thickness t; the model is solved per unit thickness.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "theory/elasticity.hpp"
#include "mesh/trimesh.hpp"

namespace rbdem::continuum {

enum class Platens { frictionless, bonded };

// automatic: direct (UMFPACK) below FeOptions::direct_dof_limit DoFs, CG preconditioned by smoothed-aggregation
// AMG (Trilinos ML with the three rigid-body modes) above.
enum class Solver { automatic, direct, cg_amg };

// How element matrices are computed. Both contract eps(phi_i) : C : eps(phi_j) JxW with the same C.
//   affine:     the straight-sided triangles have a constant Jacobian J, so each element matrix is
//               |det J| sum_mn R_ab[m][n] (J^-1 C J^-T)_cd[m][n] with a reference tensor R of shape-gradient
//               products integrated once on the reference triangle. Exact for MappingFE(FE_SimplexP(1)).
//   fe_values:  textbook FEValues per cell (deal.II step-8); the reference the affine path is tested against.
enum class Assembly { affine, fe_values };

struct FeOptions {
  int degree = 1;                               // 1 or 2 (FE_SimplexP)
  theory::Plane plane = theory::Plane::strain;  // plane strain (default) or plane stress
  Platens platens = Platens::frictionless;
  Solver solver = Solver::automatic;  // automatic: direct below direct_dof_limit DoFs, CG+AMG above
  double platen_displacement = 1e-5;  // m, downward displacement of the top platen (> 0 = compression)
  bool fields = true;                 // fill the centroid fields
  Assembly assembly = Assembly::affine;
  // Solver::automatic uses CG+AMG from this many DoFs on: UMFPACK is slower than CG+AMG from about 1e4 DoFs
  // and twice as slow at 6e4 (docs/continuum.md).
  std::size_t direct_dof_limit = 20000;
  // CG stops at |r| <= cg_tolerance |b| (b: the right-hand side with the platen displacements). At 1e-8 the
  // modulus is within ~1e-13 of the exact discrete value and top and bottom forces agree to a few 1e-8.
  double cg_tolerance = 1e-8;
};

struct FeResult {
  double apparent_modulus = 0;             // Pa: (F_top / (W t)) / (platen_displacement / H)
  double top_force = 0, bottom_force = 0;  // N, compression positive, for thickness t
  std::size_t dofs = 0, cells = 0;
  unsigned iterations = 0;                 // CG iterations (0 for the direct solver)
  Solver solver_used = Solver::automatic;  // direct or cg_amg after resolving Solver::automatic
  double setup_seconds = 0;                // triangulation, DoFs, sparsity pattern, platen DoFs
  double assemble_seconds = 0;             // element matrices into the global matrix, platen displacements
  double solve_seconds = 0;                // factorisation or AMG setup, plus the solve
  double precondition_seconds = 0;         // the factorisation or AMG setup alone (part of solve_seconds)
  double fields_seconds = 0;               // reactions and centroid fields (not part of the three above)
  std::vector<double> ux, uy;              // m, displacement at each triangle's centroid (same order as mesh.triangles)
  std::vector<double> sxx, syy, sxy;       // Pa, tension positive, stress at each triangle's centroid
};

// Homogeneous TI material with the bedding trace at bedding_deg counter-clockwise from x (= the joint dip beta).
// Throws std::invalid_argument for inputs a user can get wrong (empty or clockwise mesh, non-admissible constants,
// degree other than 1 or 2, non-positive thickness or displacement). Initialises MPI itself when nobody did
// (Trilinos needs it) and finalises it at exit; under mpirun it leaves MPI alone and solves serially on each rank.
// Calls from several threads work on separate deal.II objects; the CG+AMG stage runs one call at a time.
FeResult solve_elastic(const TriMesh& mesh, const theory::TIConstants& c, double bedding_deg, double thickness,
                       const FeOptions& options = {});

// The plane stiffness C = S^-1 in Voigt form [xx, yy, xy] with engineering shear strain (Pa), as the model uses it.
using Stiffness3 = std::array<std::array<double, 3>, 3>;
Stiffness3 stiffness_voigt(const theory::TIConstants& c, double bedding_deg, theory::Plane plane);

// The deal.II version the model was built with (a smoke check that the library links).
std::string dealii_version();

}  // namespace rbdem::continuum
