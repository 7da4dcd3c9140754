// Explicit engine throughput on the paper's default specimen (1 mm mesh, beta = 60 deg): nanoseconds per
// bond-step and bond-steps per second, at 1 and 2 threads, for the elastic phase (intact bonds, platens loading).
#include <benchmark/benchmark.h>

#include <omp.h>

#include "dem/engine.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/static_solve.hpp"
#include "dem/topology.hpp"

namespace {

const rbdem::Topology& default_topology() {
  static const rbdem::Topology topo = [] {
    rbdem::Scene s;
    return rbdem::build_topology(rbdem::make_mesh(s), s.specimen.thickness, s.rock.density);
  }();
  return topo;
}

// One engine step of `scene` on the default specimen, at state.range(0) threads.
void engine_steps(benchmark::State& state, rbdem::Scene scene) {
  scene.numerics.threads = int(state.range(0));
  const auto& topo = default_topology();
  rbdem::Engine engine(topo, scene, rbdem::EngineOptions::from_scene(scene));
  engine.set_dt(0.5 * rbdem::stability_limit(engine));
  engine.run(200);  // warm-up: platen contacts formed, caches warm
  const long steps = 500;
  for (auto _ : state) engine.run(steps);
  const double bond_steps = double(topo.bonds.size()) * double(steps) * double(state.iterations());
  state.counters["bonds"] = double(topo.bonds.size());
  state.counters["ns_per_bond_step"] =
      benchmark::Counter(bond_steps, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["bond_steps_per_s"] = benchmark::Counter(bond_steps, benchmark::Counter::kIsRate);
}

void BM_EngineStep(benchmark::State& state) { engine_steps(state, rbdem::Scene{}); }
BENCHMARK(BM_EngineStep)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

// The same with the seed paper's brittle bonds (fracture_energy = 0: no bond ever enters the softened list).
void BM_EngineStepBrittle(benchmark::State& state) {
  rbdem::Scene scene;
  scene.rock.fracture_energy = scene.joint.fracture_energy = 0.0;
  engine_steps(state, scene);
}
BENCHMARK(BM_EngineStepBrittle)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

void BM_StabilityLimit(benchmark::State& state) {
  rbdem::Scene scene;
  const auto& topo = default_topology();
  rbdem::Engine engine(topo, scene, rbdem::EngineOptions::from_scene(scene));
  for (auto _ : state) benchmark::DoNotOptimize(rbdem::stability_limit(engine));
}
BENCHMARK(BM_StabilityLimit)->Unit(benchmark::kMillisecond);

void BM_StaticSolve(benchmark::State& state) {
  rbdem::Scene scene;
  const auto& topo = default_topology();
  rbdem::Engine engine(topo, scene, rbdem::EngineOptions::from_scene(scene));
  for (auto _ : state) benchmark::DoNotOptimize(rbdem::solve_static(engine));
  state.counters["dofs"] = double(3 * topo.blocks.size());
}
BENCHMARK(BM_StaticSolve)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
