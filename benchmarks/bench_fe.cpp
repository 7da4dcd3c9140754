// FE cost per DoF of the continuum model (continuum/fe_model.hpp): setup + assembly + CG/AMG solve of the bonded
// specimen (beta = 60 deg, default cg_tolerance), from about 1e4 to 1e6 DoFs, P1 and P2. Meshing (gmsh) is done once
// per size outside the timed loop; centroid fields are off (fields_seconds is not part of the figure).
//
// Usage:
//   build-fe/benchmarks/bench_fe                                  # all sizes (meshing takes about a minute)
//   build-fe/benchmarks/bench_fe --benchmark_filter='P1/1000$'     # one size: P1, h = 1000 um
//   RBDEM_BENCH_MESH_DIR=/tmp/meshes build-fe/benchmarks/bench_fe   # keep the meshes as .msh between runs
// Counters: dofs, us_per_dof (setup + assemble + solve, per DoF), iterations (CG), and the split
// setup_us_per_dof, assemble_us_per_dof, solve_us_per_dof (of which amg_us_per_dof is the AMG setup).
// BM_FeJointed*: the FE twin with discrete joints (continuum/fe_joints.hpp) on a structured mesh made here, no gmsh:
//   build-fe/benchmarks/bench_fe --benchmark_filter='FeJointed'
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "continuum/fe_joints.hpp"
#include "continuum/fe_model.hpp"
#include "dem/specimen_mesh.hpp"

