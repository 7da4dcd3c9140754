// Block groups of the 2D model: chosen blocks held fixed, moved at a prescribed velocity, or loaded by a constant
// force. See components.hpp.
//
// A fixed or driven group's blocks are fixed in the integrator (their state is kept); after each step a driven
// group moves them by its velocity times the step and sets their velocities, so they push the rest of the model as a
// rigid displacement would. Its reading is the reaction: the sum of the forces on its blocks in the last step. A
// force group adds its force to each of its blocks after the contacts and the other components.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "dem/boundary/components.hpp"

namespace rbdem {

BlockGroupImpl<2>::BlockGroupImpl(Engine<2>& engine, const GroupSettings& settings)
    : engine_(engine), settings_(settings) {
  const std::size_t nb = engine.model().num_blocks();
  std::sort(settings_.blocks.begin(), settings_.blocks.end());
  settings_.blocks.erase(std::unique(settings_.blocks.begin(), settings_.blocks.end()), settings_.blocks.end());
  for (int b : settings_.blocks)
    if (b < 0 || std::size_t(b) >= nb)
      throw std::invalid_argument(fmt::format("block group '{}': block {} is not in the model ({} blocks)",
                                              settings_.name, b, nb));
  if (settings_.mode != GroupSettings::Mode::fixed && settings_.value.size() != 3)
    throw std::invalid_argument(fmt::format("block group '{}': give 3 values (x, y and the rotation) for its {}",
                                            settings_.name,
                                            settings_.mode == GroupSettings::Mode::velocity ? "velocity" : "force"));
  if (settings_.mode != GroupSettings::Mode::force)
    for (int b : settings_.blocks) engine.fix_block(b);
}

void BlockGroupImpl<2>::set_value(const std::vector<double>& value) {
  if (settings_.mode == GroupSettings::Mode::fixed)
    throw std::invalid_argument(fmt::format("block group '{}' is fixed: it takes no velocity or force", settings_.name));
  if (value.size() != 3)
    throw std::invalid_argument(fmt::format("block group '{}': give 3 values (x, y and the rotation), not {}",
                                            settings_.name, value.size()));
  settings_.value = value;
}

std::vector<double> BlockGroupImpl<2>::displacement() const {
  const Model<2>& m = engine_.model();
  const ModelState<2>& s = engine_.state();
  std::vector<double> d(2, 0.0);
  for (int b : settings_.blocks) d[0] += s.x[std::size_t(b)] - m.x0[std::size_t(b)], d[1] += s.y[std::size_t(b)] - m.y0[std::size_t(b)];
  const double n = double(std::max<std::size_t>(settings_.blocks.size(), 1));
  return {d[0] / n, d[1] / n};
}

std::vector<std::pair<std::string, double>> BlockGroupImpl<2>::readings() const {
  const std::vector<double> d = displacement();
  return {{"force_x_n", force_[0]}, {"force_y_n", force_[1]}, {"moment_n_m", force_[2]},
          {"displacement_x_m", d[0]}, {"displacement_y_m", d[1]}, {"work_j", work_}};
}

void BlockGroupImpl<2>::forces_end(const Model<2>&, ModelState<2>& s, Workspace<2>& w, const StepContext& c) {
  if (settings_.mode != GroupSettings::Mode::force) return;
  const double* f = settings_.value.data();
  double power = 0.0;
  for (int b : settings_.blocks) {
    const std::size_t k = std::size_t(b);
    w.cfx[k] += f[0], w.cfy[k] += f[1], w.cm[k] += f[2];
    power += f[0] * s.vx[k] + f[1] * s.vy[k] + f[2] * s.omega[k];
  }
  if (c.advance) work_ += power * c.dt;
}

void BlockGroupImpl<2>::after_step(const Model<2>&, ModelState<2>& s, Workspace<2>& w, double dt) {
  force_.assign(3, 0.0);
  for (int b : settings_.blocks) {
    const std::size_t k = std::size_t(b);
    force_[0] += s.fx[k], force_[1] += s.fy[k], force_[2] += s.moment[k];
  }
  if (settings_.mode != GroupSettings::Mode::velocity) return;
  // The group pushes the rest of the model with the opposite of the force on its blocks: its work is -F . v dt.
  const double* v = settings_.value.data();
  work_ -= (force_[0] * v[0] + force_[1] * v[1] + force_[2] * v[2]) * dt;
  for (int b : settings_.blocks) {
    const std::size_t k = std::size_t(b);
    s.x[k] += v[0] * dt, s.y[k] += v[1] * dt, s.theta[k] += v[2] * dt;
    s.vx[k] = v[0], s.vy[k] = v[1], s.omega[k] = v[2];
  }
  stages::update_rotations_of(s, w, settings_.blocks);
}

// A force group: its force at each block's centroid and its moment as a couple. A fixed or driven group: the
// reaction that holds each block now, the opposite of the resultant of every other force on it, at its centroid.
void BlockGroupImpl<2>::loads(const Model<2>&, const ModelState<2>& s, const Workspace<2>&, int component,
                              const std::vector<double>& others, BoundaryLoads& out) const {
  const bool force = settings_.mode == GroupSettings::Mode::force;
  const double* f = settings_.value.data();
  for (int b : settings_.blocks) {
    const std::size_t k = std::size_t(b);
    if (force) append_load(out, b, component, s.x[k], s.y[k], f[0], f[1], f[2]);
    else append_load(out, b, component, s.x[k], s.y[k], -others[3 * k], -others[3 * k + 1], -others[3 * k + 2]);
  }
}

void BlockGroupImpl<2>::static_supports(const Model<2>&, StaticSupports2& supports) const {
  if (settings_.mode == GroupSettings::Mode::force) {
    if (supports.load.empty()) supports.load.assign(3 * engine_.model().num_blocks(), 0.0);
    for (int b : settings_.blocks)
      for (std::size_t d = 0; d < 3; ++d) supports.load[3 * std::size_t(b) + d] += settings_.value[d];
  } else {
    supports.fixed.insert(supports.fixed.end(), settings_.blocks.begin(), settings_.blocks.end());
  }
}

void BlockGroupImpl<2>::save(Snapshot& s) const {
  const std::string p = "groups/" + settings_.name + "/";
  s.add(p + "work", Extent::scalar, work_);
  s.add(p + "force", Extent::free, force_);
  s.add(p + "blocks", Extent::free, settings_.blocks);
  s.add(p + "value", Extent::free, settings_.value);
}

void BlockGroupImpl<2>::load(const Snapshot& s, const Model<2>&) {
  const std::string p = "groups/" + settings_.name + "/";
  if (s.get<std::vector<int>>(p + "blocks") != settings_.blocks)
    throw std::invalid_argument(fmt::format("the snapshot's block group '{}' holds other blocks", settings_.name));
  work_ = s.get<double>(p + "work");
  force_ = s.get<std::vector<double>>(p + "force");
  settings_.value = s.get<std::vector<double>>(p + "value");
}

}  // namespace rbdem
