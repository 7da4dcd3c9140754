// rbdem ucs, rbdem triaxial, rbdem brazilian: one test of one specimen (dem/driver/ucs.hpp).
//
//   rbdem ucs --beta 60 --out runs/b60                  # the paper specimen at beta = 60 deg
//   rbdem ucs my.toml --set mesh.size=0.002 --out runs/x
//   rbdem ucs my.toml --set mesh.size=0.002 --out runs/x --resume   # continue after Ctrl-C, a kill or a crash
//   rbdem triaxial --beta 60 --confining 10e6 --out runs/t60        # confined at sigma_3 = 10 MPa
//   rbdem brazilian --beta 30 --out runs/bz30           # a 50 mm disc (specimen.shape = "disc" is implied)
// Writes summary.json, curve.csv, cracks.csv, scene.toml, result.h5 and result.xdmf into --out, each atomically.
// Runs the elastic gate first (cached per scene, docs/elastic.md) and refuses with exit status 3 when it fails;
// --skip-elastic-gate runs anyway. While running it writes checkpoint.h5 (numerics.checkpoint_every_steps,
// numerics.checkpoint_every_seconds) and on SIGINT / SIGTERM, then exits with 130 / 143; --resume continues from it.
// A run the watchdog stops (non-finite state, energy from nowhere) writes its results up to the last sound state
// with "completed": false and exits with status 1 (docs/reliability.md).
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "compare/gate/gate_cache.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"
#include "dem/driver/ucs.hpp"
#include "io/checkpoint.hpp"
#include "io/results.hpp"

