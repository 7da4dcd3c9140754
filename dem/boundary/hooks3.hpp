// The engine's side of a boundary component of the 3D model (dem/boundary/boundary.hpp), as BoundaryHooks<2>
// (dem/boundary/hooks.hpp) is in 2D: the engine holds the hooks of the installed components in their order and
// calls each in turn, so their forces are summed in a fixed order and the results stay bit-identical at any thread
// count.
#pragma once

#include <vector>

#include "dem/boundary/hooks.hpp"
#include "dem/model3.hpp"
#include "dem/snapshot.hpp"
#include "dem/state3.hpp"
#include "dem/state_tables.hpp"

namespace rbdem {

// A platen's contact with a block's face as linear springs at the face's centroid (r from the block's centroid):
// normal stiffness kn along z, and with sticking platens ks along x and y (the static solve, dem/static_start3.cpp);
// kb (N m) bounds the rotational stiffness the contact on the overlap volume adds about the horizontal axes when the
// face tilts (k_n per area times the face's polar moment), for the stability limit only.
struct PlatenRow3 {
  int block;
  bool top;
  double kn, ks;  // N/m
  Vec3 r;         // m
  double kb = 0;  // N m
};

template <>
class BoundaryHooks<3> {
 public:
  virtual ~BoundaryHooks() = default;
  // Adds the component's force and moment (about the centroid) on each block at the state `s` into `force` and
  // `moment` (one per block), on the thread that runs the step's serial part. `advance` false: evaluate only (no
  // history, no energy booked). Returns the work its friction dissipated in the step (J, not negative).
  virtual double add_forces(const Model<3>& m, const ModelState<3>& s, std::vector<Vec3>& force,
                            std::vector<Vec3>& moment, double dt, bool advance) = 0;
  // Once per step, before the step's threads start, on the thread that runs the step: the state is that of the
  // step's start (the bond stage that follows moves no block, and the step's cracks are logged after it), so a
  // component may renew here what its prepare_forces and add_forces read (the contacts' pair list). Default: none.
  virtual void begin_step(const Model<3>& m, const ModelState<3>& s) { (void)m, (void)s; }
  // The part of the next add_forces(..., advance = true) that each of the step's `threads` threads may compute side
  // by side before it, thread `thread` its share (the engine calls it on every thread of the step, between the
  // bonds and the serial part, with the state not moving). A component that uses it keeps each item's result and
  // add_forces then sums them in its fixed order, so the step is the same at any thread count. Default: none.
  virtual void prepare_forces(const Model<3>& m, const ModelState<3>& s, double dt, int thread, int threads) {
    (void)m, (void)s, (void)dt, (void)thread, (void)threads;
  }
  // After the integrator: the component's own motion (the top platen).
  virtual void after_step(const Model<3>&, ModelState<3>&, double dt) { (void)dt; }
  // The forces it puts on the blocks now, each at its point (Simulation::boundary_loads()).
  virtual void loads(const Model<3>& m, const ModelState<3>& s, int component, BoundaryLoads& out) const = 0;
  // The stiffness it adds to each block (the block-wise critical step) and its rows in the static solve.
  virtual void add_stiffness(const Model<3>&, std::vector<BlockStiffness3>& k) const { (void)k; }
  virtual void static_rows(const Model<3>&, std::vector<PlatenRow3>& rows) const { (void)rows; }
  // The state of a static solution scaled by `factor` (the top platen's position).
  virtual void apply_static(const Model<3>&, const StaticResult& st, double factor) { (void)st, (void)factor; }
  virtual double stored_energy() const { return 0.0; }
  virtual double work_done() const = 0;
  virtual void save(Snapshot& s) const = 0;
  virtual void load(const Snapshot& s, const Model<3>& m) = 0;
};

}  // namespace rbdem
