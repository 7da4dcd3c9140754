// The FE twin with joints: deal.II linear elasticity on the DEM's TriMesh in which the joints are discrete
// zero-thickness interfaces instead of being smeared into a homogenized TI continuum (continuum/fe_model.hpp).
// Owns: splitting the mesh along the interface edges, the interface element, the per-layer material, the glued
// (infinitely stiff) interfaces as constraints, and the platen loading and apparent modulus of fe_model.hpp.
// This header is deal.II-free (plain C++17) so that callers do not pay deal.II's compile cost. P1 elements only
// (FE_SimplexP(1): constant strain triangles); there is no P2 variant.
//
// Split. A node's incident triangles are grouped into classes connected through mesh edges that are NOT interfaces;
// every class gets its own copy of the node. A node inside a through-going joint gets 2 copies, the tip of a joint
// that ends inside the specimen keeps 1 (its fan is connected around the tip), the crossing of two joints gets 4.
//
// Material. Triangle t of layer l = mesh.layer[t] has the plane stiffness C_l = S_l^-1 (Pa) with S_l =
// theory::rotated_compliance(theory::reduced_compliance(layer_constants[l], plane), bedding_deg): the same bedding
// rotation for every layer. Each triangle is a constant strain triangle: K_e = A B^T C_l B (per unit thickness).
//
// Interface element on an edge of length L (m) between the copies (side 1, side 2) of its nodes p, q:
//   jump [u](xi) = (1 - xi) [u]_p + xi [u]_q,  [u]_i = u_i(side 2) - u_i(side 1)   (m, linear along the edge)
//   traction t = K [u] (Pa),  K = k_n n n^T + k_s s s^T,  n the edge normal, s the tangent, k_n, k_s in Pa/m
//   energy per unit thickness = 1/2 int_0^L [u]^T K [u] dl, integrated exactly:
//   K_e(8 x 8) = sign_side sign_side' L M_pq K,  M = [[1/3, 1/6], [1/6, 1/3]],  sign(side 1) = -1, sign(side 2) = +1.
// The consistent M (not a lumped diagonal) makes the element exact for linear jumps, so a uniform traction is
// reproduced exactly. An infinitely stiff (glued) interface ties the copies of its two nodes together with
// AffineConstraints (u of every copy = u of one representative copy) rather than a penalty: k = 1e6 E/s already
// costs ~5e-9 of E in round-off with UMFPACK. Glued interfaces on every split edge reproduce solve_elastic to
// round-off.
//
// Platens and modulus exactly as fe_model.hpp (docs/continuum.md): specimen = bounding box [xmin, xmax] x
// [ymin, ymax], W, H; every copy keeps the boundary position of its node (tolerance 1e-6 max(W, H)):
//   frictionless: top u_y = -delta, bottom u_y = 0, one u_x = 0 pin at the bottom-left node (one copy of it).
//   bonded:       top u = (0, -delta), bottom u = (0, 0).
// F_top, F_bottom (N, compression positive) = thickness x the sum over the platen u_y rows of the unconstrained
// residual K u (no body force), E_app = (F_top / (W t)) / (delta / H) (Pa).
//
// Closed forms it meets (tests/test_fe_joints.cpp), frictionless platens: one joint normal to the load adds its
// compliance, H / E_app = H / E_r + 1 / k_n (plane stress; E_r / (1 - nu^2) in plane strain), to round-off; a
// joint set at spacing s tends to theory::goodman, exactly at dips 0 and 90 (uniform stress), with an error first
// order in s / W at 45 (the blocks cut by the free sides).
//
// Units: SI (m, Pa, Pa/m, N). Forces are for the given out-of-plane thickness t; the model is solved per unit
// thickness.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "continuum/fe_model.hpp"
#include "mesh/trimesh.hpp"
#include "theory/elasticity.hpp"

