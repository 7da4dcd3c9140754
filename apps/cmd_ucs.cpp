// rbdem ucs: one uniaxial compression test.
//
//   rbdem ucs --beta 60 --out runs/b60                  # the paper specimen at beta = 60 deg
//   rbdem ucs my.toml --set mesh.size=0.002 --out runs/x
// Writes summary.json, curve.csv, cracks.csv and scene.toml into --out. Runs the elastic gate first (cached per
// scene, docs/elastic.md) and refuses with exit status 3 when it fails; --skip-elastic-gate runs anyway.
#include <unistd.h>

#include <chrono>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "compare/gate/gate_cache.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"
#include "dem/ucs.hpp"
#include "io/results.hpp"

namespace rbdem::cli {

namespace {

struct UcsCommandOptions {
  SceneOptions scene;
  std::string out = "runs/ucs";
  bool skip_elastic_gate = false;
};

int run_ucs_command(const UcsCommandOptions& opt) {
  const Scene scene = resolve_scene(opt.scene);
  print_scene(scene, opt.scene);
  if (!opt.skip_elastic_gate && !compare::require_elastic_gate(scene)) return check_failed;
  const TriMesh mesh = make_mesh(scene);
  const Topology topo = build_topology(mesh, scene.specimen.thickness, scene.rock.density);
  fmt::print("ucs: {} blocks, {} bonds ({} joint), beta = {} deg\n", topo.blocks.size(), topo.bonds.size(),
             topo.count(BondKind::joint), scene.joint_set.dip_deg);
  UcsOptions uo;
  const bool tty = isatty(fileno(stderr));
  if (tty && !opt.scene.quiet)
    uo.progress = [](const UcsProgress& p) {
      fmt::print(stderr, "\r  step {:>8}  strain {:.3e}  stress {:7.2f} MPa  peak {:7.2f} MPa  cracks {:>6}", p.step,
                 p.strain, p.stress / 1e6, p.peak / 1e6, p.cracks);
    };
  const UcsResult r = run_ucs(scene, topo, uo);
  if (tty && !opt.scene.quiet) fmt::print(stderr, "\n");
  io::write_ucs(opt.out, scene, mesh, topo, r);
  fmt::print("ucs: peak {:.2f} MPa at strain {:.3e}, E50 {:.2f} GPa, {} cracks (rock t/s {}/{}, joint t/s {}/{}), "
             "{}, {} steps of {:.3g} s, {:.1f} s wall\n",
             r.peak_stress / 1e6, r.strain_at_peak, r.youngs_modulus / 1e9, r.crack_counts.total(),
             r.crack_counts.rock_tensile, r.crack_counts.rock_shear, r.crack_counts.joint_tensile,
             r.crack_counts.joint_shear, r.failure_mode, r.steps, r.dt, r.wall_seconds);
  fmt::print("ucs: wrote {}/summary.json, curve.csv, cracks.csv\n", opt.out);
  return ok;
}

}  // namespace

Runner add_ucs_command(CLI::App& app) {
  auto opt = std::make_shared<UcsCommandOptions>();
  CLI::App* cmd = app.add_subcommand("ucs", "one uniaxial compression test: summary.json, curve.csv, cracks.csv");
  add_scene_options(*cmd, opt->scene);
  cmd->add_option("--out,-o", opt->out, "output folder")->capture_default_str();
  cmd->add_flag("--skip-elastic-gate", opt->skip_elastic_gate,
                "run even when the elastic gate fails (DEM vs Amadei moduli, rbdem elastic; cached per scene)");
  return [opt]() { return run_ucs_command(*opt); };
}

}  // namespace rbdem::cli
