// Explicit engine throughput on the paper's default specimen (1 mm mesh, beta = 60 deg): nanoseconds per
// bond-step and bond-steps per second, at 1 and 2 threads, for the elastic phase (intact bonds, platens loading).
// The steps run through the Simulation interface with the platens installed as a protocol installs them.
#include <benchmark/benchmark.h>

#include <omp.h>

#include <atomic>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "dem/simulation_impl.hpp"
#include "dem/simulation_impl3.hpp"
#include "dem/specimen_mesh3.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"
#include "mesh/block_order.hpp"

namespace {

// The paper specimen meshed at `mesh_size` (m), its blocks in `order` (mesh.block_order), built once per size and
// order.
const rbdem::Topology<2>& topology(double mesh_size, const std::string& order = "mesh") {
  static std::map<std::pair<double, std::string>, rbdem::Topology<2>> cache;
  auto it = cache.find({mesh_size, order});
  if (it == cache.end()) {
    rbdem::Scene s;
    s.mesh.size = mesh_size;
    s.mesh.block_order = order;
    it = cache.emplace(std::pair{mesh_size, order},
                       rbdem::build_topology(rbdem::make_mesh(s), s.specimen.thickness, s.rock.density))
             .first;
  }
  return it->second;
}

const rbdem::Topology<2>& default_topology() { return topology(rbdem::Scene{}.mesh.size); }

// The simulation of `scene` on `topo`, with the platens of a compression test. Its team keeps the thread count
// asked for (a run shrinks it while other processes hold the cores: dem/team.hpp), so that a row measures that count.
std::unique_ptr<rbdem::SimulationImpl<2>> simulation(const rbdem::Scene& scene, const rbdem::Topology<2>& topo,
                                                     bool adapt = false) {
  auto sim = std::make_unique<rbdem::SimulationImpl<2>>(scene, topo, rbdem::SimulationOptions{},
                                                        [adapt](rbdem::EngineOptions& o) { o.adapt_threads = adapt; });
  sim->add_platens({scene.loading.platen_velocity, scene.loading.platen_friction});
  return sim;
}

// One engine step of `scene` on the default specimen (or `topo`), at state.range(0) threads.
void engine_steps(benchmark::State& state, rbdem::Scene scene, const rbdem::Topology<2>* topo_in = nullptr,
                  bool adapt = false) {
  scene.numerics.threads = int(state.range(0));
  const auto& topo = topo_in ? *topo_in : default_topology();
  const auto impl = simulation(scene, topo, adapt);
  rbdem::Simulation& sim = *impl;
  sim.set_dt(0.5 * sim.stability_limit());
  sim.run(200);  // warm-up: platen contacts formed, caches warm
  const long steps = 500;
  for (auto _ : state) sim.run(steps);
  const double bond_steps = double(topo.bonds.size()) * double(steps) * double(state.iterations());
  state.counters["bonds"] = double(topo.bonds.size());
  state.counters["ns_per_bond_step"] =
      benchmark::Counter(bond_steps, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["bond_steps_per_s"] = benchmark::Counter(bond_steps, benchmark::Counter::kIsRate);
}

void BM_EngineStep(benchmark::State& state) { engine_steps(state, rbdem::Scene{}); }
BENCHMARK(BM_EngineStep)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

// The same with the team that follows the free cores, as runs have it (dem/team.hpp): on an idle machine its cost
// is the measurement of the run delay, once per 50 ms per thread.
void BM_EngineStepAdaptive(benchmark::State& state) { engine_steps(state, rbdem::Scene{}, nullptr, true); }
BENCHMARK(BM_EngineStepAdaptive)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

// The same step on the paper specimen meshed at state.range(1) tenths of a millimetre (3, 1, 0.5 mm: about 2 000,
// 20 000 and 78 000 bonds): how the cost per bond-step and the two-thread gain change as the arrays outgrow the
// caches (docs/performance.md, "Growth with size").
void BM_EngineStepSize(benchmark::State& state) {
  const rbdem::Scene scene;
  engine_steps(state, scene, &topology(1e-4 * double(state.range(1))));
}
BENCHMARK(BM_EngineStepSize)
    ->ArgsProduct({{1, 2}, {30, 10, 5}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

// The same with the blocks along a Hilbert curve (mesh.block_order = "hilbert"; docs/performance.md, "The order of
// the blocks").
void BM_EngineStepSizeHilbert(benchmark::State& state) {
  const rbdem::Scene scene;
  engine_steps(state, scene, &topology(1e-4 * double(state.range(1)), "hilbert"));
}
BENCHMARK(BM_EngineStepSizeHilbert)
    ->ArgsProduct({{1, 2}, {30, 10, 5}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

// The same with the seed paper's brittle bonds (fracture_energy = 0: no bond ever enters the softened list).
void BM_EngineStepBrittle(benchmark::State& state) {
  rbdem::Scene scene;
  scene.rock.fracture_energy = scene.joint.fracture_energy = 0.0;
  engine_steps(state, scene);
}
BENCHMARK(BM_EngineStepBrittle)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

// The exact stability limit (300 power iterations on the assembled stiffness), at state.range(0) threads.
void BM_StabilityLimit(benchmark::State& state) {
  rbdem::Scene scene;
  scene.numerics.threads = int(state.range(0));
  const auto sim = simulation(scene, default_topology());
  for (auto _ : state) benchmark::DoNotOptimize(sim->stability_limit());
}
BENCHMARK(BM_StabilityLimit)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The static start's solve (the active-set iterations: LDLT, then BiCGSTAB preconditioned by it) at
// state.range(0) threads for the products and the triangular solves.
void BM_StaticSolve(benchmark::State& state) {
  rbdem::Scene scene;
  const auto sim = simulation(scene, default_topology());
  const std::atomic<int> threads{int(state.range(0))};
  rbdem::StaticOptions options;
  options.threads = &threads;
  for (auto _ : state) benchmark::DoNotOptimize(sim->solve_static(options));
  state.counters["dofs"] = double(3 * sim->num_blocks());
}
BENCHMARK(BM_StaticSolve)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

// The 3D engine on the paper's cylinder (50 x 100 mm, joints at 60 deg every 10 mm) meshed in tetrahedra of 4 mm
// (about 18,000 blocks and 35,000 face bonds), its blocks in `order`: the elastic phase with the platens loading,
// at state.range(0) threads. The counters bonds_ns, serial_ns and blocks_ns split the wall time per bond-step by the
// engine's stages (Engine<3>::step_times: the bond stage, the serial part with the platens, the gather and the rigid
// step).
void engine_steps3(benchmark::State& state, const std::string& order) {
  static std::map<std::string, rbdem::TetMesh> meshes;
  if (!meshes.count(order)) {
    rbdem::SpecimenGeometry3 g;
    g.set1.dip_deg = 60;
    rbdem::TetMesh m = rbdem::mesh_specimen3(g, 0.004);
    rbdem::apply_block_order(m, order);
    meshes.emplace(order, std::move(m));
  }
  const rbdem::TetMesh& mesh = meshes.at(order);
  rbdem::Scene scene;
  scene.numerics.threads = int(state.range(0));
  rbdem::SimulationImpl<3> sim(scene, mesh, {}, [](rbdem::EngineOptions& o) { o.adapt_threads = false; });
  sim.add_platens({scene.loading.platen_velocity, scene.loading.platen_friction});
  sim.set_dt(0.7 * sim.block_step_estimate() / 0.35);  // about 0.7 x the exact limit (the estimate is about a third)
  sim.set_dt(std::min(sim.dt(), 0.7 * sim.stability_limit(100)));
  sim.run(100);
  const long steps = 100;
  const rbdem::StepTimes t0 = sim.engine().step_times();
  for (auto _ : state) sim.run(steps);
  const double bond_steps = double(sim.num_bonds()) * double(steps) * double(state.iterations());
  const rbdem::StepTimes& t = sim.engine().step_times();
  state.counters["bonds_ns"] = 1e9 * (t.bonds - t0.bonds) / bond_steps;
  state.counters["serial_ns"] = 1e9 * (t.serial - t0.serial) / bond_steps;
  state.counters["blocks_ns"] = 1e9 * (t.blocks - t0.blocks) / bond_steps;
  state.counters["blocks"] = double(sim.num_blocks());
  state.counters["bonds"] = double(sim.num_bonds());
  state.counters["ns_per_bond_step"] =
      benchmark::Counter(bond_steps, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["bond_steps_per_s"] = benchmark::Counter(bond_steps, benchmark::Counter::kIsRate);
}
void BM_EngineStep3D(benchmark::State& state) { engine_steps3(state, "mesh"); }
BENCHMARK(BM_EngineStep3D)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

// The same with the tetrahedra along a Hilbert curve (mesh.block_order = "hilbert").
void BM_EngineStep3DHilbert(benchmark::State& state) { engine_steps3(state, "hilbert"); }
BENCHMARK(BM_EngineStep3DHilbert)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

BENCHMARK_MAIN();
