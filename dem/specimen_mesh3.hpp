// The three-dimensional specimen and its tetrahedral mesh, made with gmsh (the OpenCASCADE kernel).
//
// The specimen is a cylinder of diameter D and height H standing on z = 0, its axis at x = y = D/2 (inscribed in
// the box [0, D] x [0, D] x [0, H]), a prism [0, W] x [0, B] x [0, H] (width along x, depth along y), or the
// Brazilian disc: a disc of diameter D and thickness t, its axis along y through (D/2, y, D/2) (inscribed in
// [0, D] x [0, t] x [0, D], so its x-z section is the 2D disc), flattened at the top and bottom over the contact
// arc 2 alpha (the flats at z = D/2 -+ (D/2) cos alpha, tagged bottom and top: the platens load them). One or two
// sets of parallel joint planes cut it: each set has a dip from the horizontal and a dip direction (0: the strike
// along the depth axis y, so the x-z section through the centre is the 2D specimen's slice through the dip; axes and
// normal as in theory/elasticity3.hpp), a spacing along its normal and an offset, one plane through the specimen's
// centre when the offset is 0, as in 2D. gmsh cuts the solid by the planes (occ::fragment), so the mesh conforms
// to every joint plane: each piece between planes is one layer (one physical volume), and a joint is a surface of
// mesh faces with a different layer on either side.
//
// A scene with specimen.dimension = 3 fills it (specimen_geometry3): specimen.shape, diameter, width, depth,
// height, thickness and contact_arc_deg, and each joint set's dip_deg, dip_direction_deg, spacing and offset.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "dem/scene.hpp"
#include "mesh/tetmesh.hpp"

namespace rbdem {

enum class Shape3 { cylinder, prism, disc };

struct JointPlaneSet {
  double dip_deg = 60.0, dip_direction_deg = 0.0;  // deg
  double spacing = 0.01, offset = 0.0;             // m, along the normal
  std::array<double, 3> normal() const;            // theory::plane_axes(dip, dip direction).normal
};

struct SpecimenGeometry3 {
  Shape3 shape = Shape3::cylinder;
  double diameter = 0.05;             // m, the cylinder
  double width = 0.05, depth = 0.05;  // m, the prism along x and y
  double height = 0.10;               // m, the cylinder and the prism
  double thickness = 0.025;           // m, the disc along y
  double contact_arc_deg = 10.0;      // deg, the disc's flats subtend 2 alpha at its centre (0: a full disc)
  bool joints = true;                 // the first set is there
  JointPlaneSet set1;
  bool second_set = false;  // the second set is there
  JointPlaneSet set2{30.0, 90.0, 0.01, 0.0};

  std::array<double, 3> centre() const;  // the centre of the specimen, m
  // Half the specimen's extent along the unit vector n (its support function about the centre), m.
  double half_extent(const std::array<double, 3>& n) const;
  double volume() const;  // of the ideal solid, m^3
};

// One joint plane: the points x with n . (x - centre) = r.
struct JointPlane {
  std::array<double, 3> normal;
  double r = 0;  // signed distance from the specimen's centre, m
  int set = 0;   // 0: the first set, 1: the second
};

// The planes that cut the specimen, the first set's then the second's: offset + k spacing for every k whose plane
// meets the solid. A plane that would cut off a cap thinner than `min_piece` (its distance to the solid's extreme
// point along n) is left out and noted in `notes`: its cap would be a handful of flat tetrahedra.
std::vector<JointPlane> joint_planes(const SpecimenGeometry3& g, double min_piece,
                                     std::vector<std::string>* notes = nullptr);

// Meshes the specimen with tetrahedra of target edge length h. Throws SceneError (naming the input and the fix) for
// non-positive or non-finite sizes and for a spacing that holds fewer than two elements. The mesh is the same for
// the same inputs, bit for bit (gmsh meshes on one thread). TetMesh::mesh_seconds holds the time gmsh took.
//
// Realizations (seed != 0, mesh.seed): as in 2D (mesh_specimen), the nodes of every curve of the cut solid (the
// rims of the ends, the cylinder's seam, the traces of the joint planes on the surface and on one another) are
// graded by a seeded geometric progression: each curve keeps the segment count gmsh gives it at size h, its spacing
// within +-2.5 % of the mean. gmsh's surface mesher then lays different triangles on every face and joint plane, and
// its Delaunay volume mesher different tetrahedra inside: a different mesh of the same solid, the same joint planes,
// the same size and quality. The same seed gives the same mesh, bit for bit; seed 0 is the mesh without grading.
TetMesh mesh_specimen3(const SpecimenGeometry3& g, double h, int seed = 0);

// The 3D specimen and joint sets of a scene (specimen.dimension = 3, validated): the shape and its sizes; the first
// set when joint_set.enabled; the second when joint_set2.enabled, at second_set_dip_deg (a dip above 90 deg is the
// same plane as 180 - dip at the opposite dip direction); dip directions modulo 360, in [0, 360). Throws SceneError
// for a scene that is not 3D.
SpecimenGeometry3 specimen_geometry3(const Scene& scene);
// A user mesh in 3D: a gmsh .msh file (any version gmsh reads) of first-order tetrahedra, one physical volume per
// layer (the layer names are the physical names; a face between two layers is a joint face). The specimen stands
// on its lowest z and is loaded at its highest (boundary_faces). Throws SceneError naming the file for a missing
// file, no physical volume, a volume in two physical volumes, other 3D elements, no tetrahedra or a degenerate one;
// tetrahedra of negative volume are turned (noted in TetMesh::notes).
TetMesh read_msh3(const std::filesystem::path& path);
// The scene's tetrahedral mesh: read_msh3(mesh.file) when the scene names one, else
// mesh_specimen3(specimen_geometry3(scene), mesh.size, mesh.seed).
TetMesh mesh_scene3(const Scene& scene);

}  // namespace rbdem
