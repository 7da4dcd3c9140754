// Specimen geometry and meshing through the gmsh C++ API.
//
// The specimen is the W x H rectangle [0, W] x [0, H], or the disc of diameter D inscribed in [0, D] x [0, D] (with
// mesh nodes at its top and bottom points, where the platens of the Brazilian test touch it), cut by one or
// two sets of parallel joints (JointSetGeometry). gmsh meshes it so that every joint is a chain of mesh edges (the
// physical curve groups "joint_set" and "joint_set2", read back as TriMesh::interfaces) and every region between
// through-going joints is its own physical surface group (a layer). User meshes are read from .msh files (physical
// surfaces = layers, physical curves = interfaces).
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "dem/scene.hpp"
#include "mesh/trimesh.hpp"

namespace rbdem {

// One set of parallel joints: dip beta from the horizontal, spacing s along the normal n = (-sin beta, cos beta),
// one joint through the specimen centre when the offset is 0; below persistence 1 each joint is a row of pieces
// joint_length long separated by rock bridges, shifted by `stagger` periods from one joint to the next.
struct JointSetGeometry {
  double dip_deg = 60.0, spacing = 0.01, offset = 0.0;  // deg, m, m
  double persistence = 1.0, joint_length = 0.02, stagger = 0.5;  // -, m, -
  // Unit vectors along the joints and along their normal; exact at 0 and 90 degrees.
  std::array<double, 2> direction() const;
  std::array<double, 2> normal() const;
};

struct SpecimenGeometry {
  double width = 0.05, height = 0.10;            // m (a disc: width = height = its diameter)
  double dip_deg = 60.0, spacing = 0.01, offset = 0.0;  // deg, m, m: the first joint set
  double persistence = 1.0, joint_length = 0.02, stagger = 0.5;  // -, m, -: the first joint set
  bool joints = true;                            // the first set is there
  bool second_set = false;                       // the second set is there
  JointSetGeometry set2;                         // the second set (its dip already resolved when it follows set 1)
  bool disc = false;                             // the disc inscribed in the width x height box
  double contact_arc_deg = 0.0;                  // a disc's flattened ends subtend 2 alpha (0: a full disc)
  int mesh_seed = 0;                             // mesh realization (mesh.seed); 0 = the unperturbed mesh
  bool structured = false;                       // a structured grid of equal right triangles (mesh.structured)

  static SpecimenGeometry from_scene(const Scene& scene);
  // The first set's unit vectors along the joints and along their normal; exact at 0 and 90 degrees.
  std::array<double, 2> direction() const;
  std::array<double, 2> normal() const;
  // Set k (0: the first, 1: the second) as a JointSetGeometry.
  JointSetGeometry set(int k) const;
};

// The names of the physical curve groups that hold the joints of a generated specimen, set by set.
inline constexpr std::array<const char*, 2> joint_set_group{"joint_set", "joint_set2"};

struct JointSegment {
  std::array<double, 2> a, b;  // end points (on the specimen boundary for through-going joints), m
  double r;                    // signed normal distance of the joint from the specimen centre, m
  int set = 0;                 // 0: the first set, 1: the second
  bool a_on_boundary = true, b_on_boundary = true;  // an end on the specimen boundary (else inside: a rock bridge)
  double length() const;
};

// The joint segments inside the specimen, the first set's then the second's. Joints that only touch a corner (or
// the rim of a disc) or lie on a side are left out; a joint that would cut off a corner (or rim) piece thinner than
// `min_piece` is left out too and noted in `notes`. Joints of a set with persistence < 1 come as their pieces;
// pieces that the boundary cuts shorter than `min_piece` are left out.
std::vector<JointSegment> joint_segments(const SpecimenGeometry& g, double min_piece = 0.0,
                                         std::vector<std::string>* notes = nullptr);

// Meshes the specimen with target edge length h. Throws SceneError when a layer is narrower than about two
// elements. When `msh_out` is not empty the mesh is also written there (gmsh MSH 4.1).
//
// Realizations (g.mesh_seed != 0): gmsh's Delaunay mesher fills the interior deterministically from the nodes on
// the curves (sides and joints), and Mesh.RandomSeed does not change a jointed specimen's mesh in gmsh 4.8. A
// nonzero seed therefore grades the nodes of every curve by a seeded geometric progression: each curve keeps the
// number of segments gmsh gives it at size h, and its spacing varies by at most +-2.5 % about the mean L / n. That
// moves nearly every node of the curves, and the mesher then lays a different interior of the same size and
// quality. The same seed gives the same mesh, bit for bit; seed 0 is the mesh without any grading.
//
// Structured (g.structured, mesh.structured): each piece of the rectangle between its horizontal joints is a
// transfinite grid of round(W / h) columns and round(H_piece / h) rows, every cell split into two right triangles.
// Every triangle on a joint then has its centroid a third of its row's height from the joint, so every joint bond
// has the same centroid distance d and the same stiffness E*/d (a direct shear test's joint breaks all at once, at
// the envelope). SceneError unless the specimen is a rectangle whose joints (if any) are one horizontal set of
// through-going joints and mesh.seed = 0.
TriMesh mesh_specimen(const SpecimenGeometry& g, double h, const std::filesystem::path& msh_out = {});

// Reads a user mesh: one physical surface group per layer, first-order triangles only, planar (z = 0), no volume
// elements. Refuses (SceneError naming the file and the fix) anything that is not a .msh file and every mesh that
// check_user_mesh refuses. Clockwise triangles are turned counter-clockwise and noted in TriMesh::notes.
TriMesh read_msh(const std::filesystem::path& path);

// The checks on an imported mesh, after gmsh: at least one triangle, finite coordinates, no zero-area triangle,
// no two nodes at one place, no node inside another triangle's free edge (T-junction: a non-conforming mesh).
// Turns clockwise triangles counter-clockwise. `source` names the mesh in messages.
void check_user_mesh(TriMesh& mesh, const std::string& source);

// The mesh a scene asks for: mesh.file when set, else the meshed specimen.
TriMesh make_mesh(const Scene& scene, const std::filesystem::path& msh_out = {});

}  // namespace rbdem
