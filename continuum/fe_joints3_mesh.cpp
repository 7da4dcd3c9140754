// The deal.II-free part of the 3D FE model with the joints (continuum/fe_joints3.hpp): the checks of the mesh and
// the interfaces, the split of the mesh into node copies, and the helpers of the front library (joint_interfaces,
// count_node_copies3). Plain C++ (no deal.II headers), compiled into both the module and the front library.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "common/union_find.hpp"
#include "continuum/fe_joints3.hpp"
#include "continuum/fe_joints3_split.hpp"

namespace rbdem::continuum {

namespace {

[[noreturn]] void fail(const char* function, const std::string& what) {
  throw std::invalid_argument(std::string(function) + ": " + what);
}

std::string text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}


void check_mesh(const char* function, const TetMesh& mesh) {
  if (mesh.tets.empty() || mesh.nodes.empty())
    fail(function, "the mesh has no tetrahedra; mesh the specimen first (rbdem::mesh_specimen3)");
  if (!mesh.layer.empty() && mesh.layer.size() != mesh.tets.size())
    fail(function, "mesh.layer has " + std::to_string(mesh.layer.size()) + " entries but the mesh has " +
                       std::to_string(mesh.tets.size()) + " tetrahedra; give one layer id per tetrahedron (or none)");
  const int n = int(mesh.nodes.size());
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    for (int v : mesh.tets[t])
      if (v < 0 || v >= n)
        fail(function, "tetrahedron " + std::to_string(t) + " refers to node " + std::to_string(v) +
                           " but the mesh has " + std::to_string(n) + " nodes");
    if (!(tet_volume(mesh, t) > 0))
      fail(function, "tetrahedron " + std::to_string(t) + " has a non-positive volume; order its nodes so that "
                     "det(b - a, c - a, d - a) > 0 (rbdem::mesh_specimen3 does)");
    if (!mesh.layer.empty() && mesh.layer[t] < 0)
      fail(function, "tetrahedron " + std::to_string(t) + " has the negative layer id " +
                         std::to_string(mesh.layer[t]));
  }
}

int position_in(const TetMesh& mesh, int tet, int node) {
  const auto& v = mesh.tets[std::size_t(tet)];
  return int(std::find(v.begin(), v.end(), node) - v.begin());
}

// Which shared face each interface is (checked): marks[f] = interface index or -1.
std::vector<int> mark_interfaces(const char* function, const TetMesh& mesh, const std::vector<SharedFace>& faces,
                                 const std::vector<InterfaceFace>& interfaces) {
  std::unordered_map<std::uint64_t, int> face_of;
  face_of.reserve(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f)
    face_of.emplace(unordered_pair_key(faces[f].tets[0], faces[f].tets[1]), int(f));
  std::vector<int> marks(faces.size(), -1);
  const int n = int(mesh.tets.size());
  for (std::size_t k = 0; k < interfaces.size(); ++k) {
    const InterfaceFace& g = interfaces[k];
    const std::string name = "interfaces[" + std::to_string(k) + "] = tetrahedra (" + std::to_string(g.tet_a) +
                             ", " + std::to_string(g.tet_b) + ")";
    if (g.tet_a < 0 || g.tet_a >= n || g.tet_b < 0 || g.tet_b >= n)
      fail(function, name + " refers to a tetrahedron outside 0 .. " + std::to_string(n - 1));
    const auto it = face_of.find(unordered_pair_key(g.tet_a, g.tet_b));
    if (g.tet_a == g.tet_b || it == face_of.end())
      fail(function, name + " is not a face of the mesh: the two tetrahedra share no face; joints must follow "
                            "mesh faces (mesh the joint planes into the specimen; joint_interfaces lists them)");
    if (marks[std::size_t(it->second)] >= 0)
      fail(function, name + " is the same face as interfaces[" + std::to_string(marks[std::size_t(it->second)]) +
                         "]; list each interface face once");
    const bool glued_n = std::isinf(g.k_n) && g.k_n > 0, glued_s = std::isinf(g.k_s) && g.k_s > 0;
    if (!(g.k_n > 0) || !(g.k_s > 0))
      fail(function, name + " has k_n = " + text(g.k_n) + " Pa/m, k_s = " + text(g.k_s) +
                         " Pa/m; both stiffnesses must be > 0 (+inf for a glued face)");
    if (glued_n != glued_s)
      fail(function, name + " has k_n = " + text(g.k_n) + " Pa/m, k_s = " + text(g.k_s) +
                         " Pa/m; give both infinite (glued) or both finite (a large finite value acts as a penalty)");
    marks[std::size_t(it->second)] = int(k);
  }
  return marks;
}

