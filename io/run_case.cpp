// One test case. See run_case.hpp.
#include "io/run_case.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "dem/driver/registry.hpp"
#include "dem/mesh_cache.hpp"
#include "io/results.hpp"

namespace rbdem::io {

CaseRun run_case(const std::string& test, const Scene& scene, const CaseOptions& options) {
  protocol_info(test).check(scene);  // before meshing: a scene that does not suit the test costs nothing
  // The explicit runs are 2D in this build: a 3D scene (specimen.dimension = 3) is meshed and measured by
  // rbdem elastic only.
  if (scene.specimen.dimension == 3)
    throw SceneError(fmt::format("rbdem {} on a 3D scene (specimen.dimension = 3) is not built: the explicit 3D "
                                 "engine is not part of this build; rbdem elastic measures a 3D scene's static "
                                 "moduli, or set specimen.dimension = 2 for the plane slice",
                                 test));
  CaseRun out;
  Scene run_scene = scene;
  if (options.threads > 0) run_scene.numerics.threads = options.threads;
  const TriMesh mesh = make_mesh_cached(run_scene, &out.mesh_cached);
  out.result = run_test(test, run_scene, mesh, options.run, [&](const Simulation& sim) {
    out.specimen = sim.specimen();
    if (options.ready) options.ready(sim, out.mesh_cached);
  });
  if (!options.out.empty()) {
    const int threads = options.write_threads ? std::max(1, options.write_threads()) : out.result.threads;
    write_run(options.out, scene, out.specimen, out.result, threads);
  }
  return out;
}

}  // namespace rbdem::io
