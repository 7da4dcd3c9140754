// The platens of the 2D model: two rigid walls, the top one at top_y closing at its velocity (or under a servo),
// the bottom one fixed at the specimen's lowest point. Each acts on the candidate blocks as a half-plane with the
// linear contact law (dem/laws/linear_contact.hpp), k_n from the block's mirror image (d = 2 x inradius). See
// components.hpp.
//
// Each candidate's contact runs in parallel into its own record (the top platen's candidates, then the bottom
// one's), each thread the candidates among the blocks it integrates; the records are then summed serially in that
// order, so the sums do not depend on the thread count.
#include <algorithm>
#include <array>
#include <cmath>

#include "dem/boundary/components.hpp"
#include "dem/contact_geometry.hpp"
#include "dem/stages/bond_kernel.hpp"

namespace rbdem {

PlatensImpl<2>::PlatensImpl(const Model<2>& m, const PlatenSettings& settings)
    : ymin_(m.ymin), ymax_(m.ymax), width_(m.width), thickness_(m.thickness), skin_(m.skin),
      friction_(settings.friction), top_y_(m.ymax), velocity_(settings.velocity) {
  const std::size_t nb = m.num_blocks();
  kn_.resize(nb), lref_.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    kn_[b] = m.law[m.block_material[b]].modulus / (2.0 * m.inradius[b]);
    lref_[b] = 2.0 * std::sqrt(3.0) * m.inradius[b];
  }
  const Topology<2>& topo = *m.topology;
  const auto& E = topo.boundary;
  for (std::size_t e = 0; e < E.size(); ++e) {
    if (E.side[e] != Side::top && E.side[e] != Side::bottom) continue;
    const int b = E.block[e];
    lref_[std::size_t(b)] = E.length[e];
    edge_block.push_back(b), edge_top.push_back(E.side[e] == Side::top);
    edge_length.push_back(E.length[e]);
    edge_rx.push_back(E.mx[e] - topo.blocks.cx[std::size_t(b)]), edge_ry.push_back(E.my[e] - topo.blocks.cy[std::size_t(b)]);
  }
  top_fs_.assign(nb, 0.0), bottom_fs_.assign(nb, 0.0);
}

LinearContact PlatensImpl<2>::law(const Model<2>& m, int block) const {
  const std::size_t b = std::size_t(block);
  return LinearContact::per_area(kn_[b], kn_[b] / m.law[m.block_material[b]].kappa, friction_, lref_[b], thickness_);
}

std::vector<std::pair<std::string, double>> PlatensImpl<2>::readings() const {
  return {{"top_force_n", top_force_},   {"bottom_force_n", bottom_force_}, {"closure_m", closure()},
          {"velocity_m_s", velocity_},   {"stress_pa", stress()},           {"work_j", work_},
          {"energy_j", energy_},         {"servo", servo_on_ ? 1.0 : 0.0}};
}

// --- the broad phase: the candidates ---------------------------------------------------------------------------

// The candidates among `blocks` (ascending), appended: a block that may reach a platen before the next rebuild
// (each side may travel half a skin), the top platen taken at `top`.
void PlatensImpl<2>::add_candidates(const Model<2>& m, const ModelState<2>& s, const std::vector<int>& blocks,
                                    double top) {
  for (int b : blocks) {
    if (s.y[b] + m.radius[b] > top - m.skin) top_candidates_.push_back(b);
    if (s.y[b] - m.radius[b] < m.ymin + m.skin) bottom_candidates_.push_back(b);
  }
}

void PlatensImpl<2>::on_rebuild(const Model<2>& m, const ModelState<2>& s, const std::vector<int>& eligible) {
  ref_top_ = top_y_;
  top_candidates_.clear(), bottom_candidates_.clear();
  add_candidates(m, s, eligible, top_y_);
}