// The geometry of interface k on shared face f, its copies read from the split.
internal::InterfaceElement3 element_of(const TetMesh& mesh, const SharedFace& f, const InterfaceFace& g,
                                       const std::vector<unsigned>& corner_copy) {
  internal::InterfaceElement3 e;
  e.nodes = f.nodes;
  const auto &a = mesh.nodes[std::size_t(f.nodes[0])], &b = mesh.nodes[std::size_t(f.nodes[1])],
             &c = mesh.nodes[std::size_t(f.nodes[2])];
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double cross[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  const double norm = std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
  e.area = 0.5 * norm;
  const double sign = f.tets[0] == g.tet_a ? 1.0 : -1.0;  // SharedFace's normal points from tets[0] into tets[1]
  for (int i = 0; i < 3; ++i) e.normal[std::size_t(i)] = sign * cross[i] / norm;
  for (int side = 0; side < 2; ++side) {
    const int tet = side == 0 ? g.tet_a : g.tet_b;
    for (int i = 0; i < 3; ++i)
      e.copy[std::size_t(side)][std::size_t(i)] =
          corner_copy[4 * std::size_t(tet) + std::size_t(position_in(mesh, tet, f.nodes[std::size_t(i)]))];
  }
  e.k_n = g.k_n, e.k_s = g.k_s;
  e.glued = std::isinf(g.k_n);
  return e;
}

}  // namespace

namespace internal {

Split3 split_tet_mesh(const char* function, const TetMesh& mesh, const std::vector<InterfaceFace>& interfaces) {
  check_mesh(function, mesh);
  const std::vector<SharedFace> faces = shared_faces(mesh);
  const std::vector<int> marks = mark_interfaces(function, mesh, faces, interfaces);
  const std::size_t n_corners = 4 * mesh.tets.size();
  UnionFind corners(n_corners);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    if (marks[f] >= 0) continue;
    const auto [t0, t1] = faces[f].tets;
    for (int node : faces[f].nodes)
      corners.unite(unsigned(4 * t0 + position_in(mesh, t0, node)), unsigned(4 * t1 + position_in(mesh, t1, node)));
  }
  Split3 s;
  constexpr unsigned none = std::numeric_limits<unsigned>::max();
  s.corner_copy.assign(n_corners, none);
  s.copies_per_node.assign(mesh.nodes.size(), 0);
  std::vector<unsigned> copy_of_root(n_corners, none);
  for (std::size_t c = 0; c < n_corners; ++c) {
    const unsigned root = corners.find(unsigned(c));
    if (copy_of_root[root] == none) {
      const int node = mesh.tets[c / 4][c % 4];
      copy_of_root[root] = unsigned(s.copy_node.size());
      s.copy_node.push_back(node);
      ++s.copies_per_node[std::size_t(node)];
    }
    s.corner_copy[c] = copy_of_root[root];
  }
  s.interfaces.resize(interfaces.size());
  for (std::size_t f = 0; f < faces.size(); ++f)
    if (marks[f] >= 0)
      s.interfaces[std::size_t(marks[f])] = element_of(mesh, faces[f], interfaces[std::size_t(marks[f])], s.corner_copy);
  return s;
}

}  // namespace internal

std::vector<InterfaceFace> joint_interfaces(const TetMesh& mesh, double k_n, double k_s, int set) {
  if (set < -1 || set > 1)
    fail("joint_interfaces", "set = " + std::to_string(set) + "; give 0 (the first joint set), 1 (the second) or -1 "
                             "(all joint faces)");
  check_mesh("joint_interfaces", mesh);
  std::vector<InterfaceFace> out;
  for (const SharedFace& f : shared_faces(mesh))
    if (f.joint && (set < 0 || f.set == set)) out.push_back({f.tets[0], f.tets[1], k_n, k_s});
  return out;
}

std::vector<int> count_node_copies3(const TetMesh& mesh, const std::vector<InterfaceFace>& interfaces) {
  return internal::split_tet_mesh("count_node_copies3", mesh, interfaces).copies_per_node;
}

}  // namespace rbdem::continuum
