// TriMesh: the specimen's triangle mesh as plain data, with no dependency on gmsh, the DEM or deal.II. Both
// solvers read this very object (dem/topology.hpp builds blocks and bonds from it, continuum/ builds its
// triangulation from it), so "the DEM and the FE model use the same mesh" is literal. Triangles are stored
// counter-clockwise; dem/specimen_mesh.hpp makes and reads meshes with gmsh.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace rbdem {

// A named chain of mesh edges: a physical curve group of the mesh (the joints of a generated set, or whatever
// curves a user mesh names). Interior edges on an interface are joints (dem/topology.hpp).
struct MeshInterface {
  std::string name;
  std::vector<std::array<int, 2>> edges;  // node index pairs
};

struct TriMesh {
  std::vector<std::array<double, 2>> nodes;   // m
  std::vector<std::array<int, 3>> triangles;  // node indices, counter-clockwise
  std::vector<int> layer;                     // layer id per triangle (0 .. layer_names.size()-1)
  std::vector<std::string> layer_names;       // physical surface group name per layer
  std::vector<MeshInterface> interfaces;      // physical curve groups (joint chains); may be empty
  std::vector<std::string> notes;             // what the mesher adjusted (skipped slivers, snapped nodes)

  std::size_t num_nodes() const { return nodes.size(); }
  std::size_t num_triangles() const { return triangles.size(); }
  std::size_t num_layers() const { return layer_names.size(); }
};

// Signed area of triangle t (m^2, positive when counter-clockwise).
double signed_area(const TriMesh& mesh, std::size_t t);
// The signed area of every triangle, in triangle order.
std::vector<double> triangle_areas(const TriMesh& mesh);

}  // namespace rbdem
