// The split of a TetMesh along its interface faces (continuum/fe_joints3.hpp, "Split"), deal.II-free: shared by the
// deal.II solve (fe_joints3.cpp) and the front library's count_node_copies3 (fe_joints3_mesh.cpp). Internal to
// continuum/.
#pragma once

#include <array>
#include <vector>

#include "continuum/fe_joints3.hpp"

namespace rbdem::continuum::internal {

// One interface after the split: the copies of its three nodes on both sides, its geometry and stiffness.
struct InterfaceElement3 {
  std::array<std::array<unsigned, 3>, 2> copy{};  // copy[side][i]: node i's copy on side 1 (tet_a) / side 2 (tet_b)
  std::array<int, 3> nodes{};                      // the mesh nodes of the face
  std::array<double, 3> normal{};                  // unit normal, from side 1 (tet_a) into side 2 (tet_b)
  double area = 0;                                 // m^2
  double k_n = 0, k_s = 0;                         // Pa/m
  bool glued = false;
};

// Corners (4 t + i, the i-th node of tetrahedron t) grouped into classes connected through shared faces that are
// not interfaces: each class is one copy (vertex) of its node, numbered in the order of first appearance along the
// tetrahedra.
struct Split3 {
  std::vector<unsigned> corner_copy;  // corner -> copy
  std::vector<int> copy_node;         // copy -> mesh node
  std::vector<int> copies_per_node;   // mesh node -> number of copies
  std::vector<InterfaceElement3> interfaces;  // in the order of the given interfaces
};

// Checks the mesh (node indices, positive volumes, layer ids) and the interfaces, and splits. Throws
// std::invalid_argument starting with `function` and naming the input and the fix.
Split3 split_tet_mesh(const char* function, const TetMesh& mesh, const std::vector<InterfaceFace>& interfaces);

}  // namespace rbdem::continuum::internal
