// The bond kernels alone, one core: nanoseconds per bond-step of the 3D face bond (BM_FaceBond3D: the kinematics in
// the co-rotated face frame, the parallel bond, the linear part on the triangle and the forces on both blocks,
// dem/stages/face_bond_kernel.hpp) on a few thousand random tetrahedron pairs, beside the 2D edge bond's scalar
// kernel (BM_EdgeBond2D: eval_bond of dem/stages/bond_kernel.hpp) on the paper's default specimen. Both loops call
// the kernel once per bond and sum the forces, so that nothing is optimised away; the engine's 2D bond stage runs
// the same kernel in vector lanes (bench_engine's BM_EngineStep measures a whole step).
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "dem/simulation_impl.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/stages/bond_kernel.hpp"
#include "dem/stages/face_bond_kernel.hpp"
#include "dem/topology.hpp"

namespace {

using namespace rbdem;

// The time per bond-step of `n` bonds per iteration (CPU time, as Google Benchmark's rates).
benchmark::Counter per_bond_step(int n, const benchmark::State& state) {
  return benchmark::Counter(double(n) * double(state.iterations()),
                            benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// `n` bonds on random faces (edges of 0.5 to 1.5 mm) between a tetrahedron below and one above, each pair strained
// by a random relative motion of up to 1e-7 m and 1e-4 rad (the linear part closed on some, open or partly open on
// the others), with moving blocks.
struct FaceBonds {
  std::vector<stages::FaceBondFrame> frame;
  std::vector<stages::BlockKin3> bi, bj;
  std::vector<double> fs1, fs2;
  explicit FaceBonds(int n) {
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    auto vec = [&](double s) { return Vec3{s * u(rng), s * u(rng), s * u(rng)}; };
    const FaceBond law{1.0 / 2.5, {10e6, 20e6, 0.5, 1.0}, 0.0};
    for (int b = 0; b < n; ++b) {
      const Tri face{
          {Vec3{0, 0, 0} + vec(0.2e-3), Vec3{1e-3, 0, 0} + vec(0.3e-3), Vec3{0.3e-3, 1e-3, 0} + vec(0.3e-3)}};
      const Vec3 mid = (1.0 / 3.0) * ((face[0] + face[1]) + face[2]);
      const Vec3 ci = mid + Vec3{0, 0, -0.25e-3} + vec(0.1e-3), cj = mid + Vec3{0, 0, 0.25e-3} + vec(0.1e-3);
      frame.push_back(stages::face_bond_frame(ci, cj, face, law, 10e9, 0.6));
      const Quat q = from_rotation_vector(vec(0.5));  // the pair's common rotation
      bi.push_back({rotate(q, ci), q, vec(1e-3), vec(1.0)});
      bj.push_back({rotate(q, cj) + vec(1e-7), q * from_rotation_vector(vec(1e-4)), vec(1e-3), vec(1.0)});
    }
    fs1.assign(std::size_t(n), 0.0), fs2.assign(std::size_t(n), 0.0);
  }
};

void BM_FaceBond3D(benchmark::State& state) {
  const int n = int(state.range(0));
  FaceBonds bonds(n);
  double sum = 0;
  for (auto _ : state) {
    for (std::size_t b = 0; b < std::size_t(n); ++b) {
      const stages::FaceBondEval ev =
          stages::eval_face_bond(bonds.frame[b], bonds.bi[b], bonds.bj[b], 1e-8, bonds.fs1[b], bonds.fs2[b], 1.0);
      bonds.fs1[b] = ev.linear.fs1, bonds.fs2[b] = ev.linear.fs2;
      sum += ev.f.x + ev.mi.y + ev.mj.z;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.counters["bonds"] = n;
  state.counters["ns_per_bond_step"] = per_bond_step(n, state);
}
BENCHMARK(BM_FaceBond3D)->Arg(4096)->Unit(benchmark::kMicrosecond);

void BM_EdgeBond2D(benchmark::State& state) {
  Scene scene;
  scene.numerics.threads = 1;
  const Topology<2> topo = build_topology(make_mesh(scene), scene.specimen.thickness, scene.rock.density);
  SimulationImpl<2> sim(scene, topo, SimulationOptions{});
  sim.add_platens({scene.loading.platen_velocity, scene.loading.platen_friction});
  sim.run(200);  // strained bonds, as the 3D ones
  const Engine<2>& e = sim.engine();
  Workspace<2> w;
  stages::update_rotations(e.state(), w, 1);
  const stages::BondArrays a(e.model(), e.state(), w);
  const int n = int(e.model().num_bonds());
  double sum = 0;
  for (auto _ : state) {
    for (int b = 0; b < n; ++b) {
      const stages::BondEval ev = stages::eval_bond(a, b, a.block(a.bi[b]), a.block(a.bj[b]), 1e-8, 0.0, 1.0);
      sum += ev.fx + ev.mi + ev.mj;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.counters["bonds"] = n;
  state.counters["ns_per_bond_step"] = per_bond_step(n, state);
}
BENCHMARK(BM_EdgeBond2D)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
