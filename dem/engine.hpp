// The explicit RB-DEM engine of the 2D model: a Model (constant data), a ModelState (the snapshot) and the stages of
// one step (dem/stages/stages.hpp): rigid triangular blocks (x, y, theta), linear parallel bonds on shared edges,
// polygon contacts after breakage and between blocks that were never neighbours, the boundary components attached
// to it (their hooks, dem/boundary/hooks.hpp), central difference time integration with Cundall local damping
// (docs/theory.md, sections 5 to 8; docs/model.md; docs/architecture.md). Code above the engine sees it through
// SimulationImpl<2> (dem/simulation_impl.hpp).
//
// The engine keeps its own invariants: callers read the state, and change it only through restore(), edit()
// (any change to the kinematics, followed by a refresh of everything derived) or the named operations below.
// Results are bit-identical at any thread count.
#pragma once

#include <algorithm>
#include <atomic>
#include <functional>
#include <stdexcept>
#include <vector>

#include "dem/boundary/hooks.hpp"
#include "dem/model.hpp"
#include "dem/scene.hpp"
#include "dem/simulation.hpp"
#include "dem/stages/stages.hpp"
#include "dem/state.hpp"
#include "dem/state_tables.hpp"
#include "dem/team.hpp"
#include "dem/topology.hpp"

namespace rbdem {

struct EngineOptions {
  double damping = 0.7;          // Cundall local damping alpha
  double mass_scaling = 1.0;     // density multiplier
  int threads = 0;               // 0 = all; the most the run may use
  // When set, each step uses min(*thread_budget, threads) threads (at least one): a sweep hands the cores of its
  // idle workers to the runs still going. Results do not depend on the thread count.
  const std::atomic<int>* thread_budget = nullptr;
  // Shrink the team while other processes hold the cores, and grow it back when they leave (dem/team.hpp). Off:
  // the team keeps its size (benchmarks of a fixed thread count). The environment variable RBDEM_ADAPT_THREADS=0
  // switches it off for every run.
  bool adapt_threads = true;
  bool contacts = true;          // false: no block-block contacts (diagnostics)
  bool skip_bonded_pairs = true;       // numerics.skip_bonded_pairs: no narrow phase for intact-bonded pairs
  bool search_free_faces_only = true;  // numerics.search_free_faces_only: broad phase over free-face blocks only
  bool update_after_breaks = true;     // numerics.update_after_breaks: contact lists updated after bond breaks

  static EngineOptions from_scene(const Scene& scene);
};

// The forces of one bond in its co-rotated frame (diagnostics, static comparisons, energies).
struct BondForces {
  double fn_b = 0, fs_b = 0, m_b = 0;  // parallel bond: normal (compression positive), shear, moment on j
  double fn_lin = 0, fs_lin = 0;       // linear part
  double sigma = 0, tau = 0;           // parallel bond peripheral stresses (tension positive)
};

template <int dim>
class Engine;

template <>
class Engine<2> {
 public:
  Engine(const Topology<2>& topo, const Scene& scene, const EngineOptions& options);

  // --- stepping ---
  void step();
  void run(long steps) {
    for (long k = 0; k < steps; ++k) step();
  }
  void set_dt(double dt) { state_.dt = dt; }
  double dt() const { return state_.dt; }
  // Block-wise estimate of the critical step (docs/theory.md, section 8): min over blocks of sqrt(m / k_trans) and
  // sqrt(I / k_rot), the attached components' stiffness included. About half the exact limit of the lattice
  // (stability_limit() in static_solve.hpp).
  double critical_step() const;

