// SimulationImpl<3>: the Simulation interface (dem/simulation.hpp) over the 3D engine (dem/engine3.hpp), its
// platens, its jacket and its static start (dem/static_start3.hpp). Block groups are not built in 3D: installing one
// throws SceneError naming what is missing.
#pragma once

#include <memory>
#include <vector>

#include "dem/boundary/components3.hpp"
#include "dem/engine3.hpp"
#include "dem/simulation.hpp"

namespace rbdem {

// The specimen's tables of a 3D model and its mesh.
Specimen describe(const Model<3>& model, const TetMesh& mesh, double density);

template <int dim>
class SimulationImpl;

template <>
class SimulationImpl<3> final : public Simulation {
 public:
  SimulationImpl(const Scene& scene, const TetMesh& mesh, const SimulationOptions& options = {},
                 const std::function<void(EngineOptions&)>& engine = nullptr);
  SimulationImpl(const SimulationImpl&) = delete;
  SimulationImpl& operator=(const SimulationImpl&) = delete;

  int dimension() const override { return 3; }
  const Specimen& specimen() const override { return specimen_; }

  void step() override { engine_.step(); }
  double dt() const override { return engine_.dt(); }
  void set_dt(double dt) override { engine_.set_dt(dt); }
  double time() const override { return engine_.time(); }
  long steps() const override { return engine_.steps(); }
  double block_step_estimate() const override { return engine_.critical_step(); }
  double stability_limit(int iterations = 300, int threads = 0) const override;
  int threads() const override { return engine_.threads(); }
  int max_threads() const override { return engine_.max_threads(); }
  TeamSize::Counts team_counts() const override { return engine_.team_counts(); }
  StepTimes step_times() const override { return engine_.step_times(); }
  BlockStates block_states() const override { return engine_.block_states(); }
  BondStates bond_states() const override { return engine_.bond_states(); }
  ContactStates contact_states() const override;
  BoundaryLoads boundary_loads() const override { return engine_.boundary_loads(); }

  Energies energies() const override { return engine_.energies(); }
  const std::vector<Crack>& cracks() const override { return engine_.cracks(); }
  std::string non_finite() const override;
  std::vector<double> pose() const override;
  void set_breakage(bool on) override { engine_.set_breakage(on); }
  void set_strain_for_log(double strain) override { engine_.set_strain_for_log(strain); }
  // -(mean radial displacement / radius) of the blocks on the lateral surface that hold an intact bond
  // (compression positive): the lateral strain of a cylinder, and of a prism on average over its sides.
  double lateral_strain() const override;
  double lateral_strain_of(const StaticResult& state) const override;

  Platens& add_platens(const PlatenSettings& settings) override;
  Jacket& add_jacket(double pressure) override;
  BlockGroup& add_group(const GroupSettings& settings) override;

  StaticResult solve_static(const StaticOptions& options = {}) const override;
  double first_break_along(const StaticResult& base, const StaticResult& increment, int* bond = nullptr) const override;
  void apply_static(const StaticResult& base, const StaticResult& increment, double lambda, double velocity) override;
  std::vector<double> pressure_load(double pressure) const override;

  Snapshot snapshot() const override;
  void restore(const Snapshot& snapshot) override;

  Engine<3>& engine() { return engine_; }
  const Engine<3>& engine() const { return engine_; }

 private:
  template <class C>
  C& install(std::unique_ptr<C> component);

  Engine<3> engine_;
  std::unique_ptr<BlockContacts3> contacts_;  // attached first: its forces are summed before the components'
  Specimen specimen_;
  std::vector<int> lateral_;  // blocks with a face on the lateral surface, ascending
  std::vector<std::unique_ptr<Boundary>> components_;
};

}  // namespace rbdem