namespace {

using rbdem::continuum::FeOptions;
using rbdem::continuum::FeResult;

// The paper specimen (50 mm x 100 mm, joints dipping 60 deg every 10 mm) meshed with edge length h_um. With
// RBDEM_BENCH_MESH_DIR set, meshes are kept there as .msh files and read back on later runs (gmsh takes ~20 s at 1e6).
const rbdem::TriMesh& specimen(long h_um) {
  static std::map<long, rbdem::TriMesh> cache;
  auto it = cache.find(h_um);
  if (it == cache.end()) {
    rbdem::SpecimenGeometry g;
    const char* dir = std::getenv("RBDEM_BENCH_MESH_DIR");
    const std::filesystem::path file =
        dir ? std::filesystem::path(dir) / ("specimen_h" + std::to_string(h_um) + "um.msh") : std::filesystem::path();
    if (dir && std::filesystem::exists(file))
      it = cache.emplace(h_um, rbdem::read_msh(file)).first;
    else
      it = cache.emplace(h_um, rbdem::mesh_specimen(g, double(h_um) * 1e-6, file)).first;
  }
  return it->second;
}

const rbdem::theory::TIConstants layered{60e9, 0.2, 25e9, 0.12, 9e9};

// The first CG+AMG call of a process initialises MPI (~0.3 s): pay it before any timing.
void warm_up() {
  static const bool done = [] {
    FeOptions o;
    o.solver = rbdem::continuum::Solver::cg_amg;
    rbdem::continuum::solve_elastic(specimen(4000), layered, 60.0, 1.0, o);
    return true;
  }();
  (void)done;
}

void run(benchmark::State& state, int degree, rbdem::continuum::Assembly assembly,
         rbdem::continuum::Solver solver = rbdem::continuum::Solver::cg_amg) {
  const rbdem::TriMesh& mesh = specimen(state.range(0));
  warm_up();
  FeOptions o;
  o.degree = degree;
  o.platens = rbdem::continuum::Platens::bonded;
  o.solver = solver;
  o.assembly = assembly;
  o.fields = false;
  FeResult r;
  double setup = 0, assemble = 0, solve = 0, amg = 0;
  for (auto _ : state) {
    r = rbdem::continuum::solve_elastic(mesh, layered, 60.0, 1.0, o);
    setup += r.setup_seconds, assemble += r.assemble_seconds, solve += r.solve_seconds;
    amg += r.precondition_seconds;
  }
  const double n = double(state.iterations()) * double(r.dofs) * 1e-6;  // us per DoF
  state.counters["dofs"] = double(r.dofs);
  state.counters["iterations"] = r.iterations;
  state.counters["us_per_dof"] = (setup + assemble + solve) / n;
  state.counters["setup_us_per_dof"] = setup / n;
  state.counters["assemble_us_per_dof"] = assemble / n;
  state.counters["solve_us_per_dof"] = solve / n;  // AMG setup + CG
  state.counters["amg_us_per_dof"] = amg / n;      // AMG setup (or LU factorisation) alone
}

void BM_FeBonded_P1(benchmark::State& state) { run(state, 1, rbdem::continuum::Assembly::affine); }
void BM_FeBonded_P2(benchmark::State& state) { run(state, 2, rbdem::continuum::Assembly::affine); }
void BM_FeBonded_P1_FeValuesAssembly(benchmark::State& state) { run(state, 1, rbdem::continuum::Assembly::fe_values); }
// UMFPACK on the small sizes: where Solver::automatic switches (FeOptions::direct_dof_limit).
void BM_FeBonded_P1_Direct(benchmark::State& state) {
  run(state, 1, rbdem::continuum::Assembly::affine, rbdem::continuum::Solver::direct);
}
void BM_FeBonded_P2_Direct(benchmark::State& state) {
  run(state, 2, rbdem::continuum::Assembly::affine, rbdem::continuum::Solver::direct);
}

// ---- The FE twin with joints (continuum/fe_joints.hpp) -------------------------------------------------------------
// 50 mm x 100 mm structured mesh of square cells of side h = range(0) um, each cut along its "/" diagonal (2 x 50 x
// 100 triangles at 1 mm), and 10 joints dipping 45 deg along the cell diagonals at spacing 15000 um / sqrt 2 =
// 10.6 mm, k_n = 5 E / s, k_s = 2 E / s (isotropic rock, E = 60 GPa, nu = 0.2). Bonded platens, fields off; the
// timed loop is the whole call (split, setup, assembly, solve). Counters as above plus seconds per call, and the
// interface edges and duplicated nodes of the split.
const rbdem::TriMesh& jointed_specimen(long h_um) {
  static std::map<long, rbdem::TriMesh> cache;
  auto it = cache.find(h_um);
  if (it != cache.end()) return it->second;
  const int nx = int(50000 / h_um), ny = 2 * nx, every = int(15000 / h_um);
  const double h = double(h_um) * 1e-6;
  rbdem::TriMesh m;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.nodes.push_back({i * h, j * h});
  auto layer = [&](double ic, double jc) { return int(std::floor((jc - ic + nx + every / 2) / every)); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int n00 = j * (nx + 1) + i, n10 = n00 + 1, n01 = n00 + nx + 1, n11 = n01 + 1;
      m.triangles.push_back({n00, n10, n11});
      m.layer.push_back(layer(i + 2.0 / 3.0, j + 1.0 / 3.0));
      m.triangles.push_back({n00, n11, n01});
      m.layer.push_back(layer(i + 1.0 / 3.0, j + 2.0 / 3.0));
    }
  const int layers = *std::max_element(m.layer.begin(), m.layer.end()) + 1;
  for (int l = 0; l < layers; ++l) m.layer_names.push_back("layer" + std::to_string(l));
  return cache.emplace(h_um, std::move(m)).first->second;
}

void run_jointed(benchmark::State& state, rbdem::continuum::Solver solver) {
  using namespace rbdem::continuum;
  const rbdem::TriMesh& mesh = jointed_specimen(state.range(0));
  const double E = 60e9, s = 15000e-6 / std::sqrt(2.0);
  std::vector<InterfaceEdge> joints;
  for (const auto& [a, b] : layer_interface_edges(mesh)) joints.push_back({a, b, 5 * E / s, 2 * E / s});
  const std::vector<rbdem::theory::TIConstants> rock(mesh.num_layers(), rbdem::theory::TIConstants::isotropic(E, 0.2));
  JointedFeOptions o;
  o.platens = Platens::bonded;
  o.solver = solver;
  o.fields = false;
  static const bool mpi_ready = [&] {  // the first CG+AMG call of a process initialises MPI (~0.3 s)
    JointedFeOptions w = o;
    w.solver = Solver::cg_amg;
    solve_elastic_jointed(jointed_specimen(5000), std::vector<rbdem::theory::TIConstants>(
                                                      jointed_specimen(5000).num_layers(), rock[0]),
                          45, {}, 1.0, w);
    return true;
  }();
  (void)mpi_ready;
  JointedFeResult r;
  double seconds = 0, setup = 0, assemble = 0, solve = 0;
  for (auto _ : state) {
    r = solve_elastic_jointed(mesh, rock, 45.0, joints, 1.0, o);
    seconds += r.seconds, setup += r.setup_seconds, assemble += r.assemble_seconds, solve += r.solve_seconds;
  }
  const double n = double(state.iterations()) * double(r.dofs) * 1e-6;  // us per DoF
  state.counters["dofs"] = double(r.dofs);
  state.counters["triangles"] = double(r.cells);
  state.counters["interface_edges"] = double(r.interface_edges);
  state.counters["duplicated_nodes"] = double(r.duplicated_nodes);
  state.counters["iterations"] = r.iterations;
  state.counters["seconds"] = seconds / double(state.iterations());
  state.counters["us_per_dof"] = seconds / n;
  state.counters["setup_us_per_dof"] = setup / n;  // split, triangulation, DoFs, constraints, sparsity
  state.counters["assemble_us_per_dof"] = assemble / n;
  state.counters["solve_us_per_dof"] = solve / n;
}

void BM_FeJointed(benchmark::State& state) { run_jointed(state, rbdem::continuum::Solver::cg_amg); }
void BM_FeJointed_Direct(benchmark::State& state) { run_jointed(state, rbdem::continuum::Solver::direct); }

// range(0) = target edge length h in um. P1 DoFs ~ 1.2e4 / h_mm^2, P2 ~ 4x that.
BENCHMARK(BM_FeBonded_P1)->Arg(1000)->Arg(330)->Arg(150)->Arg(105)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FeBonded_P2)->Arg(2000)->Arg(660)->Arg(300)->Arg(210)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FeBonded_P1_FeValuesAssembly)->Arg(330)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FeBonded_P1_Direct)->Arg(1000)->Arg(460)->Arg(330)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FeBonded_P2_Direct)->Arg(2000)->Arg(920)->Arg(660)->Unit(benchmark::kMillisecond);
// range(0) = h in um: 1000 is the default specimen at 1 mm (1e4 triangles, 10 joints).
BENCHMARK(BM_FeJointed)->Arg(1000)->Arg(500)->Arg(250)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FeJointed_Direct)->Arg(1000)->Arg(500)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