  // --- the model and its state ---
  const Model<2>& model() const { return model_; }
  const ModelState<2>& state() const { return state_; }
  const Topology<2>& topology() const { return *model_.topology; }
  // Replaces the state by a snapshot of a run of the same scene and topology. Throws std::invalid_argument when it
  // does not fit (another scene or mesh).
  void restore(const ModelState<2>& s);
  // Changes the state through `change`, then refreshes everything derived from it (rotations, bond damage, the
  // pair list at the next step). For placing blocks (the static start, tests) and similar set-ups.
  void edit(const std::function<void(ModelState<2>&)>& change);
  // Breaks bond b now (tests, prepared specimens): its pair becomes a contact that carries the linear part on.
  void break_bond(int b);
  // Fixes block b in place (the integrator keeps its state: block groups, tests), or frees it again; sets a block's
  // mass and inertia (tests).
  void fix_block(int b, bool fixed = true);
  void set_block_mass(int b, double mass, double inertia);
  // A boundary component's hooks, called after those attached before (their forces are summed in that order). The
  // component must outlive the engine.
  void attach(BoundaryHooks<2>* hooks);
  const stages::Hooks& hooks() const { return hooks_; }

  // --- forces without stepping (reference integrators, compare/reference_integrator.hpp) ---
  // The generalized force (F_x, F_y, M) on every block at the current state, through the same stages as step()
  // (bonds, contacts, the components, gathered in step()'s fixed order), without advancing time, any history or
  // any energy account. The pair list is refreshed when blocks moved more than half a skin. Shear histories enter
  // as they are: the forces are a function of the positions and velocities alone when no shear history is carried
  // (frictionless contacts and platens, linear parts that cannot stick: see check_reference_scope).
  void evaluate_forces(std::vector<double>& fx, std::vector<double>& fy, std::vector<double>& moment);

  // --- diagnostics ---
  BondForces bond_forces(int bond) const;  // the forces of a bond in the current state
  // The state as dimension-free tables (dem/state_tables.hpp; engine_tables.cpp).
  BlockStates block_states() const;
  BondStates bond_states() const;
  ContactStates contact_states() const;
  BoundaryLoads boundary_loads() const;  // the attached components' loads, in their order
  Energies energies() const;
  std::size_t active_contacts() const;
  const EngineOptions& options() const { return options_; }
  int max_threads() const { return nthreads_; }  // the most threads a step may use
  // The threads of the next parallel stage: the team's size (fewer while other processes hold the cores,
  // dem/team.hpp), and with a budget no more than it, so that no team is ever larger than the cores the sweep gave
  // the run (idle extra threads make libgomp stop spinning and wake slowly). Work beside the steps (the stability
  // limit, the static start) uses it too.
  int threads() const {
    const int n = team_.size();
    return options_.thread_budget ? std::clamp(options_.thread_budget->load(std::memory_order_relaxed), 1, n) : n;
  }
  // How the team's size followed the cores free (windows measured, shrinks, probes).
  const TeamSize::Counts& team_counts() const { return team_.counts(); }
  // Where the steps' time went, on the thread that calls step().
  const StepTimes& step_times() const { return times_; }
  // How the bonds and blocks are split among the threads. The split follows the threads' measured speed and no
  // result depends on it; tests move it to check that.
  Workspace<2>::Partition& partition() { return work_.part; }
  // The broad phase's grid and how often it was rebuilt and updated (diagnostics, tests).
  const Workspace<2>::BroadGrid& broad_phase() const { return work_.grid; }

  // Convenience reads of the state.
  double time() const { return state_.time; }
  long steps() const { return state_.steps; }
  const std::vector<Crack>& cracks() const { return state_.cracks; }

  // --- what the driver controls ---
  void set_breakage(bool on) { state_.breakage = on; }  // off: an elastic lattice (tests, stability checks)
  void set_strain_for_log(double strain) { state_.strain_for_log = strain; }
  // Called for each new crack (after it is logged).
  std::function<void(const Crack&)> on_crack;

 private:
  StepContext context(bool advance) const;
  void refresh();

  EngineOptions options_;
  Model<2> model_;
  ModelState<2> state_;
  Workspace<2> work_;
  stages::Hooks hooks_;
  stages::DetectionOptions detection_;
  int nthreads_ = 1;  // the most threads the run may use
  TeamSize team_{1, false};
  StepTimes times_;
  std::vector<ThreadBusy> busy_;  // per thread: this step's busy time per phase
};

}  // namespace rbdem
