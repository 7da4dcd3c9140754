// The jacket of the 2D model: a confining pressure on the specimen's outer edges, as a membrane would apply it
// (docs/model.md, "Confined compression"). See components.hpp.
//
// Each outer edge that is not on a platen carries the follower force F = -p t L n, L n the edge's current length
// times its current outward normal, at its current midpoint; the work p does is booked (the watchdog counts it as
// energy put in). The rule for a jacket that loses contact: an edge carries pressure while its block is part of the
// specimen, i.e. still has an intact bond or a contact that carries force this step. A block that lost every bond
// and every contact (a fragment that flew off) gets no pressure: a membrane would span the gap rather than push a
// loose fragment back, and a constant force on a free block would accelerate it without bound. Such edges are
// counted (faces_lost, and the most at any step, faces_lost_max: "jacket_edges_lost" in summary.json).
#include <algorithm>
#include <stdexcept>

#include "dem/boundary/components.hpp"
#include "dem/stages/bond_kernel.hpp"

namespace rbdem {

JacketImpl<2>::JacketImpl(const Model<2>& m, double pressure) : thickness_(m.thickness), pressure_(pressure) {
  const Topology<2>& topo = *m.topology;
  const auto& E = topo.boundary;
  if (E.ax.size() != E.size() || E.by.size() != E.size())
    throw std::invalid_argument("the jacket: the topology's boundary edges have no end points (ax, ay, bx, by)");
  for (std::size_t e = 0; e < E.size(); ++e) {
    if (E.side[e] == Side::top || E.side[e] == Side::bottom) continue;
    const std::size_t b = std::size_t(E.block[e]);
    block_.push_back(E.block[e]);
    ax_.push_back(E.ax[e] - topo.blocks.cx[b]), ay_.push_back(E.ay[e] - topo.blocks.cy[b]);
    bx_.push_back(E.bx[e] - topo.blocks.cx[b]), by_.push_back(E.by[e] - topo.blocks.cy[b]);
  }
}

std::vector<std::pair<std::string, double>> JacketImpl<2>::readings() const {
  return {{"pressure_pa", pressure_}, {"work_j", work_}, {"faces_lost", double(lost_)},
          {"faces_lost_max", double(lost_max_)}};
}

void JacketImpl<2>::forces_end(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c) {
  if (!(pressure_ > 0.0)) {
    if (c.advance) lost_ = 0;
    return;
  }
  // Blocks in a contact that carries force this step (the contact stage's records).
  const std::size_t nb = m.num_blocks();
  touching_.assign(nb, 0);
  for (const std::vector<int>& list : w.in_contact)
    for (int p : list) {
      const Workspace<2>::PairForce& f = w.pair_force[std::size_t(p)];
      if (f.fx != 0.0 || f.fy != 0.0) touching_[std::size_t(s.contacts.i[p])] = touching_[std::size_t(s.contacts.j[p])] = 1;
    }
  int lost = 0;
  double work = 0.0;
  for (std::size_t e = 0; e < block_.size(); ++e) {
    const std::size_t k = std::size_t(block_[e]);
    if (!loaded(m, s, e)) {
      ++lost;
      continue;
    }
    const auto [fx, fy, rx, ry] = face_force(e, w.cos_t[k], w.sin_t[k]);
    w.cfx[k] += fx, w.cfy[k] += fy, w.cm[k] += stages::cross(rx, ry, fx, fy);
    work += fx * (s.vx[k] - s.omega[k] * ry) + fy * (s.vy[k] + s.omega[k] * rx);
  }
  if (!c.advance) return;
  lost_ = lost;
  lost_max_ = std::max(lost_max_, lost);
  work_ += work * c.dt;
}

JacketImpl<2>::FaceForce JacketImpl<2>::face_force(std::size_t e, double co, double si) const {
  const double pt = pressure_ * thickness_;
  const double ax = co * ax_[e] - si * ay_[e], ay = si * ax_[e] + co * ay_[e];
  const double bx = co * bx_[e] - si * by_[e], by = si * bx_[e] + co * by_[e];
  // L n = (dy, -dx) for the edge a -> b: the outside is to its right.
  return {-pt * (by - ay), pt * (bx - ax), 0.5 * (ax + bx), 0.5 * (ay + by)};
}

bool JacketImpl<2>::loaded(const Model<2>& m, const ModelState<2>& s, std::size_t e) const {
  const int b = block_[e];
  return (std::size_t(b) < touching_.size() && touching_[std::size_t(b)]) || m.has_intact_bond(b, s.broken);
}

// Each loaded face's force at its midpoint now; whether a block without an intact bond is loaded follows the
// contacts of the last step, as in that step.
void JacketImpl<2>::loads(const Model<2>& m, const ModelState<2>& s, const Workspace<2>& w, int component,
                          const std::vector<double>&, BoundaryLoads& out) const {
  if (!(pressure_ > 0.0)) return;
  for (std::size_t e = 0; e < block_.size(); ++e) {
    if (!loaded(m, s, e)) continue;
    const int b = block_[e];
    const std::size_t k = std::size_t(b);
    const auto [fx, fy, rx, ry] = face_force(e, w.cos_t[k], w.sin_t[k]);
    append_load(out, b, component, s.x[k] + rx, s.y[k] + ry, fx, fy);
  }
}

std::vector<double> JacketImpl<2>::reference_load(const Model<2>& m, double pressure) const {
  std::vector<double> f(3 * m.num_blocks(), 0.0);
  const double pt = pressure * thickness_;
  for (std::size_t e = 0; e < block_.size(); ++e) {
    const std::size_t b = std::size_t(block_[e]);
    // The same force as forces_end in the reference configuration.
    const double fx = -pt * (by_[e] - ay_[e]), fy = pt * (bx_[e] - ax_[e]);
    const double rx = 0.5 * (ax_[e] + bx_[e]), ry = 0.5 * (ay_[e] + by_[e]);
    f[3 * b] += fx, f[3 * b + 1] += fy, f[3 * b + 2] += rx * fy - ry * fx;
  }
  return f;
}

void JacketImpl<2>::save(Snapshot& s) const {
  s.add("jacket/pressure", Extent::scalar, pressure_);
  s.add("jacket/work", Extent::scalar, work_);
  s.add("jacket/lost", Extent::scalar, lost_);
  s.add("jacket/lost_max", Extent::scalar, lost_max_);
}

void JacketImpl<2>::load(const Snapshot& s, const Model<2>&) {
  pressure_ = s.get<double>("jacket/pressure");
  work_ = s.get<double>("jacket/work");
  lost_ = s.get<int>("jacket/lost");
  lost_max_ = s.get<int>("jacket/lost_max");
}

}  // namespace rbdem
