// FE reference of the Brazilian (diametral compression) test: deal.II plane linear elasticity of a homogeneous
// transversely isotropic disc loaded by two opposite point forces at the ends of its vertical diameter, on a
// TriMesh of the disc. The closed forms it is checked against are in theory/disc.hpp (Hondros for the isotropic
// disc, Claesson & Bohloli's approximation for the TI one). This header is deal.II-free (plain C++17); the model
// is in fe_disc.cpp.
//
// Geometry, read from the mesh: the boundary nodes (on edges of one triangle) must lie on one circle, with a node
// at its top (cx, cy + R) and one at its bottom (cx, cy - R). The top node is the highest boundary node, the
// bottom node the lowest; (cx, cy) is their midpoint and R half their distance. Checked to
// DiscOptions::geometry_tolerance * R: the two on one vertical line, every boundary node at distance R.
//
// Material: the plane stiffness C = S^-1 with S = theory::rotated_compliance(theory::reduced_compliance(c, plane),
// bedding_deg), the bedding trace at bedding_deg counter-clockwise from x (= the joint dip beta); the same C as
// continuum::stiffness_voigt (continuum/fe_model.hpp). Elements: FE_SimplexP(1) or (2) in an FESystem of two.
//
// Load: f_y = -P at the top node and +P at the bottom node (P > 0 compresses the disc), solved per unit thickness
// with P / t, so stresses are those of a disc of thickness t. The load is self-equilibrated; the rigid-body modes
// are removed by point constraints (DiscPins). Three constraints that block the three rigid modes are statically
// determinate: their reactions equal minus the resultant and moment of the load, which vanish, so they are 0 for
// any mesh (to round-off) and the stresses do not depend on which three are chosen. A fourth (redundant) one
// carries no reaction only if the discrete solution satisfies it anyway: u_x(top) = -u_x(bottom) holds when the
// mesh is centrally symmetric (the material and the load are invariant under the half-turn about the centre),
// otherwise it carries a small self-equilibrated reaction of the order of the discretisation error.
//
// Centre stress (tension positive, Pa), three estimates:
//   centre_mean:  area-weighted mean of the cell-mean stresses over the cells whose centroid lies within
//                 r_avg = DiscOptions::average_radius of (cx, cy): the exact mean of the FE stress over that union
//                 of cells (for P2 the cell mean is the centroid value, the stress being linear in a cell). It
//                 differs from the centre value by the curvature of the field, about (r_avg^2 / 8) lap(sigma):
//                 for the isotropic disc and r_avg = R/10, sigma_xx is about 1 % below 2P/(pi D t).
//   centre_point: the FE stress at (cx, cy); where the point lies on an edge or a node (a node of the structured
//                 meshes), the area-weighted mean of the values of the cells that contain it.
//   centre_fit:   the constant term of the area-weighted least-squares fit of a quadratic in (x - cx, y - cy) to
//                 the cell means over the same cells (the cell mean of each monomial integrated exactly): removes
//                 the curvature bias of centre_mean. NaN when fewer than 12 cells lie within r_avg.
// Units: SI (m, Pa, N). Forces are for the given thickness t.
#pragma once

#include <cstddef>
#include <vector>

#include "continuum/fe_model.hpp"
#include "mesh/trimesh.hpp"
#include "theory/disc.hpp"
#include "theory/elasticity.hpp"

namespace rbdem::continuum {

// The point constraints that remove the rigid-body modes (all with zero displacement). "centre" is the mesh node
// nearest to (cx, cy).
enum class DiscPins {
  centre_and_top,         // u_x, u_y at the centre node, u_x at the top node: 3, statically determinate
  diameter_ends,          // u_x at the top and bottom nodes, u_y at the centre node: 3, statically determinate
  centre_top_and_bottom,  // u_x, u_y at the centre node, u_x at the top and bottom nodes: 4, one redundant
};

struct DiscOptions {
  int degree = 1;                   // 1 or 2 (FE_SimplexP)
  double average_radius = 0;        // m, r_avg of centre_mean and centre_fit; 0 = R / 10
  bool fields = false;              // fill the per-triangle centroid stresses
  DiscPins pins = DiscPins::centre_and_top;
  Solver solver = Solver::automatic;     // UMFPACK below direct_dof_limit DoFs, CG + AMG (Trilinos ML) above
  std::size_t direct_dof_limit = 20000;  // as FeOptions (docs/continuum.md: UMFPACK is slower above ~1e4 DoFs)
  double cg_tolerance = 1e-10;           // CG stops at |r| <= cg_tolerance |b|
  double geometry_tolerance = 1e-6;      // relative to R: top/bottom on one vertical, boundary nodes on the circle
};

struct DiscReaction {
  int node = 0;        // mesh node index
  int component = 0;   // 0: x, 1: y
  double force = 0;    // N for thickness t: the force the constraint exerts on the disc
};

struct DiscResult {
  theory::DiscStress centre_mean, centre_point, centre_fit;  // Pa, tension positive
  double average_radius = 0;  // m, the r_avg used
  double average_area = 0;    // m^2, the area of the cells averaged over
  std::size_t average_cells = 0;
  double cx = 0, cy = 0, radius = 0;                    // m, the disc read from the mesh
  int top_node = -1, bottom_node = -1, centre_node = -1;  // mesh node indices (load points and the centre pin)
  std::vector<DiscReaction> reactions;                  // one per constraint
  double max_reaction = 0;                              // N, max |force| over the constraints
  std::size_t dofs = 0, cells = 0;
  unsigned iterations = 0;                 // CG iterations (0 for the direct solver)
  Solver solver_used = Solver::automatic;  // direct or cg_amg after resolving Solver::automatic
  double seconds = 0;                      // wall time of the whole call
  std::vector<double> sxx, syy, sxy;       // Pa, per triangle (mesh order) at its centroid, when options.fields
};

// Diametral point load P = `load` (N, > 0 compresses) on a disc of thickness `thickness` (m), homogeneous TI
// material with the bedding at bedding_deg. Throws std::invalid_argument for inputs a user can get wrong: an empty
// mesh, a triangle that is clockwise, degenerate or refers to a missing node, a mesh that is not a disc with nodes
// at the top and bottom of its vertical diameter, non-admissible constants, a non-finite bedding angle, a
// non-positive or non-finite load or thickness, degree other than 1 or 2, a negative average_radius or one that
// holds no cell centroid. Throws std::runtime_error when CG does not converge, or when a statically determinate set
// of pins shows a reaction above 1e-6 P (an internal check: it is 0 by statics).
// The CG + AMG stage initialises MPI when nobody has (Trilinos needs it) and runs one at a time with the CG + AMG
// stages of every model of continuum/; the direct solver needs no MPI.
DiscResult solve_disc(const TriMesh& mesh, const theory::TIConstants& c, double bedding_deg, theory::Plane plane,
                      double load, double thickness, const DiscOptions& options = {});

}  // namespace rbdem::continuum
