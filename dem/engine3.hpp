// The explicit RB-DEM engine of the 3D model: rigid tetrahedral blocks (centroid and unit quaternion), linear
// parallel bonds on shared triangular faces (dem/laws/face_bond.hpp, dem/stages/face_bond_kernel.hpp) that go on
// as compression-only Coulomb face contacts through their linear part once broken, the boundary components attached
// to it (dem/boundary/hooks3.hpp), and the rigid-block step of dem/rigid3.hpp (leapfrog translation, the symplectic
// splitting for the rotation, Cundall's local damping per component). docs/theory.md, section 11; docs/model.md.
//
// One step: the bond stage (each thread a contiguous range of bonds, in chunks of 64: the blocks' records
// transposed, the branch-free kernel of dem/stages/face_bonds3.hpp in vector lanes over the model's bond table,
// each bond's forces into its own slot; then, bond by bond, the exact form where the lanes' form does not hold and
// the failure test where the load reaches the strength), the serial part (the crack log from the threads' lists in
// thread order, which is bond order; the boundary components' forces), the block stage (each thread a contiguous
// range of blocks, in chunks: the gather of each block's bonds in bond order, then the rigid step of
// dem/rigid3.hpp in vector lanes, and each block's record for the next step). Every sum is done in the same order
// at any thread count and a bond's or a block's numbers do not depend on the lane or chunk it falls in, so results
// are bit-identical at any thread count. The records are refreshed by the step, by edit() and by restore(): a
// boundary component changes forces, never the blocks' kinematics. Contacts between blocks that were never
// neighbours are not detected here: a boundary component adds them (dem/boundary/).
#pragma once

#include <functional>
#include <vector>

#include "dem/boundary/hooks3.hpp"
#include "dem/engine.hpp"
#include "dem/model3.hpp"
#include "dem/state3.hpp"
#include "dem/state_tables.hpp"
#include "dem/team.hpp"

namespace rbdem {

template <>
class Engine<3> {
 public:
  // The model of `mesh` (which must outlive the engine) with the scene's materials.
  Engine(const TetMesh& mesh, const Scene& scene, const EngineOptions& options);

  // --- stepping ---
  void step();
  void run(long steps) {
    for (long k = 0; k < steps; ++k) step();
  }
  void set_dt(double dt) { state_.dt = dt; }
  double dt() const { return state_.dt; }
  double time() const { return state_.time; }
  long steps() const { return state_.steps; }
  // The block-wise critical step (BlockStiffness3 over each block's bonds and components).
  double critical_step() const;

  // --- the model and its state ---
  const Model<3>& model() const { return model_; }
  const ModelState<3>& state() const { return state_; }
  // Replaces the state (throws std::invalid_argument when it does not fit the model).
  void restore(const ModelState<3>& s);
  // Changes the state through `change` (placing blocks: the static start, tests).
  void edit(const std::function<void(ModelState<3>&)>& change) {
    change(state_);
    refresh_records();
  }
  void break_bond(int b);
  void fix_block(int b, bool fixed = true);
  // Bond b's forces at the state now (the parallel bond's undamaged part and the linear part apart), without
  // advancing its history.
  stages::FaceBondOut bond_forces(std::size_t b) const {
    double keep = 0;
    return bond_now(b, keep);
  }
  void attach(BoundaryHooks<3>* hooks) { hooks_.push_back(hooks); }
  const std::vector<BoundaryHooks<3>*>& hooks() const { return hooks_; }

  // The force and moment on every block at the current state through the same stages as step(), without advancing
  // anything (tests, the reference checks).
  void evaluate_forces(std::vector<Vec3>& force, std::vector<Vec3>& moment) const;

  // --- diagnostics ---
  BlockStates block_states() const;
  BondStates bond_states() const;
  BoundaryLoads boundary_loads() const;
  Energies energies() const;
  const std::vector<Crack>& cracks() const { return state_.cracks; }
  const EngineOptions& options() const { return options_; }
  int max_threads() const { return nthreads_; }
  int threads() const;
  const TeamSize::Counts& team_counts() const { return team_.counts(); }
  const StepTimes& step_times() const { return times_; }

  void set_breakage(bool on) { state_.breakage = on; }
  void set_strain_for_log(double strain) { state_.strain_for_log = strain; }
  std::function<void(const Crack&)> on_crack;

 private:
  // A bond that broke this step, with what its crack records: the bond point, the mode, the peripheral stresses.
  struct Break {
    int bond = 0;
    BreakMode mode = BreakMode::none;
    Vec3 p;
    double sigma = 0, tau = 0;
  };
  // Bond b's forces at the state now, with its intact fraction (0 when broken): what step() computes, for the
  // diagnostics (no history advanced).
  stages::FaceBondOut bond_now(std::size_t b, double& keep) const;
  void bond_range(std::size_t b0, std::size_t b1, double dt, bool advance, std::vector<Break>* breaks);
  void log_breaks(const std::vector<std::vector<Break>>& breaks);
  void gather(std::size_t b, Vec3& force, Vec3& moment) const;
  // The blocks [b0, b1): each one's gathered force, its step (the damping's work into damping_work_), its record;
  // false when a position or velocity is no longer finite.
  bool block_range(std::size_t b0, std::size_t b1);
  // Block b's record from the state (every block's after any change of the state from outside the step).
  void refresh_record(std::size_t b);
  void refresh_records();

  EngineOptions options_;
  Model<3> model_;
  ModelState<3> state_;
  std::vector<BoundaryHooks<3>*> hooks_;
  // workspace (derived, never stored)
  std::vector<stages::FaceBondSlot> slot_;  // each bond's forces this step, as the gather reads them
  std::vector<stages::BlockRecord3> record_;  // each block's kinematics at the step's start
  std::vector<Vec3> ext_f_, ext_m_;
  std::vector<double> damping_work_;
  std::vector<std::vector<Break>> breaks_;  // per thread, the bonds it broke this step, ascending
  int nthreads_ = 1;
  TeamSize team_{1, false};
  StepTimes times_;
};

}  // namespace rbdem
