// The deal.II-free part of the FE model with the joints (continuum/fe_joints.hpp): the uniform refinement of a
// jointed mesh, with its interfaces carried to the halves of their edges, and the map of the refined fields back to
// the parent triangles. Plain C++ (no deal.II headers), compiled once.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "continuum/fe_joints.hpp"

namespace rbdem::continuum {

namespace {

std::uint64_t edge_key(int a, int b) {
  return (std::uint64_t(std::uint32_t(std::min(a, b))) << 32) | std::uint32_t(std::max(a, b));
}

}  // namespace

RefinedJointedMesh refine_jointed_mesh(const TriMesh& mesh, const std::vector<InterfaceEdge>& interfaces, int levels) {
  if (levels < 0) throw std::invalid_argument("refine_jointed_mesh: levels = " + std::to_string(levels) + " < 0");
  RefinedJointedMesh out;
  out.mesh = mesh;
  out.interfaces = interfaces;
  out.children = 1;
  for (int level = 0; level < levels; ++level) {
    const TriMesh& m = out.mesh;
    TriMesh r;
    r.nodes = m.nodes;
    r.layer_names = m.layer_names;
    r.notes = m.notes;
    std::unordered_map<std::uint64_t, int> midpoint;
    midpoint.reserve(3 * m.triangles.size());
    auto mid = [&](int a, int b) {
      const auto [it, inserted] = midpoint.emplace(edge_key(a, b), int(r.nodes.size()));
      if (inserted)
        r.nodes.push_back({0.5 * (m.nodes[a][0] + m.nodes[b][0]), 0.5 * (m.nodes[a][1] + m.nodes[b][1])});
      return it->second;
    };
    r.triangles.reserve(4 * m.triangles.size());
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      const auto [v0, v1, v2] = m.triangles[t];
      const int m01 = mid(v0, v1), m12 = mid(v1, v2), m20 = mid(v2, v0);
      // Children 4t .. 4t+3: the three corners, then the middle one; all counter-clockwise like the parent.
      r.triangles.push_back({v0, m01, m20});
      r.triangles.push_back({m01, v1, m12});
      r.triangles.push_back({m20, m12, v2});
      r.triangles.push_back({m01, m12, m20});
      if (!m.layer.empty())
        for (int c = 0; c < 4; ++c) r.layer.push_back(m.layer[t]);
    }
    std::vector<InterfaceEdge> halves;
    halves.reserve(2 * out.interfaces.size());
    for (const InterfaceEdge& e : out.interfaces) {
      const auto it = midpoint.find(edge_key(e.node_a, e.node_b));
      if (it == midpoint.end())
        throw std::invalid_argument("refine_jointed_mesh: the interface (" + std::to_string(e.node_a) + ", " +
                                    std::to_string(e.node_b) + ") is not an edge of the mesh");
      halves.push_back({e.node_a, it->second, e.k_n, e.k_s});
      halves.push_back({it->second, e.node_b, e.k_n, e.k_s});
    }
    out.mesh = std::move(r);
    out.interfaces = std::move(halves);
    out.children *= 4;
  }
  return out;
}

std::vector<double> parent_means(const std::vector<double>& child_values, std::size_t children) {
  if (children == 0 || child_values.size() % children != 0)
    throw std::invalid_argument("parent_means: " + std::to_string(child_values.size()) +
                                " values are not a whole number of groups of " + std::to_string(children));
  std::vector<double> out(child_values.size() / children, 0.0);
  for (std::size_t k = 0; k < child_values.size(); ++k) out[k / children] += child_values[k] / double(children);
  return out;
}

}  // namespace rbdem::continuum
