// Average stress and diametral loads. See measure.hpp.
#include "dem/measure.hpp"

#include <cmath>
#include <stdexcept>

#include "dem/stages/bond_kernel.hpp"

namespace rbdem {

StressTensor average_stress(const Engine<2>& engine, double cx, double cy, double radius) {
  const Model<2>& m = engine.model();
  const ModelState<2>& s = engine.state();
  const Topology<2>& topo = engine.topology();
  std::vector<char> inside(m.num_blocks(), 0);
  StressTensor out;
  for (std::size_t b = 0; b < m.num_blocks(); ++b)
    if (std::hypot(s.x[b] - cx, s.y[b] - cy) <= radius) {
      inside[b] = 1;
      out.area += topo.blocks.area[b];
      ++out.blocks;
    }
  if (out.blocks == 0) return out;
  Workspace<2> w;
  stages::update_rotations(s, w, 1);
  double sxx = 0, syy = 0, sxy = 0, syx = 0;
  for (std::size_t k = 0; k < m.num_bonds(); ++k) {
    if (s.broken[k]) continue;
    const int i = m.bi[k], j = m.bj[k];
    if (!inside[std::size_t(i)] && !inside[std::size_t(j)]) continue;
    const stages::BondEval ev =
        stages::eval_bond(m, s, w, int(k), 0.0, s.fs_lin[k], ParallelBond::intact_fraction(s.drive[k], m.frame.rupture[k]));
    // The slot's force acts on j at the bond point; -f on i.
    for (const auto& [blk, sign] : {std::pair{j, 1.0}, std::pair{i, -1.0}}) {
      if (!inside[std::size_t(blk)]) continue;
      const double rx = ev.px - s.x[std::size_t(blk)], ry = ev.py - s.y[std::size_t(blk)];
      sxx += rx * sign * ev.fx, syy += ry * sign * ev.fy, sxy += rx * sign * ev.fy, syx += ry * sign * ev.fx;
    }
  }
  // The bonds' forces are compression positive on j along i -> j; the Love sum gives the stress with tension
  // positive once divided by the area and the thickness (and with the sign of a force pulling the block outward).
  const double scale = 1.0 / (out.area * m.thickness);
  out.xx = sxx * scale, out.yy = syy * scale, out.xy = 0.5 * (sxy + syx) * scale;
  return out;
}

std::vector<double> diametral_load(const Engine<2>& engine, const TriMesh& mesh, double force) {
  const Model<2>& m = engine.model();
  const Topology<2>& topo = engine.topology();
  const double tol = 1e-9 * topo.width();
  const double xc = 0.5 * (topo.xmin + topo.xmax);
  std::vector<double> load(3 * m.num_blocks(), 0.0);
  for (const auto& [y, fy] : {std::pair{topo.ymax, -force}, std::pair{topo.ymin, force}}) {
    int node = -1;
    for (std::size_t n = 0; n < mesh.nodes.size(); ++n)
      if (std::abs(mesh.nodes[n][0] - xc) <= tol && std::abs(mesh.nodes[n][1] - y) <= tol) node = int(n);
    if (node < 0)
      throw std::invalid_argument("diametral load: the mesh has no node at the disc's top or bottom point");
    std::vector<int> holders;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
      for (int v : mesh.triangles[t])
        if (v == node) holders.push_back(int(t));
    for (int b : holders) {  // the force shared among the blocks at the node, applied at the node
      const double share = fy / double(holders.size());
      const double rx = mesh.nodes[std::size_t(node)][0] - m.x0[std::size_t(b)];
      load[3 * std::size_t(b) + 1] += share;
      load[3 * std::size_t(b) + 2] += rx * share;
    }
  }
  return load;
}

}  // namespace rbdem
