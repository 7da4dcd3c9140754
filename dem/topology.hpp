// Blocks and bonds from a TriMesh: one rigid block per triangle, one bond per interior edge.
//
// Block: centroid, area, mass = rho t A, polar moment of inertia about the centroid
//        I = m (|p0|^2 + |p1|^2 + |p2|^2) / 12 with p_k the vertices relative to the centroid.
// Bond:  the two blocks i < j, the shared edge (midpoint, length L, end nodes), the unit normal n from i to j
//        (perpendicular to the edge), the lever arms midpoint - centroid, and the centroid distance measured
//        along the normal, d = n . (c_j - c_i). With k_n = E*/d a uniform normal strain eps across the edge gives
//        the normal stress E* eps, so E* is the modulus of the chain of blocks and bonds along n.
//        kind = joint when the two triangles lie in different layers or the edge lies on one of the mesh's
//        interfaces (a physical curve group: the joints of a generated set, or a curve drawn in a user mesh, which
//        may end inside a layer), rock otherwise; `interface` is the index of that interface in
//        TriMesh::interfaces (the first one that holds the edge), -1 for none.
// Boundary: every edge with one triangle, tagged bottom / right / top / left by the specimen's bounding box, with
//        its midpoint (where a platen touches a block that has this edge on it).
// CSR adjacency: the bonds of block b are bond_of[bond_offset[b] .. bond_offset[b+1]).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "dem/dim.hpp"
#include "dem/records.hpp"
#include "mesh/trimesh.hpp"

namespace rbdem {

enum class Side : std::uint8_t { bottom = 0, right = 1, top = 2, left = 3, other = 4 };

template <int dim>
struct Topology;

// The topology of a triangle mesh.
template <>
struct Topology<2> {
  struct BlockGeometry {
    std::vector<double> cx, cy;          // centroid, m
    std::vector<double> area;            // m^2
    std::vector<double> mass;            // kg (density x thickness x area)
    std::vector<double> inertia;         // kg m^2, polar, about the centroid
    std::vector<double> radius;          // m, largest centroid-to-vertex distance (bounding circle)
    std::vector<std::array<double, 6>> shape;  // vertices relative to the centroid, counter-clockwise (x0,y0,...)
    std::vector<int> layer;
    std::size_t size() const { return cx.size(); }
  };

  struct BondGeometry {
    std::vector<int> i, j;               // blocks, i < j
    std::vector<int> node_a, node_b;     // mesh nodes of the shared edge
    std::vector<double> mx, my;          // edge midpoint, m
    std::vector<double> length;          // L, m
    std::vector<double> nx, ny;          // unit normal from block i to block j
    std::vector<double> d;               // centroid distance along the normal, m
    std::vector<BondKind> kind;
    std::vector<int> interface;          // index into Topology::interface_names, -1 for none
    std::size_t size() const { return i.size(); }
  };

  struct BoundaryEdges {
    std::vector<int> block;
    std::vector<int> node_a, node_b;     // in the block's counter-clockwise order: the outside is right of a -> b
    std::vector<double> ax, ay, bx, by;  // their coordinates, m
    std::vector<double> mx, my;          // edge midpoint, m (the contact point of a platen on this edge)
    std::vector<double> length;
    std::vector<Side> side;
    std::size_t size() const { return block.size(); }
  };

  BlockGeometry blocks;
  BondGeometry bonds;
  BoundaryEdges boundary;
  std::vector<int> bond_offset, bond_of;  // CSR: bonds of each block
  double xmin = 0, xmax = 0, ymin = 0, ymax = 0;  // specimen bounding box, m
  double thickness = 1.0;                          // m
  std::vector<std::string> layer_names;            // the mesh's layer (physical surface) names, by layer id
  std::vector<std::string> interface_names;        // the mesh's interface (physical curve) names

  double width() const { return xmax - xmin; }
  double height() const { return ymax - ymin; }
  std::size_t count(BondKind k) const;
  double total_length(BondKind k) const;
};

// Builds blocks, bonds, boundary tags and adjacency. Throws SceneError when an edge has more than two triangles
// or a triangle is degenerate. Free edges off the bounding box (holes, curved sides) are tagged Side::other.
Topology<2> build_topology(const TriMesh& mesh, double thickness, double density);

}  // namespace rbdem
