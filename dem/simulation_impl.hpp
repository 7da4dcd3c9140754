// SimulationImpl<dim>: the Simulation interface (dem/simulation.hpp) over the engine of one dimension, its boundary
// components and its static solve. Code that works on the 2D model itself (the verification cases, the reference
// integrator, the tests of the engine) reaches the engine and the topology through it; everything else sees only
// the Simulation.
#pragma once

#include <memory>
#include <vector>

#include "dem/boundary/components.hpp"
#include "dem/engine.hpp"
#include "dem/simulation.hpp"
#include "dem/static_solve.hpp"
#include "dem/topology.hpp"

namespace rbdem {

// The specimen's tables of a 2D topology and its mesh (bond materials from the model). Without a mesh the tables
// hold no nodes and cells (a simulation for measurements, whose results are not written as a run folder).
Specimen describe(const Topology<2>& topo, const TriMesh* mesh, const std::vector<std::uint8_t>& bond_material);

template <int dim>
class SimulationImpl;

template <>
class SimulationImpl<2> final : public Simulation {
 public:
  // The model of `mesh` (its topology built here, at the scene's thickness and density) with the scene's materials
  // and numerics. `engine` adjusts the engine's options (tests: no contacts, other savings).
  SimulationImpl(const Scene& scene, const TriMesh& mesh, const SimulationOptions& options = {},
                 const std::function<void(EngineOptions&)>& engine = nullptr);
  // The same from a topology built already (its specimen has no mesh: see describe()).
  SimulationImpl(const Scene& scene, Topology<2> topology, const SimulationOptions& options = {},
                 const std::function<void(EngineOptions&)>& engine = nullptr);
  SimulationImpl(const SimulationImpl&) = delete;
  SimulationImpl& operator=(const SimulationImpl&) = delete;

  int dimension() const override { return 2; }
  const Specimen& specimen() const override { return specimen_; }

  void step() override { engine_.step(); }
  double dt() const override { return engine_.dt(); }
  void set_dt(double dt) override { engine_.set_dt(dt); }
  double time() const override { return engine_.time(); }
  long steps() const override { return engine_.steps(); }
  double block_step_estimate() const override { return engine_.critical_step(); }
  double stability_limit(int iterations = 300, int threads = 0) const override {
    return rbdem::stability_limit(engine_, iterations, threads);
  }
  int threads() const override { return engine_.threads(); }
  int max_threads() const override { return engine_.max_threads(); }
  TeamSize::Counts team_counts() const override { return engine_.team_counts(); }
  StepTimes step_times() const override { return engine_.step_times(); }
  BlockStates block_states() const override { return engine_.block_states(); }
  BondStates bond_states() const override { return engine_.bond_states(); }
  ContactStates contact_states() const override { return engine_.contact_states(); }
  BoundaryLoads boundary_loads() const override { return engine_.boundary_loads(); }

  Energies energies() const override { return engine_.energies(); }
  const std::vector<Crack>& cracks() const override { return engine_.cracks(); }
  std::string non_finite() const override;
  std::vector<double> pose() const override;
  void set_breakage(bool on) override { engine_.set_breakage(on); }
  void set_strain_for_log(double strain) override { engine_.set_strain_for_log(strain); }
  double lateral_strain() const override;
  double lateral_strain_of(const StaticResult& state) const override;

  Platens& add_platens(const PlatenSettings& settings) override;
  Jacket& add_jacket(double pressure) override;
  BlockGroup& add_group(const GroupSettings& settings) override;

  StaticResult solve_static(const StaticOptions& options = {}) const override {
    return rbdem::solve_static(engine_, options);
  }
  double first_break_along(const StaticResult& base, const StaticResult& increment, int* bond = nullptr) const override;
  std::vector<double> break_factors_along(const StaticResult& base, const StaticResult& increment,
                                          bool mean_strength) const override {
    return rbdem::break_factors_along(engine_, base, increment, mean_strength);
  }
  void apply_static(const StaticResult& base, const StaticResult& increment, double lambda, double velocity) override;
  std::vector<double> pressure_load(double pressure) const override;

  Snapshot snapshot() const override;
  void restore(const Snapshot& snapshot) override;

  // The 2D model itself.
  Engine<2>& engine() { return engine_; }
  const Engine<2>& engine() const { return engine_; }
  const Topology<2>& topology() const { return topology_; }

 private:
  // The specimen's width from its sides: the blocks of the boundary edges tagged left and right, or, for a disc,
  // the rim blocks within a tenth of the height of the horizontal diameter.
  void find_sides();
  template <class C>
  C& install(std::unique_ptr<C> component);

  Topology<2> topology_;  // the engine's model points into it: declared first, never moved
  Engine<2> engine_;
  Specimen specimen_;
  std::vector<int> left_, right_;
  std::vector<std::unique_ptr<Boundary>> components_;
};

}  // namespace rbdem
