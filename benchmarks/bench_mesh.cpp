// Meshing cost of the paper specimen: gmsh time and topology build time versus mesh size.
#include <benchmark/benchmark.h>

#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"

namespace {

void BM_MeshSpecimen(benchmark::State& state) {
  const double h = 1e-3 / double(state.range(0));  // range(0) = 1/h in 1/mm
  rbdem::SpecimenGeometry g;
  g.dip_deg = 60.0;
  std::size_t blocks = 0;
  for (auto _ : state) {
    auto mesh = rbdem::mesh_specimen(g, h);
    blocks = mesh.num_triangles();
    benchmark::DoNotOptimize(mesh);
  }
  state.counters["blocks"] = double(blocks);
}
BENCHMARK(BM_MeshSpecimen)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_BuildTopology(benchmark::State& state) {
  rbdem::SpecimenGeometry g;
  g.dip_deg = 60.0;
  const auto mesh = rbdem::mesh_specimen(g, 1e-3 / double(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(rbdem::build_topology(mesh, 1.0, 2700.0));
  state.counters["blocks"] = double(mesh.num_triangles());
}
BENCHMARK(BM_BuildTopology)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