void PlatensImpl<2>::on_join(const Model<2>& m, const ModelState<2>& s, const std::vector<int>& joining) {
  const std::size_t top = top_candidates_.size(), bottom = bottom_candidates_.size();
  add_candidates(m, s, joining, ref_top_);
  std::inplace_merge(top_candidates_.begin(), top_candidates_.begin() + std::ptrdiff_t(top), top_candidates_.end());
  std::inplace_merge(bottom_candidates_.begin(), bottom_candidates_.begin() + std::ptrdiff_t(bottom),
                     bottom_candidates_.end());
}

bool PlatensImpl<2>::rebuild_due(const Model<2>& m) const { return std::abs(top_y_ - ref_top_) > 0.5 * m.skin; }

// --- the forces ---------------------------------------------------------------------------------------------------

// The contact of candidate k (the top platen's candidates first) into its record.
void PlatensImpl<2>::contact(const Model<2>& m, ModelState<2>& s, const Workspace<2>& w, const StepContext& c, int k) {
  const int ntop = int(top_candidates_.size());
  const bool top = k < ntop;
  const int b = top ? top_candidates_[std::size_t(k)] : bottom_candidates_[std::size_t(k - ntop)];
  const double wy = top ? top_y_ : m.ymin;
  const double my = top ? 1.0 : -1.0;  // into the platen
  const double wall_vy = top ? -velocity_ : 0.0;
  double v[6];
  stages::block_vertices(m, s, w, b, v);
  Overlap ov;
  double& fs_hist = (top ? top_fs_ : bottom_fs_)[std::size_t(b)];  // each block once per platen
  if (!overlap_halfplane(v, 3, 0.0, wy, 0.0, my, ov)) {
    force_[std::size_t(k)] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, false};
    if (c.advance) fs_hist = 0.0;
    return;
  }
  const LinearContact contact_law = law(m, b);
  const double fn = contact_law.normal_force(ov.area, ov.chord);
  // Force on the block: -fn along the normal (out of the platen), shear along t = perp(n).
  const double nx = ov.nx, ny = ov.ny, tx = -ny, ty = nx;
  const double rx = ov.px - s.x[b], ry = ov.py - s.y[b];
  const double vrx = s.vx[b] - s.omega[b] * ry, vry = s.vy[b] + s.omega[b] * rx - wall_vy;
  const double vt = vrx * tx + vry * ty;
  double fs = fs_hist;
  const double friction = contact_law.update_shear(fn, ov.chord, vt, c.dt, fs) ? std::abs(fs * vt * c.dt) : 0.0;
  if (c.advance) fs_hist = fs;
  const double fx = -fn * nx + fs * tx, fy = -fn * ny + fs * ty;
  force_[std::size_t(k)] = {fx, fy, stages::cross(rx, ry, fx, fy), fn, contact_law.strain_energy(fn, fs, ov.chord),
                            friction, true};
}

void PlatensImpl<2>::forces_begin(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c) {
  (void)s;
  if (c.advance) {
    // The servo's speed for this step, from the last step's stress.
    if (servo_on_)
      velocity_ = std::clamp(servo_.gain * (servo_.target_stress - stress()), -servo_.max_velocity,
                             servo_.max_velocity);
    top_force_ = bottom_force_ = energy_ = 0.0;
  }
  stages::partition(m, w, c.threads);
  force_.resize(top_candidates_.size() + bottom_candidates_.size());
}

void PlatensImpl<2>::forces_share(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c, int t,
                                  int nt) {
  // Each thread takes the candidates among the blocks it integrates (the lists are sorted by block): it reads the
  // blocks it moved itself.
  const std::array<int, 2> blocks = w.share(w.part.block, t, nt);
  const int b0 = blocks[0], b1 = blocks[1];
  auto mine = [&](const std::vector<int>& list, int& lo, int& hi) {
    lo = int(std::lower_bound(list.begin(), list.end(), b0) - list.begin());
    hi = int(std::lower_bound(list.begin(), list.end(), b1) - list.begin());
  };
  const int ntop = int(top_candidates_.size());
  int lo, hi;
  mine(top_candidates_, lo, hi);
  for (int k = lo; k < hi; ++k) contact(m, s, w, c, k);
  mine(bottom_candidates_, lo, hi);
  for (int k = lo; k < hi; ++k) contact(m, s, w, c, ntop + k);
}

