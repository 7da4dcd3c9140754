// Blocks, bonds, boundary edges and CSR adjacency from a TriMesh. See topology.hpp.
#include "dem/topology.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <fmt/format.h>

#include "dem/scene.hpp"

namespace rbdem {

std::size_t Topology<2>::count(BondKind k) const {
  return std::size_t(std::count(bonds.kind.begin(), bonds.kind.end(), k));
}

double Topology<2>::total_length(BondKind k) const {
  double s = 0;
  for (std::size_t b = 0; b < bonds.size(); ++b)
    if (bonds.kind[b] == k) s += bonds.length[b];
  return s;
}

Topology<2> build_topology(const TriMesh& mesh, double thickness, double density) {
  Topology<2> topo;
  topo.thickness = thickness;
  const std::size_t nt = mesh.triangles.size();
  auto& B = topo.blocks;
  B.cx.resize(nt), B.cy.resize(nt), B.area.resize(nt), B.mass.resize(nt), B.inertia.resize(nt);
  B.radius.resize(nt), B.shape.resize(nt), B.layer = mesh.layer;

  topo.xmin = topo.ymin = 1e300;
  topo.xmax = topo.ymax = -1e300;
  for (const auto& p : mesh.nodes) {
    topo.xmin = std::min(topo.xmin, p[0]), topo.xmax = std::max(topo.xmax, p[0]);
    topo.ymin = std::min(topo.ymin, p[1]), topo.ymax = std::max(topo.ymax, p[1]);
  }

  for (std::size_t t = 0; t < nt; ++t) {
    const auto& tri = mesh.triangles[t];
    const auto& a = mesh.nodes[tri[0]];
    const auto& b = mesh.nodes[tri[1]];
    const auto& c = mesh.nodes[tri[2]];
    const double cx = (a[0] + b[0] + c[0]) / 3.0, cy = (a[1] + b[1] + c[1]) / 3.0;
    const double area = signed_area(mesh, t);
    if (!(area > 0))
      throw SceneError(fmt::format("mesh triangle {} has non-positive area {:.3g} m^2 after orientation: the mesh is "
                                   "degenerate; remesh with a different mesh.size",
                                   t, area));
    B.cx[t] = cx, B.cy[t] = cy, B.area[t] = area;
    B.mass[t] = density * thickness * area;
    double r2sum = 0, rmax = 0;
    for (int v = 0; v < 3; ++v) {
      const auto& p = mesh.nodes[tri[v]];
      const double dx = p[0] - cx, dy = p[1] - cy;
      B.shape[t][2 * v] = dx, B.shape[t][2 * v + 1] = dy;
      r2sum += dx * dx + dy * dy;
      rmax = std::max(rmax, std::hypot(dx, dy));
    }
    B.inertia[t] = B.mass[t] * r2sum / 12.0;
    B.radius[t] = rmax;
  }

  // Edge -> the (at most two) triangles that hold it.
  struct EdgeUse {
    int t0 = -1, t1 = -1;
    int count = 0;
  };
  std::unordered_map<std::uint64_t, EdgeUse> edges;
  edges.reserve(3 * nt);
  auto key = [](int u, int v) {
    if (u > v) std::swap(u, v);
    return (std::uint64_t(std::uint32_t(u)) << 32) | std::uint32_t(v);
  };
  for (std::size_t t = 0; t < nt; ++t)
    for (int e = 0; e < 3; ++e) {
      auto& use = edges[key(mesh.triangles[t][e], mesh.triangles[t][(e + 1) % 3])];
      (use.count == 0 ? use.t0 : use.t1) = int(t);
      if (++use.count > 2)
        throw SceneError(fmt::format("mesh edge ({}, {}) is shared by more than two triangles: the mesh is not a "
                                     "valid 2D manifold",
                                     mesh.triangles[t][e], mesh.triangles[t][(e + 1) % 3]));
    }

  // Edge -> the first interface that holds it.
  std::unordered_map<std::uint64_t, int> on_interface;
  for (std::size_t f = 0; f < mesh.interfaces.size(); ++f)
    for (const auto& [u, v] : mesh.interfaces[f].edges) on_interface.emplace(key(u, v), int(f));
  topo.layer_names = mesh.layer_names;
  for (const auto& itf : mesh.interfaces) topo.interface_names.push_back(itf.name);

  // Deterministic order: walk triangles and their edges in mesh order.
  const double tol = 1e-9 * std::max(topo.width(), topo.height());
  auto& N = topo.bonds;
  auto& E = topo.boundary;
  for (std::size_t t = 0; t < nt; ++t)
    for (int e = 0; e < 3; ++e) {
      const int u = mesh.triangles[t][e], v = mesh.triangles[t][(e + 1) % 3];
      const auto& use = edges.at(key(u, v));
      const auto& pu = mesh.nodes[u];
      const auto& pv = mesh.nodes[v];
      const double len = std::hypot(pv[0] - pu[0], pv[1] - pu[1]);
      if (use.count == 2) {
        const int i = std::min(use.t0, use.t1), j = std::max(use.t0, use.t1);
        if (int(t) != i) continue;  // each interior edge once, from its lower-numbered triangle
        const double mx = 0.5 * (pu[0] + pv[0]), my = 0.5 * (pu[1] + pv[1]);
        double nx = (pv[1] - pu[1]) / len, ny = -(pv[0] - pu[0]) / len;
        const double dn = nx * (B.cx[j] - B.cx[i]) + ny * (B.cy[j] - B.cy[i]);
        if (dn < 0) nx = -nx, ny = -ny;
        N.i.push_back(i), N.j.push_back(j);
        N.node_a.push_back(u), N.node_b.push_back(v);
        N.mx.push_back(mx), N.my.push_back(my);
        N.length.push_back(len);
        N.nx.push_back(nx), N.ny.push_back(ny);
        N.d.push_back(std::abs(dn));
        const auto found = on_interface.find(key(u, v));
        const int itf = found == on_interface.end() ? -1 : found->second;
        N.interface.push_back(itf);
        N.kind.push_back(mesh.layer[i] == mesh.layer[j] && itf < 0 ? BondKind::rock : BondKind::joint);
      } else {
        Side side = Side::other;
        if (std::abs(pu[1] - topo.ymin) <= tol && std::abs(pv[1] - topo.ymin) <= tol) side = Side::bottom;
        else if (std::abs(pu[1] - topo.ymax) <= tol && std::abs(pv[1] - topo.ymax) <= tol) side = Side::top;
        else if (std::abs(pu[0] - topo.xmin) <= tol && std::abs(pv[0] - topo.xmin) <= tol) side = Side::left;
        else if (std::abs(pu[0] - topo.xmax) <= tol && std::abs(pv[0] - topo.xmax) <= tol) side = Side::right;
        E.block.push_back(int(t));
        E.node_a.push_back(u), E.node_b.push_back(v);
        E.ax.push_back(pu[0]), E.ay.push_back(pu[1]), E.bx.push_back(pv[0]), E.by.push_back(pv[1]);
        E.mx.push_back(0.5 * (pu[0] + pv[0])), E.my.push_back(0.5 * (pu[1] + pv[1]));
        E.length.push_back(len);
        E.side.push_back(side);
      }
    }

  // CSR adjacency, bonds of each block in increasing bond index.
  topo.bond_offset.assign(nt + 1, 0);
  for (std::size_t b = 0; b < N.size(); ++b) ++topo.bond_offset[N.i[b] + 1], ++topo.bond_offset[N.j[b] + 1];
  for (std::size_t t = 0; t < nt; ++t) topo.bond_offset[t + 1] += topo.bond_offset[t];
  topo.bond_of.resize(topo.bond_offset[nt]);
  std::vector<int> fill(topo.bond_offset.begin(), topo.bond_offset.end() - 1);
  for (std::size_t b = 0; b < N.size(); ++b) topo.bond_of[fill[N.i[b]]++] = int(b), topo.bond_of[fill[N.j[b]]++] = int(b);
  return topo;
}

}  // namespace rbdem
