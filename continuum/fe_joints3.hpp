// The 3D FE twin with joints: deal.II linear elasticity on the 3D DEM's TetMesh in which the joints are discrete
// zero-thickness interfaces instead of being smeared into the homogenized TI continuum of fe_3d.hpp. The 3D
// counterpart of fe_joints.hpp, built the same way. Owns: splitting the mesh along the interface faces, the
// triangular interface element, the per-layer material, the glued (infinitely stiff) interfaces as constraints, and
// the platens and moduli of fe_3d.hpp. This header is deal.II-free (plain C++) so that callers do not pay deal.II's
// compile cost. P1 elements only (FE_SimplexP<3>(1): constant strain tetrahedra); degree 2 is refused (its
// interface element would need the six-node triangle).
//
// Split. A node's incident tetrahedra are grouped into classes connected through mesh faces that are NOT
// interfaces; every class gets its own copy of the node. A node inside a through-going joint plane gets 2 copies;
// a node on the edge of a joint that ends inside the specimen keeps 1 (its star is connected around the tip line);
// a node on the line where two joint planes cross gets 4 (more where more planes meet). The split is deal.II-free
// (fe_joints3_mesh.cpp): count_node_copies3 reports it.
//
// Material. Tetrahedron t of layer l = mesh.layer[t] has the stiffness C_l = S_l^-1 with S_l =
// theory::rotated_compliance(layer_constants[l], dip, dip direction): its plane of isotropy along the joint planes,
// the same rotation for every layer, exactly as solve_elastic_3d.
//
// Interface element on a triangle of area A (m^2) between the copies (side 1 = InterfaceFace::tet_a's, side 2 =
// tet_b's) of its three nodes:
//   jump [u](x) = sum_i N_i(x) [u]_i,  [u]_i = u_i(side 2) - u_i(side 1)   (m, linear over the triangle)
//   traction t = K [u] (Pa),  K = k_n n n^T + k_s (I - n n^T),  n the face's unit normal, k_n, k_s in Pa/m
//   energy = 1/2 int [u]^T K [u] dA, integrated exactly with the consistent triangle mass matrix
//   M_ij = int N_i N_j dA = A/12 (1 + delta_ij):  K_e(18 x 18) = sign_side sign_side' M_ij K,  sign(side 1) = -1.
// The consistent M (not a lumped diagonal) makes the element exact for linear jumps, so a uniform traction is
// reproduced exactly. An infinitely stiff (glued) interface ties the copies of its three nodes together with
// AffineConstraints (u of every copy = u of one representative copy) rather than a penalty, so glued interfaces on
// every joint face reproduce solve_elastic_3d to round-off.
//
// Platens exactly as fe_3d.hpp: the specimen stands on z = zmin, its top at z = zmax; every copy keeps the
// boundary position of its node (tolerance 1e-6 of the largest extent):
//   frictionless: top u_z = -delta, bottom u_z = 0; the rigid horizontal motions pinned on one copy each: u_x, u_y
//                 at the bottom node with the least x (ties by y), u_y at the bottom node with the greatest x.
//   bonded:       top u = (0, 0, -delta), bottom u = 0.
//
// Moduli. F H = int sigma_zz dV still holds (the displacement z e_z is continuous, so the interfaces do no work in
// it): apparent_modulus = <sigma_zz> / (delta / H) with <sigma_zz> = F H / V as in fe_3d.hpp. The mean strain is
// the jointed body's: the cells' strains plus the interfaces' jumps, <eps> = (1/V) (int eps dV + int sym([u] (x) n)
// dA), which by Gauss is (1/V) int sym(u (x) n) dA over the outer surface; so mean_strain_modulus = <sigma_zz> /
// <eps_zz> and the lateral strains include the joints' closing and sliding, and between frictionless platens (whose
// mean stress is exactly uniaxial) they are the jointed body's effective compliance's.
//
// Closed forms it meets (tests/test_fe_joints3.cpp): glued interfaces = solve_elastic_3d to round-off; horizontal
// joints on a prism (Goodman's series model) H / E_app = H / E_r + n / k_n to round-off, vertical joints change
// nothing, also where the two sets cross; a joint set at 45 deg tends to theory::goodman's TI medium as s / W
// falls; stiff joints in isotropic rock tend to the unjointed solution.
//
// Units: SI (m, Pa, Pa/m, N).
#pragma once