void PlatensImpl<2>::forces_end(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c) {
  (void)m;
  const int ntop = int(top_candidates_.size()), n = ntop + int(bottom_candidates_.size());
  double top_total = 0.0, bottom_total = 0.0, energy = 0.0;
  for (int k = 0; k < n; ++k) {
    const bool top = k < ntop;
    const int b = top ? top_candidates_[std::size_t(k)] : bottom_candidates_[std::size_t(k - ntop)];
    const Force& f = force_[std::size_t(k)];
    if (!f.touching) continue;
    if (c.advance) s.e_friction += f.friction;
    w.cfx[b] += f.fx, w.cfy[b] += f.fy, w.cm[b] += f.m;
    (top ? top_total : bottom_total) += f.fn;
    energy += f.energy;
  }
  if (!c.advance) return;
  top_force_ = top_total, bottom_force_ = bottom_total, energy_ = energy;
  work_ += top_force_ * velocity_ * c.dt;
}

void PlatensImpl<2>::after_step(const Model<2>&, ModelState<2>&, Workspace<2>&, double dt) { top_y_ -= velocity_ * dt; }

// Every block that overlaps a platen now, not only the candidates (a state set by apply_static has none before its
// first step): the contact law at the overlap and the shear force as carried (capped by friction), at the overlap's
// centroid, the top platen's rows first.
void PlatensImpl<2>::loads(const Model<2>& m, const ModelState<2>& s, const Workspace<2>& w, int component,
                           const std::vector<double>&, BoundaryLoads& out) const {
  for (const bool top : {true, false}) {
    const double wy = top ? top_y_ : m.ymin;
    const double my = top ? 1.0 : -1.0;  // into the platen
    const std::vector<double>& history = top ? top_fs_ : bottom_fs_;
    for (std::size_t b = 0; b < m.num_blocks(); ++b) {
      if (top ? s.y[b] + m.radius[b] < wy : s.y[b] - m.radius[b] > wy) continue;
      double v[6];
      stages::block_vertices(m, s, w, int(b), v);
      Overlap ov;
      if (!overlap_halfplane(v, 3, 0.0, wy, 0.0, my, ov)) continue;
      const LinearContact contact_law = law(m, int(b));
      const double fn = contact_law.normal_force(ov.area, ov.chord);
      double fs = history[b];
      contact_law.update_shear(fn, ov.chord, 0.0, 0.0, fs);
      const double tx = -ov.ny, ty = ov.nx;
      append_load(out, int(b), component, ov.px, ov.py, -fn * ov.nx + fs * tx, -fn * ov.ny + fs * ty);
    }
  }
}

// --- the stability estimate and the static solve ------------------------------------------------------------------

void PlatensImpl<2>::add_stiffness(const Model<2>& m, std::vector<double>& kt, std::vector<double>& kr) const {
  for (std::size_t e = 0; e < edge_block.size(); ++e) {
    const std::size_t blk = std::size_t(edge_block[e]);
    const double k = kn_[blk] * thickness_ * edge_length[e];
    kt[blk] += k * (1.0 + 1.0 / m.law[m.block_material[blk]].kappa);
    const double r = 0.5 * m.radius[blk];
    kr[blk] += k * r * r;
  }
}

void PlatensImpl<2>::static_supports(const Model<2>& m, StaticSupports2& supports) const {
  (void)m;
  for (std::size_t e = 0; e < edge_block.size(); ++e) {
    const int b = edge_block[e];
    supports.platen_rows.push_back({b, edge_top[e] != 0, kn_[std::size_t(b)] * thickness_ * edge_length[e],
                                    edge_rx[e], edge_ry[e]});
  }
  supports.sticky_platens = friction_ > 0.0;
}

