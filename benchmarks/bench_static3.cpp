// The 3D static solves on the jointed cylinder (50 x 100 mm, joints at 60 deg, dem/specimen_mesh3.hpp) meshed in
// tetrahedra of h mm: the elastic network's solve (solve_static3, dem/static3.hpp) by each sparse solver, and the
// static start of a 3D run (solve_static, dem/static_start3.hpp: the active set of the linear parts and the first
// break along it). docs/performance.md, "The 3D static solve".
//
// The machine these run on is often shared, so beside the wall time (UseRealTime) each row reports cpu_s, the
// process's CPU seconds per iteration (all threads; the BLAS and Eigen may run their own): the comparable number
// when other processes hold the cores. The mesh is built once per size, outside the timed loop.
//   build/benchmarks/bench_static3 --benchmark_filter='h_mm:12'       (the quick check, 6 s)
//   build/benchmarks/bench_static3 --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <ctime>
#include <map>

#include "dem/simulation_impl3.hpp"
#include "dem/specimen_mesh3.hpp"
#include "dem/static3.hpp"
#include "dem/static_start3.hpp"

namespace {

using rbdem::Static3Solver;

// The jointed cylinder at mesh size h_mm, built once per size; joints 25 mm apart where the 10 mm of the paper's
// scene are thinner than the tets (as tests/test_static3_solver.cpp meshes it).
const rbdem::TetMesh& cylinder(long h_mm) {
  static std::map<long, rbdem::TetMesh> cache;
  auto it = cache.find(h_mm);
  if (it == cache.end()) {
    rbdem::SpecimenGeometry3 g;
    g.set1.dip_deg = 60;
    const double h = 1e-3 * double(h_mm);
    if (h > g.set1.spacing) g.set1.spacing = 0.025;
    it = cache.emplace(h_mm, rbdem::mesh_specimen3(g, h)).first;
  }
  return it->second;
}

// The process's CPU seconds, every thread's.
double cpu_seconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

// The solver of state.range(0), or false (the row skipped) where this build has no CHOLMOD.
bool pick_solver(benchmark::State& state, Static3Solver& s) {
  s = Static3Solver(state.range(0));
  state.SetLabel(rbdem::solver_name(s));
  if (s == Static3Solver::cholmod && !rbdem::cholmod_available()) {
    state.SkipWithError("built without CHOLMOD (RBDEM_WITH_CHOLMOD)");
    return false;
  }
  return true;
}

// One solve of the elastic network by the solver state.range(0) on the cylinder of state.range(1) mm: assembly and
// solve, as `rbdem elastic` does it per dip. Counters: dofs, CG's iterations, CHOLMOD's factor (nonzeros of L and
// operations; 0 for the others), the solve's own split of its wall time (assemble_s, solve_s), cpu_s.
void BM_Static3Solve(benchmark::State& state) {
  Static3Solver s;
  if (!pick_solver(state, s)) return;
  const rbdem::TetMesh& mesh = cylinder(state.range(1));
  rbdem::Static3Options o;
  o.solver = s;
  rbdem::Static3Result r;
  double assemble = 0, solve = 0;
  const double c0 = cpu_seconds();
  for (auto _ : state) {
    r = rbdem::solve_static3(mesh, o);
    assemble += r.assemble_seconds, solve += r.solve_seconds;
  }
  const double cpu = cpu_seconds() - c0;
  state.counters["cpu_s"] = benchmark::Counter(cpu, benchmark::Counter::kAvgIterations);
  state.counters["assemble_s"] = benchmark::Counter(assemble, benchmark::Counter::kAvgIterations);
  state.counters["solve_s"] = benchmark::Counter(solve, benchmark::Counter::kAvgIterations);
  state.counters["blocks"] = double(r.blocks);
  state.counters["dofs"] = double(r.dofs);
  state.counters["cg_it"] = r.iterations;
  state.counters["L_nonzeros"] = r.factor_nonzeros;
  state.counters["flops"] = r.factor_flops;
}
// Arguments: the solver, the mesh size in mm. The LDLT's fill on tetrahedra costs minutes at 4 mm (113,000 dofs):
// it runs at the coarse sizes only.
BENCHMARK(BM_Static3Solve)
    ->ArgNames({"solver", "h_mm"})
    ->Args({int(Static3Solver::cg), 12})
    ->Args({int(Static3Solver::cholmod), 12})
    ->Args({int(Static3Solver::ldlt), 12})
    ->Args({int(Static3Solver::cg), 6})
    ->Args({int(Static3Solver::cholmod), 6})
    ->Args({int(Static3Solver::ldlt), 6})
    ->Args({int(Static3Solver::cg), 4})
    ->Args({int(Static3Solver::cholmod), 4})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The static start of a 3D run on the cylinder of state.range(1) mm between frictionless platens, by the solver
// state.range(0): the all-closed stiffness factorised once, each later active set solved by CG preconditioned with
// that factor (by CG + incomplete Cholesky afresh for the solver cg). Counters: active-set and CG iterations, the
// linear parts left open, the first break's load factor (the same for every solver), cpu_s.
void BM_Static3Start(benchmark::State& state) {
  Static3Solver s;
  if (!pick_solver(state, s)) return;
  rbdem::Scene scene;
  scene.numerics.threads = 1;
  rbdem::SimulationImpl<3> sim(scene, cylinder(state.range(1)));
  sim.add_platens({0.0, 0.0});
  rbdem::StaticOptions so;
  so.platen_displacement = 1e-6 * sim.specimen().height();
  rbdem::StaticResult r;
  const double c0 = cpu_seconds();
  for (auto _ : state) r = rbdem::solve_static(sim.engine(), so, s);
  state.counters["cpu_s"] = benchmark::Counter(cpu_seconds() - c0, benchmark::Counter::kAvgIterations);
  state.counters["blocks"] = double(sim.num_blocks());
  state.counters["dofs"] = double(r.dofs);
  state.counters["active_sets"] = r.active_set_iterations;
  state.counters["cg_it"] = r.krylov_iterations;
  state.counters["open"] = double(r.open_bonds);
  state.counters["first_break"] = r.first_break_factor;
}
// CG + incomplete Cholesky takes minutes at 4 mm (a fresh iteration per active set), the LDLT's factorisation too:
// at 4 mm CHOLMOD alone runs.
BENCHMARK(BM_Static3Start)
    ->ArgNames({"solver", "h_mm"})
    ->ArgsProduct({{int(Static3Solver::cg), int(Static3Solver::cholmod), int(Static3Solver::ldlt)}, {12, 6}})
    ->Args({int(Static3Solver::cholmod), 4})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
