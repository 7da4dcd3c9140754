// Simulation: one interface for a DEM model of any dimension. The test driver, the protocols and monitors, the
// summary, the writers, studies, the elastic gate, `rbdem verify`, the command line and the Python module see this
// class and nothing of the engine below it, as MFEM's solvers see an Operator. It is implemented by
// SimulationImpl<dim> (dem/simulation_impl.hpp) over the dimension's engine, model, state, stages and laws
// (templates on dim, dem/dim.hpp): dim = 2 (triangular blocks) and dim = 3 (tetrahedral blocks).
//
// What a simulation offers:
//   stepping      step(), the clock, the time step and the stability limits, the threads a step may use
//   state         energies, the crack log, the block poses, finiteness, snapshot() and restore()
//   boundaries    components a protocol installs (dem/boundary/boundary.hpp): platens, a jacket, block groups;
//                 their forces, static rows, snapshot fields and readings come with them
//   static start  the exact elastic solution of the intact model under the installed boundaries, the load factor
//                 of the first bond failure along a path, and the state set to a point on that path
//   specimen      the dimension-free tables of its mesh, blocks and bonds (dem/specimen.hpp)
// Results are bit-identical at any thread count; a restored snapshot continues bit for bit.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "dem/boundary/boundary.hpp"
#include "dem/records.hpp"
#include "dem/scene.hpp"
#include "dem/snapshot.hpp"
#include "dem/specimen.hpp"
#include "dem/state_tables.hpp"
#include "dem/static_result.hpp"
#include "dem/team.hpp"
#include "mesh/trimesh.hpp"

namespace rbdem {
struct TetMesh;
}

namespace rbdem {

// Thrown when the run blows up (positions no longer finite): the step is too large or the scene unphysical.
class InstabilityError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Energies {
  double kinetic = 0;   // J
  double strain = 0;    // J, stored in bonds, contacts and boundary components
  double damping = 0;   // J, dissipated by local damping (cumulative)
  double friction = 0;  // J, dissipated by sliding contacts (cumulative, approximate)
  double work = 0;      // J, done by the boundary components (cumulative), summed in their order
};

struct SimulationOptions {
  // When set, each step uses min(*thread_budget, numerics.threads) threads (at least one): a sweep hands the cores
  // of its idle workers to the runs still going. Results do not depend on the thread count.
  const std::atomic<int>* thread_budget = nullptr;
};

class Simulation {
 public:
  virtual ~Simulation() = default;
  // The model of `mesh` with the scene's materials and numerics (the dimension follows the mesh).
  static std::unique_ptr<Simulation> create(const Scene& scene, const TriMesh& mesh,
                                            const SimulationOptions& options = {});
  // The 3D model of a tetrahedral mesh (which must outlive the simulation).
  static std::unique_ptr<Simulation> create(const Scene& scene, const TetMesh& mesh,
                                            const SimulationOptions& options = {});

  virtual int dimension() const = 0;
  virtual const Specimen& specimen() const = 0;
  std::size_t num_blocks() const { return specimen().num_blocks(); }
  std::size_t num_bonds() const { return specimen().num_bonds(); }

  // --- time stepping ---
  // One explicit step. Throws InstabilityError when a position is no longer finite.
  virtual void step() = 0;
  void run(long steps) {
    for (long k = 0; k < steps; ++k) step();
  }
  virtual double dt() const = 0;
  virtual void set_dt(double dt) = 0;
  virtual double time() const = 0;
  virtual long steps() const = 0;
  // The block-wise estimate of the critical step (docs/theory.md, section 8), about half the exact limit.
  virtual double block_step_estimate() const = 0;
  // 2 / sqrt(lambda_max(M^-1 K)) of the intact model with every linear part closed and the installed boundaries: the
  // largest stable step of the undamped central difference scheme (power iteration; the same to the last bit at
  // any thread count; threads = 0: threads()).
  virtual double stability_limit(int iterations = 300, int threads = 0) const = 0;
  virtual int threads() const = 0;      // the threads the next step may use (a sweep's budget)
  virtual int max_threads() const = 0;  // the most threads a step may use (numerics.threads)
  // How the team followed the cores free while other processes held some (dem/team.hpp).
  virtual TeamSize::Counts team_counts() const = 0;
  // Where the steps' wall time went so far (dem/team.hpp).
  virtual StepTimes step_times() const = 0;