void PlatensImpl<2>::apply_static(const Model<2>& m, const ModelState<2>& s, const StaticResult& st, double factor) {
  // A block's platen shear goes to the platen it touches, found from its position.
  const double mid = 0.5 * (top_y_ + m.ymin);
  for (std::size_t b = 0; b < m.num_blocks(); ++b)
    if (!st.platen_fs.empty() && st.platen_fs[b] != 0.0) (s.y[b] > mid ? top_fs_ : bottom_fs_)[b] = factor * st.platen_fs[b];
  top_y_ = m.ymax - factor * st.platen_displacement;
}

// --- snapshot -------------------------------------------------------------------------------------------------

void PlatensImpl<2>::save(Snapshot& s) const {
  s.add("platens/top_y", Extent::scalar, top_y_);
  s.add("platens/velocity", Extent::scalar, velocity_);
  s.add("platens/servo", Extent::scalar, servo_on_);
  s.add("platens/servo_target_stress", Extent::scalar, servo_.target_stress);
  s.add("platens/servo_gain", Extent::scalar, servo_.gain);
  s.add("platens/servo_max_velocity", Extent::scalar, servo_.max_velocity);
  s.add("platens/friction", Extent::scalar, friction_);
  s.add("platens/top_force", Extent::scalar, top_force_);
  s.add("platens/bottom_force", Extent::scalar, bottom_force_);
  s.add("platens/energy", Extent::scalar, energy_);
  s.add("platens/work", Extent::scalar, work_);
  s.add("platens/ref_top", Extent::scalar, ref_top_);
  s.add("platens/top_candidates", Extent::free, top_candidates_);
  s.add("platens/bottom_candidates", Extent::free, bottom_candidates_);
  s.add("platens/top_fs", Extent::blocks, top_fs_);
  s.add("platens/bottom_fs", Extent::blocks, bottom_fs_);
}

void PlatensImpl<2>::load(const Snapshot& s, const Model<2>& m) {
  if (s.get<double>("platens/friction") != friction_)
    throw std::invalid_argument("the snapshot's platens have another friction coefficient");
  const std::size_t nb = m.num_blocks();
  auto blocks_in_range = [nb](const std::vector<int>& v) {
    return std::all_of(v.begin(), v.end(), [nb](int b) { return b >= 0 && std::size_t(b) < nb; });
  };
  const auto& top_c = s.get<std::vector<int>>("platens/top_candidates");
  const auto& bottom_c = s.get<std::vector<int>>("platens/bottom_candidates");
  const auto& top_fs = s.get<std::vector<double>>("platens/top_fs");
  const auto& bottom_fs = s.get<std::vector<double>>("platens/bottom_fs");
  if (!blocks_in_range(top_c) || !blocks_in_range(bottom_c) || top_fs.size() != nb || bottom_fs.size() != nb)
    throw std::invalid_argument("the snapshot's platens do not fit this model (another scene or mesh)");
  top_y_ = s.get<double>("platens/top_y");
  velocity_ = s.get<double>("platens/velocity");
  servo_on_ = s.get<bool>("platens/servo");
  servo_ = {s.get<double>("platens/servo_target_stress"), s.get<double>("platens/servo_gain"),
            s.get<double>("platens/servo_max_velocity")};
  top_force_ = s.get<double>("platens/top_force");
  bottom_force_ = s.get<double>("platens/bottom_force");
  energy_ = s.get<double>("platens/energy");
  work_ = s.get<double>("platens/work");
  ref_top_ = s.get<double>("platens/ref_top");
  top_candidates_ = top_c, bottom_candidates_ = bottom_c;
  top_fs_ = top_fs, bottom_fs_ = bottom_fs;
}

}  // namespace rbdem
