// TetMesh: a three-dimensional specimen's tetrahedral mesh as plain data, with no dependency on gmsh, the DEM or
// deal.II; the 3D counterpart of TriMesh. The FE twin (continuum/fe_3d.hpp) builds its triangulation from this very
// object, and the 3D DEM will build one rigid block per tetrahedron and one bond per shared face from it.
// dem/specimen_mesh3.hpp makes it with gmsh.
//
// Conventions: z is the load axis, the specimen stands on z = zmin with its top at z = zmax. Every tetrahedron has
// a positive signed volume det(b - a, c - a, d - a) / 6 > 0 (deal.II's reference orientation). The layers are the
// pieces between the joint planes: one id per tetrahedron, and a face is a joint face exactly where the ids of its
// two tetrahedra differ (the mesher conforms to the planes, so every joint is a surface of mesh faces).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace rbdem {

enum class FaceTag : unsigned char { bottom, top, lateral };

// A face on the specimen's surface: its nodes ordered so that (b - a) x (c - a) points out of the specimen.
struct BoundaryFace {
  std::array<int, 3> nodes;
  int tet = 0;  // the tetrahedron it belongs to
  FaceTag tag = FaceTag::lateral;
};

struct TetMesh {
  std::vector<std::array<double, 3>> nodes;  // m
  std::vector<std::array<int, 4>> tets;      // node indices, positive volume
  std::vector<int> layer;                    // layer id per tetrahedron (0 .. layer_names.size()-1)
  std::vector<std::string> layer_names;      // one per layer, ordered along the first joint set's normal
  // Per layer (may be empty): how many planes of the first and of the second joint set lie below it along their
  // normals. Two layers that differ in the first count meet on a plane of the first set.
  std::vector<std::array<int, 2>> layer_rows;
  std::vector<BoundaryFace> boundary;        // the surface, each face tagged bottom, top or lateral
  std::vector<std::string> notes;            // what the mesher adjusted (planes left out, nodes snapped)
  double mesh_seconds = 0;                   // wall time gmsh took (geometry, fragment, mesh), s

  std::size_t num_nodes() const { return nodes.size(); }
  std::size_t num_tets() const { return tets.size(); }
  std::size_t num_layers() const { return layer_names.size(); }
};

// A face shared by two tetrahedra: where a bond of the 3D DEM sits. A joint face separates two layers.
struct SharedFace {
  std::array<int, 3> nodes;  // ordered so that (b - a) x (c - a) points from tets[0] into tets[1]
  std::array<int, 2> tets;
  bool joint = false;
  int set = -1;  // -1: rock (one layer); 0: a joint of the first set, 1: of the second (TetMesh::layer_rows)
};

// Signed volume of tetrahedron t, m^3 (positive in a valid mesh).
double tet_volume(const TetMesh& mesh, std::size_t t);
// Every face shared by two tetrahedra, in order of (tets[0], tets[1]). Throws std::invalid_argument when a face
// belongs to more than two tetrahedra (a broken mesh).
std::vector<SharedFace> shared_faces(const TetMesh& mesh);
// The faces of only one tetrahedron (the surface), outward, tagged by height: all three nodes within `tol` of the
// lowest z of the mesh is bottom, of the highest top, anything else lateral.
std::vector<BoundaryFace> boundary_faces(const TetMesh& mesh, double tol);

// Element quality. The minimum dihedral angle (between two faces along their common edge; 70.5 deg in the regular
// tetrahedron) falls to 0 in a sliver, whose volume vanishes though no edge is short; the radius ratio
// 3 r_in / r_circ is 1 in the regular tetrahedron and 0 in any degenerate one.
double min_dihedral_deg(const TetMesh& mesh, std::size_t t);
double radius_ratio(const TetMesh& mesh, std::size_t t);

// What a tetrahedral mesh holds: the counts a 3D DEM run costs by (blocks = tets, bonds = shared faces), its
// volume and its worst elements.
struct TetMeshReport {
  std::size_t nodes = 0, tets = 0, layers = 0;
  std::size_t rock_faces = 0, joint_faces = 0;          // shared faces inside a layer / across a joint
  std::size_t bottom_faces = 0, top_faces = 0, lateral_faces = 0;
  double volume = 0;                                    // m^3, sum of the tetrahedra
  double min_dihedral_deg = 0, min_radius_ratio = 0;    // over all tetrahedra
  std::size_t slivers = 0;                              // tetrahedra with a dihedral angle under sliver_deg
  double mesh_seconds = 0;                              // from TetMesh::mesh_seconds
};
inline constexpr double sliver_deg = 10.0;
TetMeshReport report(const TetMesh& mesh);

}  // namespace rbdem
