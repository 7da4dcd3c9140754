// rbdem elastic: the DEM's static elastic moduli against the FE model with the joints as interfaces (the gate),
// Amadei's formula and the homogenized FE twin.
//
//   rbdem elastic --out runs/el                          # the paper specimen, beta = 0, 15, ..., 90 deg
//   rbdem elastic my.toml --set mesh.size=0.002 --out runs/el2 --fields
//   rbdem elastic --set specimen.dimension=3 --out runs/el3   # the 3D cylinder: DEM static vs the 3D FE twin
// Writes elastic.json into --out (contract in docs/elastic.md) and prints the table. Exit status 3 when the gate
// fails (the DEM does not reproduce the FE model with the joints within elastic.tolerance).
#include <cstdlib>
#include <filesystem>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "compare/gate/elastic_gate.hpp"
#include "compare/gate/elastic_gate3.hpp"
#include "compare/gate/gate_cache.hpp"
#include "io/results.hpp"
#include "study/report.hpp"

namespace rbdem::cli {

namespace {

struct ElasticCommandOptions {
  SceneOptions scene;
  std::string out = "runs/elastic";
  bool fields = false;
  bool verbose = false;
};

// A 3D scene (specimen.dimension = 3): the DEM's static solve against the FE twin with the DEM's constants
// (compare/gate/elastic_gate3.hpp). No cache: the failure runs it would gate are 2D in this build.
int run_elastic3_command(const Scene& scene, const ElasticCommandOptions& opt) {
  if (opt.fields)
    throw SceneError("--fields writes the 2D block displacements; a 3D scene (specimen.dimension = 3) has none: "
                     "drop --fields");
  compare::Elastic3Options go;
  if (opt.verbose) go.log = [](const std::string& s) { fmt::print("{}\n", s); };
  fmt::print("elastic: the 3D {}: constants from prisms, then the specimen at beta = 0, 15, ..., 90 deg (mesh {:g} "
             "mm)\n",
             scene.specimen.shape, 1e3 * scene.mesh.size);
  const compare::Elastic3Report report = compare::run_elastic_gate3(scene, go);
  std::filesystem::create_directories(opt.out);
  io::write_text_atomic(std::filesystem::path(opt.out) / "elastic.json",
                        compare::elastic3_json(report, scene).dump(1) + "\n");
  fmt::print("{}", compare::elastic3_table(report));
  fmt::print("elastic: {:.1f} s wall (constants {:.1f} s; over the dips: meshing {:.1f} s, DEM {:.1f} s, FE {:.1f} "
             "s, FE with the joints {:.1f} s); wrote {}/elastic.json\n",
             report.seconds, report.constants_seconds, report.mesh_seconds, report.dem_seconds, report.fe_seconds,
             report.fe_joints_seconds, opt.out);
  return report.gate.passed ? ok : check_failed;
}

int run_elastic_command(const ElasticCommandOptions& opt) {
  const Scene scene = resolve_scene(opt.scene);
  print_scene(scene, opt.scene);
  if (scene.specimen.dimension == 3) return run_elastic3_command(scene, opt);
  compare::ElasticGateOptions go;
  go.fields = opt.fields;
  if (opt.verbose) go.log = [](const std::string& s) { fmt::print("{}\n", s); };
  fmt::print("elastic: meshing and solving the specimen at beta = 0, 15, ..., 90 deg and unjointed (mesh {:g} mm)\n",
             1e3 * scene.mesh.size);
  const compare::ElasticReport report = compare::run_elastic_gate(scene, go);
  std::filesystem::create_directories(opt.out);
  io::write_text_atomic(std::filesystem::path(opt.out) / "elastic.json",
                        compare::elastic_json(report, scene).dump(1) + "\n");
  compare::store_elastic_gate(scene, report);
  if (opt.fields) {
    // DEM and the FE model with the joints side by side at the dip where they differ most (python/rbdem_figures.py;
    // skipped without matplotlib).
    const auto script = study::figure_script();
    const auto png = std::filesystem::path(opt.out) / "elastic_fields.png";
    const std::string cmd = fmt::format("'{}' '{}' elastic-fields '{}' '{}' > /dev/null 2>&1", study::figure_python(),
                                        script.string(), png.string(),
                                        (std::filesystem::path(opt.out) / "elastic.json").string());
    if (!script.empty() && std::system(cmd.c_str()) == 0) fmt::print("elastic: wrote {}\n", png.string());
  }
  fmt::print("{}", compare::elastic_table(report));
  fmt::print("elastic: {:.1f} s wall (DEM {:.1f} s, FE {:.1f} s of which the FE model with the joints {:.1f} s "
             "summed over the dips{}); wrote {}/elastic.json\n",
             report.seconds, report.dem_seconds, report.fe_seconds, report.fe_joints_seconds,
             report.linear_check_run ? fmt::format(", linear check {:.1f} s", report.linear_check_seconds) : "",
             opt.out);
  return report.gate.passed ? ok : check_failed;
}

}  // namespace

Runner add_elastic_command(CLI::App& app) {
  auto opt = std::make_shared<ElasticCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "elastic", "elastic moduli: DEM static vs the FE model with the joints (the gate), Amadei and the homogenized FE "
                 "over beta = 0..90");
  add_scene_options(*cmd, opt->scene);
  cmd->add_option("--out,-o", opt->out, "output folder (elastic.json)")->capture_default_str();
  cmd->add_flag("--fields", opt->fields,
                "also write the block displacements of the DEM, the FE and the FE with the joints per angle into "
                "elastic.json");
  cmd->add_flag("--verbose,-v", opt->verbose, "print each DEM solve as it finishes");
  return [opt]() { return run_elastic_command(*opt); };
}

}  // namespace rbdem::cli