namespace rbdem::cli {

namespace {


struct TestCommandOptions {
  std::string test;  // ucs | triaxial | brazilian
  SceneOptions scene;
  std::optional<double> confining;  // triaxial: --confining PA
  std::string out;
  bool skip_elastic_gate = false;
  bool resume = false;
  long interrupt_at_step = -1;  // tests: act as if SIGINT arrived at this step
  bool allow_supercritical_dt = false;  // tests: let numerics.dt exceed the critical step (provokes the watchdog)
};

std::atomic<bool> interrupted{false};
volatile std::sig_atomic_t last_signal = 0;
extern "C" void on_signal(int sig) {
  last_signal = sig;
  interrupted.store(true);
}

int run_test_command(const TestCommandOptions& opt) {
  namespace fs = std::filesystem;
  SceneOptions so = opt.scene;
  if (opt.confining) so.sets.insert(so.sets.begin(), fmt::format("loading.confining_pressure={:.17g}", *opt.confining));
  if (opt.test == "brazilian") so.sets.insert(so.sets.begin(), "specimen.shape=disc");
  const Scene scene = resolve_scene(so);
  check_test_scene(opt.test, scene);
  print_scene(scene, opt.scene);
  const fs::path out(opt.out);
  const fs::path ckpt_file = out / "checkpoint.h5";
  // Before anything runs: the output folder must take files, and a resume needs its checkpoint.
  io::require_writable_dir(out);
  TestCheckpoint resume_from;
  if (opt.resume) {
    if (!fs::exists(ckpt_file))
      throw std::invalid_argument(fmt::format("--resume: there is no checkpoint {} to continue from{}; run without "
                                              "--resume to start afresh",
                                              ckpt_file.string(),
                                              fs::exists(out / "summary.json") ? " (the run there is complete)" : ""));
    resume_from = io::read_checkpoint(ckpt_file);
    if (resume_from.scene_toml != to_toml(scene) || resume_from.test != opt.test)
      throw SceneError(fmt::format("--resume: {} was written for another scene; resume with the same scene file, "
                                   "--set options and mesh as the interrupted run, or start afresh without --resume",
                                   ckpt_file.string()));
  }
  // The gate checks the scene's materials; a disc is checked as the rectangular specimen of the same materials.
  if (!opt.resume && !opt.skip_elastic_gate && !compare::require_elastic_gate(gate_scene(scene))) return check_failed;
  const TriMesh mesh = make_mesh(scene);
  const Topology topo = build_topology(mesh, scene.specimen.thickness, scene.rock.density);
  fmt::print("{}: {} blocks, {} bonds ({} joint), beta = {} deg{}\n", opt.test, topo.blocks.size(), topo.bonds.size(),
             topo.count(BondKind::joint), scene.joint_set.dip_deg,
             opt.test == "triaxial" ? fmt::format(", sigma_3 = {:.4g} MPa", scene.loading.confining_pressure / 1e6)
                                    : std::string());
  RunOptions uo;
  const bool tty = isatty(fileno(stderr));
  if (tty && !opt.scene.quiet)
    uo.progress = [](const RunProgress& p) {
      fmt::print(stderr, "\r  step {:>8}  strain {:.3e}  stress {:7.2f} MPa  peak {:7.2f} MPa  cracks {:>6}", p.step,
                 p.strain, p.stress / 1e6, p.peak / 1e6, p.cracks);
    };
  uo.checkpoint = [&](const TestCheckpoint& c) { io::write_checkpoint(ckpt_file, c); };
  uo.cancel = &interrupted;
  uo.interrupt_at_step = opt.interrupt_at_step;
  uo.allow_supercritical_dt = opt.allow_supercritical_dt;
  if (opt.resume) {
    uo.resume = &resume_from;
    fmt::print("{}: resuming from {} at step {} (strain {:.4e})\n", opt.test, ckpt_file.string(), resume_from.engine.steps,
               resume_from.record.curve.empty() ? 0.0 : resume_from.record.curve.back().strain);
  }
  interrupted.store(false);
  auto old_int = std::signal(SIGINT, on_signal);
  auto old_term = std::signal(SIGTERM, on_signal);
  TestResult r;
  try {
    r = run_test(opt.test, scene, topo, uo);
  } catch (const RunCancelled& c) {
    std::signal(SIGINT, old_int), std::signal(SIGTERM, old_term);
    if (tty && !opt.scene.quiet) fmt::print(stderr, "\n");
    const int sig = last_signal != 0 ? int(last_signal) : SIGINT;
    fmt::print(stderr,
               "rbdem: interrupted ({}) at step {}: wrote the checkpoint {}. To continue, run the same command with "
               "--resume\n",
               sig == SIGTERM ? "SIGTERM" : "SIGINT", c.step, ckpt_file.string());
    return 128 + sig;
  } catch (...) {
    std::signal(SIGINT, old_int), std::signal(SIGTERM, old_term);
    throw;
  }
  std::signal(SIGINT, old_int), std::signal(SIGTERM, old_term);
  if (tty && !opt.scene.quiet) fmt::print(stderr, "\n");
  io::write_run(out, scene, mesh, topo, r);
  if (!r.completed) {
    fmt::print(stderr, "rbdem: run failed: {}\n", r.watchdog_message);
    fmt::print(stderr, "rbdem: wrote {}/summary.json with \"completed\": false (results up to the last sound state); "
                       "the last checkpoint, if any, is {}\n", opt.out, ckpt_file.string());
    return run_failed;
  }
  std::error_code ec;
  fs::remove(ckpt_file, ec);  // the run is complete: its results supersede the checkpoint
  if (r.test == "brazilian")
    fmt::print("brazilian: tensile strength {:.3f} MPa (peak load {:.4g} N, layers at {:g} deg to the load), ",
               r.tensile_strength / 1e6, r.peak_load, r.layer_angle_deg);
  else if (r.test == "triaxial")
    fmt::print("triaxial: sigma_1 {:.2f} MPa, deviator {:.2f} MPa at sigma_3 {:.2f} MPa, axial strain {:.3e}, lateral "
               "{:.3e}, ",
               r.peak_stress / 1e6, r.deviator_at_peak / 1e6, r.confining_pressure / 1e6, r.strain_at_peak,
               r.lateral_strain_at_peak);
  else
    fmt::print("ucs: peak {:.2f} MPa at strain {:.3e}, E50 {:.2f} GPa, ", r.peak_stress / 1e6, r.strain_at_peak,
               r.youngs_modulus / 1e9);
  fmt::print("{} cracks (rock t/s {}/{}, joint t/s {}/{}), {}, {} steps of {:.3g} s, {:.1f} s wall\n",
             r.crack_counts.total(), r.crack_counts.rock_tensile, r.crack_counts.rock_shear,
             r.crack_counts.joint_tensile, r.crack_counts.joint_shear, r.failure_mode, r.steps, r.dt, r.wall_seconds);
  if (r.jacket_edges_lost > 0)
    fmt::print("{}: note: up to {} jacket edges carried no pressure (their blocks broke off the specimen)\n", opt.test,
               r.jacket_edges_lost);
  if (!r.quasi_static)
    fmt::print("{}: warning: the test was not quasi-static: {}\n", opt.test, r.quasi_static_reason);
  fmt::print("{}: wrote {}/summary.json, curve.csv, cracks.csv, scene.toml, result.h5, result.xdmf\n", opt.test,
             opt.out);
  return ok;
}

}  // namespace

Runner add_test_command(CLI::App& app, const std::string& test) {
  auto opt = std::make_shared<TestCommandOptions>();
  opt->test = test;
  opt->out = "runs/" + test;
  const char* what = test == "ucs"        ? "one uniaxial compression test"
                     : test == "triaxial" ? "one confined (triaxial) compression test: --confining sets sigma_3"
                                          : "one Brazilian (diametral compression) test of a disc";
  CLI::App* cmd = app.add_subcommand(test, fmt::format("{}: summary.json, curve.csv, cracks.csv, result.h5", what));
  add_scene_options(*cmd, opt->scene);
  if (test == "triaxial")
    cmd->add_option("--confining", opt->confining,
                    "confining pressure sigma_3 [Pa] (loading.confining_pressure), e.g. --confining 10e6");
  cmd->add_option("--out,-o", opt->out, "output folder")->capture_default_str();
  cmd->add_flag("--skip-elastic-gate", opt->skip_elastic_gate,
                "run even when the elastic gate fails (DEM vs the FE model with the joints, and Amadei where the "
                "layers homogenize; rbdem elastic; cached per scene)");
  cmd->add_flag("--resume", opt->resume,
                "continue the interrupted run in --out from its checkpoint.h5 (same scene and options)");
  cmd->add_option("--interrupt-at-step", opt->interrupt_at_step,
                  "testing: stop at this step as if interrupted (writes the checkpoint, exit 130)")
      ->group("");  // hidden
  cmd->add_flag("--allow-supercritical-dt", opt->allow_supercritical_dt,
                "testing: accept numerics.dt above the critical step (the watchdog then stops the run)")
      ->group("");  // hidden
  return [opt]() { return run_test_command(*opt); };
}

}  // namespace rbdem::cli