  // --- what the model holds ---
  virtual Energies energies() const = 0;
  virtual const std::vector<Crack>& cracks() const = 0;
  // Empty when every block's position and velocity is finite, else what is not.
  virtual std::string non_finite() const = 0;
  // The block poses, component-major (Frame::pose: Dim<dim>::pose components).
  virtual std::vector<double> pose() const = 0;
  // The state as tables (copies; dem/state_tables.hpp): the blocks now (their forces of the last step), the
  // bonds' forces now (broken bonds as zero rows), and the pairs in contact now with their forces now (the contact
  // law at the overlap, the shear force as carried): the bond and contact forces the force evaluation gives.
  virtual BlockStates block_states() const = 0;
  virtual BondStates bond_states() const = 0;
  virtual ContactStates contact_states() const = 0;
  // The forces the boundary components put on the blocks now, each at its point (a platen's contact law at the
  // overlap now, a jacket's pressure on the faces as they are now, a group's force or reaction): with the bond and
  // contact rows, every force on each block.
  virtual BoundaryLoads boundary_loads() const = 0;
  // Off: an elastic model in which no bond breaks (tests, stability checks).
  virtual void set_breakage(bool on) = 0;
  // The axial strain the crack log records with new cracks.
  virtual void set_strain_for_log(double strain) = 0;
  // Called for each new crack, after it is logged.
  std::function<void(const Crack&)> on_crack;
  // -(width change) / width of the specimen now, from the blocks of its sides that still hold an intact bond
  // (compression positive; 0 without sides), and the same for the displacements of a static solution.
  virtual double lateral_strain() const = 0;
  virtual double lateral_strain_of(const StaticResult& state) const = 0;

  // --- boundary components, in the order installed (the order their forces are summed) ---
  virtual Platens& add_platens(const PlatenSettings& settings) = 0;
  virtual Jacket& add_jacket(double pressure) = 0;
  virtual BlockGroup& add_group(const GroupSettings& settings) = 0;
  const std::vector<Boundary*>& boundaries() const { return boundaries_; }
  // The first installed component of type B, or null.
  template <class B>
  B* find() const {
    for (Boundary* b : boundaries_)
      if (auto* c = dynamic_cast<B*>(b)) return c;
    return nullptr;
  }

  // --- the static elastic solution of the intact model (the start of a failure run) ---
  virtual StaticResult solve_static(const StaticOptions& options = {}) const = 0;
  // The smallest lambda >= 0 at which some bond reaches its strength along base + lambda x increment (the bond law's
  // failure test), and that bond; +inf when none does. An empty base is the unloaded specimen.
  virtual double first_break_along(const StaticResult& base, const StaticResult& increment,
                                   int* bond = nullptr) const = 0;
  // Every bond's own factor of first_break_along (+inf where it never breaks), in bond order; with `mean_strength`
  // every bond at its material's stated (mean) strength, without the Weibull factor of the heterogeneity. Empty
  // where the dimension does not provide it (3D): its users then fall back on first_break_along.
  virtual std::vector<double> break_factors_along(const StaticResult& /*base*/, const StaticResult& /*increment*/,
                                                  bool /*mean_strength*/) const {
    return {};
  }
  // Puts the model into base + lambda x increment (an empty base: the unloaded specimen), with the velocity field of
  // the increment's platen closing at `velocity`; the linear parts' and platens' shear histories and the top
  // platen's position follow, the clock is set to the time the platen needs for lambda x increment.
  virtual void apply_static(const StaticResult& base, const StaticResult& increment, double lambda,
                            double velocity) = 0;
  // The generalized load of a pressure (Pa) on the jacket's faces in the reference configuration, dof(dim) entries
  // per block, for StaticOptions::load: the same forces as the jacket's stage at rest.
  virtual std::vector<double> pressure_load(double pressure) const = 0;

  // --- snapshot ---
  virtual Snapshot snapshot() const = 0;
  // Throws std::invalid_argument when the snapshot does not fit (another scene, mesh or set of boundaries).
  virtual void restore(const Snapshot& snapshot) = 0;

 protected:
  std::vector<Boundary*> boundaries_;
};

}  // namespace rbdem
