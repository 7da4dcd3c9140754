// One test case. See run_case.hpp.
#include "io/run_case.hpp"

#include <algorithm>

#include "dem/driver/registry.hpp"
#include "dem/mesh_cache.hpp"
#include "io/results.hpp"

namespace rbdem::io {

CaseRun run_case(const std::string& test, const Scene& scene, const CaseOptions& options) {
  protocol_info(test).check(scene);  // before meshing: a scene that does not suit the test costs nothing
  CaseRun out;
  Scene run_scene = scene;
  if (options.threads > 0) run_scene.numerics.threads = options.threads;
  const auto ready = [&](const Simulation& sim) {
    out.specimen = sim.specimen();
    if (options.ready) options.ready(sim, out.mesh_cached);
  };
  if (scene.specimen.dimension == 3) {  // tetrahedral blocks
    const TetMesh mesh = make_mesh3_cached(run_scene, &out.mesh_cached);
    out.result = run_test(test, run_scene, mesh, options.run, ready);
  } else {
    const TriMesh mesh = make_mesh_cached(run_scene, &out.mesh_cached);
    out.result = run_test(test, run_scene, mesh, options.run, ready);
  }
  if (!options.out.empty()) {
    const int threads = options.write_threads ? std::max(1, options.write_threads()) : out.result.threads;
    write_run(options.out, scene, out.specimen, out.result, threads);
  }
  return out;
}

}  // namespace rbdem::io