namespace rbdem::continuum {

// One mesh edge on a joint. Its two triangles usually lie in different layers (layer_interface_edges lists those),
// but that is not required: a joint ending inside a layer is a chain of interface edges inside one layer id.
struct InterfaceEdge {
  int node_a = 0, node_b = 0;  // mesh node indices of the edge (either order)
  double k_n = 0, k_s = 0;     // Pa/m, normal and shear stiffness per unit area; both +inf = glued (tied copies).
                               // Both must be > 0: a cut joint with k_s = 0 leaves blocks free to slide.
};

struct JointedFeOptions {
  Platens platens = Platens::frictionless;
  theory::Plane plane = theory::Plane::strain;
  double platen_displacement = 1e-5;  // m, downward displacement of the top platen (> 0 = compression)
  Solver solver = Solver::automatic;  // automatic: UMFPACK below direct_dof_limit DoFs, CG+AMG from there
  bool fields = true;                 // fill the centroid fields
  std::size_t direct_dof_limit = 20000;  // as FeOptions::direct_dof_limit
  // CG stops at |r| <= cg_tolerance |b|. Soft joints (k_n s << E) slow CG down: the AMG near null space holds
  // the rigid modes of the whole specimen, not of each block.
  double cg_tolerance = 1e-8;
  // Uniform refinement levels before the solve (refine_jointed_mesh): each triangle split into 4^refinement, each
  // interface edge into 2^refinement with the same k_n, k_s; fields are returned per triangle of the given mesh
  // (the mean over its children, i.e. the mean displacement and stress of the triangle). Constant strain triangles
  // are too stiff in bending: a layer bent between soft joints, 10 triangles thick, is 0.5 % too stiff unrefined and
  // 0.1 % with one level (docs/continuum.md, "The model with the joints").
  int refinement = 0;
};

struct JointedFeResult {
  double apparent_modulus = 0;             // Pa: (F_top / (W t)) / (platen_displacement / H)
  double top_force = 0, bottom_force = 0;  // N, compression positive, for thickness t
  std::size_t dofs = 0, cells = 0;   // of the solved (refined) mesh
  std::size_t interface_edges = 0;   // interface elements + glued edges (= interfaces.size(), of the given mesh)
  std::size_t glued_edges = 0;       // of which infinitely stiff (constraints)
  std::size_t duplicated_nodes = 0;  // extra vertices the split made: sum over nodes of (copies - 1)
  std::size_t constrained_dofs = 0;  // platen values, the pin, and the ties of glued copies
  unsigned iterations = 0;           // CG iterations (0 for the direct solver)
  Solver solver_used = Solver::automatic;
  double seconds = 0;  // wall time of the whole call
  double setup_seconds = 0, assemble_seconds = 0, solve_seconds = 0, fields_seconds = 0;  // its stages
  std::vector<double> ux, uy;         // m, displacement at each triangle's centroid (order of mesh.triangles)
  std::vector<double> sxx, syy, sxy;  // Pa, tension positive, stress at each triangle's centroid
  // Per given interface (the order of `interfaces`): the mean normal jump over the edge, (m), positive when its two
  // sides separate, 0 for a glued edge; with refinement the mean over the edge's pieces. Always filled: a caller
  // that models a joint which carries less in tension than in compression iterates on its sign
  // (compare/gate: the unilateral joints of the DEM's linear parts).
  std::vector<double> interface_opening;
};

// layer_constants[l]: the elastic constants of layer l (isotropic via TIConstants::isotropic, or transversely
// isotropic), with its bedding trace at bedding_deg from x (the same rotation for every layer). Its size must be
// the number of layers, max(mesh.num_layers(), largest layer id + 1); an empty mesh.layer means one layer 0.
// Throws std::invalid_argument naming the input for everything a user can get wrong: an empty, clockwise or
// out-of-range mesh, a wrong layer_constants size, non-admissible constants, an interface that is not an interior
// mesh edge or is listed twice, a stiffness that is not > 0 or only half infinite, non-positive thickness or
// displacement. MPI: as solve_elastic (initialised on the first CG+AMG call when nobody did; the CG+AMG stages of
// solve_elastic_jointed, solve_elastic and solve_disc run one at a time).
JointedFeResult solve_elastic_jointed(const TriMesh& mesh, const std::vector<theory::TIConstants>& layer_constants,
                                      double bedding_deg, const std::vector<InterfaceEdge>& interfaces,
                                      double thickness, const JointedFeOptions& options = {});

// The edges of a mesh whose two triangles have different layer ids, each as (smaller node, larger node), sorted:
// a deterministic order for callers that assign k_n, k_s per edge.
std::vector<std::pair<int, int>> layer_interface_edges(const TriMesh& mesh);

// Uniform refinement of a jointed mesh (deal.II-free, continuum/fe_joints_mesh.cpp): every triangle t split at its
// edge midpoints into the children 4t .. 4t+3 (three corners, then the middle one; counter-clockwise, layer of the
// parent), repeated `levels` times, and every interface edge into its two halves with the same k_n, k_s. New nodes
// are appended after the given ones. Throws std::invalid_argument for an interface that is not a mesh edge.
struct RefinedJointedMesh {
  TriMesh mesh;
  std::vector<InterfaceEdge> interfaces;
  std::size_t children = 1;  // triangles per parent: 4^levels, children of parent t are t * children ...
};
RefinedJointedMesh refine_jointed_mesh(const TriMesh& mesh, const std::vector<InterfaceEdge>& interfaces, int levels);

// The mean of each consecutive group of `children` values (children of a parent have equal areas).
std::vector<double> parent_means(const std::vector<double>& child_values, std::size_t children);

// How many copies of each mesh node the split along `interfaces` makes (1 = not split, 0 = used by no triangle).
// The split solve_elastic_jointed uses; throws as it does for bad interfaces.
std::vector<int> count_node_copies(const TriMesh& mesh, const std::vector<InterfaceEdge>& interfaces);

}  // namespace rbdem::continuum
