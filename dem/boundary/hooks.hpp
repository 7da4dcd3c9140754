// The engine's side of a boundary component (dem/boundary/boundary.hpp): the hooks through which the engine of one
// dimension calls it at each point of a step, of the static solve and of a snapshot. A component implements its
// dimension-free interface (Platens, Jacket, BlockGroup) and BoundaryHooks<dim>; the engine holds the hooks of the
// installed components in their order and calls each in turn, so their forces are summed in a fixed order and the
// results stay bit-identical at any thread count.
#pragma once

#include <vector>

#include "dem/model.hpp"
#include "dem/snapshot.hpp"
#include "dem/static_result.hpp"
#include "dem/stages/stages.hpp"
#include "dem/state.hpp"
#include "dem/state_tables.hpp"

namespace rbdem {

// What a component adds to the static elastic solve of the 2D model (dem/static_solve.cpp).
struct StaticSupports2 {
  // A platen's contact with a block's boundary edge as a linear spring: normal stiffness k along y at the edge's
  // midpoint (rx, ry from the centroid), and with sticking platens the shear stiffness k / kappa along x.
  struct PlatenRow {
    int block;
    bool top;
    double k;       // N/m
    double rx, ry;  // m
  };
  std::vector<PlatenRow> platen_rows;
  bool sticky_platens = false;  // friction > 0: the platens hold the edges against sliding
  std::vector<int> fixed;       // blocks whose three dofs are held at zero
  std::vector<double> load;     // constant loads (3 per block; empty: none), added to StaticOptions::load
};

// One row of a 2D component's loads: the force (fx, fy) on `block` at (px, py) and a couple besides.
inline void append_load(BoundaryLoads& out, int block, int component, double px, double py, double fx, double fy,
                        double couple = 0.0) {
  out.block.push_back(block), out.component.push_back(component);
  out.point.insert(out.point.end(), {px, py});
  out.force.insert(out.force.end(), {fx, fy});
  out.moment.push_back(couple);
}

template <int dim>
class BoundaryHooks;

template <>
class BoundaryHooks<2> {
 public:
  virtual ~BoundaryHooks() = default;

  // --- the step ---
  // The broad phase rebuilt its lists over the eligible blocks (ascending) / added the `joining` blocks after bond
  // breaks (ascending): candidates for the component's contacts.
  virtual void on_rebuild(const Model<2>&, const ModelState<2>&, const std::vector<int>& eligible) { (void)eligible; }
  virtual void on_join(const Model<2>&, const ModelState<2>&, const std::vector<int>& joining) { (void)joining; }
  // Whether the broad phase must rebuild whatever the blocks did (the top platen moved half a skin).
  virtual bool rebuild_due(const Model<2>&) const { return false; }
  // The forces: begin once before the step's team, share on each thread t of nt (its blocks, Workspace::share), end
  // once after every share and after the contacts' sums: adds into w.cfx, w.cfy, w.cm. `c.advance` false: evaluate
  // only (no history, no energy booked).
  virtual void forces_begin(const Model<2>&, ModelState<2>&, Workspace<2>&, const StepContext&) {}
  virtual bool shares() const { return false; }
  virtual void forces_share(const Model<2>&, ModelState<2>&, Workspace<2>&, const StepContext&, int t, int nt) {
    (void)t, (void)nt;
  }
  virtual void forces_end(const Model<2>&, ModelState<2>&, Workspace<2>&, const StepContext&) {}
  // After the integrator, serially: the component's own motion (the top platen), prescribed blocks.
  virtual void after_step(const Model<2>&, ModelState<2>&, Workspace<2>&, double dt) { (void)dt; }
  // The forces it puts on the blocks in the state `s` now, each at its point, appended to `out` with `component`
  // as their component (its index among those installed): what its stage adds to each block, for measurements
  // (the Love-Weber stress, dem/measure.hpp). Advances nothing; `w` is the engine's workspace of that state.
  // A component that holds its blocks (holds_blocks()) puts the reaction that keeps them on their prescribed path:
  // `others` gives, 3 per block, the resultant force and moment (about the centroid) of every other force on it
  // now (bonds, contacts, the other components); it is empty for the others.
  virtual void loads(const Model<2>& m, const ModelState<2>& s, const Workspace<2>& w, int component,
                     const std::vector<double>& others, BoundaryLoads& out) const = 0;
  virtual bool holds_blocks() const { return false; }

  // --- the stability estimate and the static solve ---
  // The stiffness it adds to each block, translational (N/m) and rotational (N m), for the block-wise estimate.
  virtual void add_stiffness(const Model<2>&, std::vector<double>& kt, std::vector<double>& kr) const {
    (void)kt, (void)kr;
  }
  virtual void static_supports(const Model<2>&, StaticSupports2& supports) const { (void)supports; }
  // The state of a static solution scaled by `factor` (its shear histories, the top platen's position).
  virtual void apply_static(const Model<2>&, const ModelState<2>&, const StaticResult& st, double factor) {
    (void)st, (void)factor;
  }

  // --- energy and snapshot ---
  virtual double stored_energy() const { return 0.0; }
  virtual double work_done() const = 0;
  // Its fields under "name/..." and back; load throws std::invalid_argument when a field is missing or does not fit.
  virtual void save(Snapshot& s) const = 0;
  virtual void load(const Snapshot& s, const Model<2>& m) = 0;
};

}  // namespace rbdem