#include <cstddef>
#include <vector>

#include "continuum/fe_3d.hpp"
#include "mesh/tetmesh.hpp"
#include "theory/elasticity3.hpp"

namespace rbdem::continuum {

// One mesh face on a joint: the face the two tetrahedra share. Their layers usually differ (joint_interfaces lists
// those faces), but that is not required: a joint ending inside a layer is a set of interface faces inside one
// layer id.
struct InterfaceFace {
  int tet_a = 0, tet_b = 0;  // the two tetrahedra (either order; side 1 is tet_a's)
  double k_n = 0, k_s = 0;   // Pa/m, normal and shear stiffness per unit area; both +inf = glued (tied copies).
                             // Both must be > 0: a cut joint with k_s = 0 leaves blocks free to slide.
};

// The jointed body's response: the fields of Fe3Result (fe_3d.hpp) with the mean strain including the joints'
// jumps (above), and the split's counts.
struct JointedFe3Result : Fe3Result {
  std::size_t interface_faces = 0;   // = interfaces.size(): interface elements + glued faces
  std::size_t glued_faces = 0;       // of which infinitely stiff (constraints)
  // Interface faces with no jump at all: every node keeps one copy on both sides (all three on the edge of the
  // joint: an isolated face, a joint strip one face wide). They are accepted and do nothing; a joint must be more
  // than one face across to open.
  std::size_t inert_faces = 0;
  std::size_t copies = 0;            // vertices after the split (the triangulation's)
  std::size_t duplicated_nodes = 0;  // copies - nodes used: the sum over nodes of (copies - 1)
  std::size_t constrained_dofs = 0;  // platen values, pins, and the ties of glued copies
  double seconds = 0;                // wall time of the whole call (setup + assemble + solve + post)
  // Per given interface (the order of `interfaces`): the mean normal jump over the face (m), positive when its two
  // sides separate, and the mean tangential jump's magnitude (m); 0 for a glued face.
  std::vector<double> interface_opening, interface_slip;
};

// layer_constants[l]: the elastic constants of layer l (isotropic via TIConstants::isotropic, or transversely
// isotropic), turned to planes of the given dip and dip direction (degrees; the same rotation for every layer). Its
// size must be the number of layers, max(mesh.num_layers(), largest layer id + 1); an empty mesh.layer means one
// layer 0. Options as solve_elastic_3d (degree must be 1). Throws std::invalid_argument naming the input for
// everything a user can get wrong: an empty or inverted mesh, a wrong layer_constants size, non-admissible
// constants, an interface whose tetrahedra do not share a face or which is listed twice, a stiffness that is not
// > 0 or only half infinite, degree 2, a non-positive displacement.
JointedFe3Result solve_elastic_3d_jointed(const TetMesh& mesh, const std::vector<theory::TIConstants>& layer_constants,
                                          double dip_deg, double dip_direction_deg,
                                          const std::vector<InterfaceFace>& interfaces,
                                          const Fe3Options& options = {});

// Deal.II-free helpers (fe_joints3_mesh.cpp).
// The faces of shared_faces(mesh) whose tetrahedra lie in different layers (the joints), in that order, each with
// the given k_n, k_s; set = 0 or 1 keeps only the faces of that joint set (SharedFace::set), -1 all of them.
std::vector<InterfaceFace> joint_interfaces(const TetMesh& mesh, double k_n, double k_s, int set = -1);
// How many copies of each mesh node the split along `interfaces` makes (1 = not split, 0 = used by no
// tetrahedron). The split solve_elastic_3d_jointed uses; throws as it does for bad interfaces.
std::vector<int> count_node_copies3(const TetMesh& mesh, const std::vector<InterfaceFace>& interfaces);

}  // namespace rbdem::continuum
