// rbdem ucs, rbdem triaxial, rbdem brazilian (every protocol of the registry, dem/driver/registry.hpp): one test of
// one specimen, through io::run_case (io/run_case.hpp).
//
//   rbdem ucs --beta 60 --out runs/b60                  # the paper specimen at beta = 60 deg
//   rbdem ucs my.toml --set mesh.size=0.002 --out runs/x
//   rbdem ucs my.toml --set mesh.size=0.002 --out runs/x --resume   # continue after Ctrl-C, a kill or a crash
//   rbdem triaxial --beta 60 --confining 10e6 --out runs/t60        # confined at sigma_3 = 10 MPa
//   rbdem brazilian --beta 30 --out runs/bz30           # a 50 mm disc (specimen.shape = "disc" is implied)
// Writes summary.json, curve.csv, cracks.csv, scene.toml, result.h5 and the .xdmf files into --out, each atomically,
// and lists what it wrote. Before meshing it estimates the run's cost (cli_common.hpp: printed when large, refused
// when the memory exceeds what the machine has available). Progress: on a terminal one line updated in place;
// otherwise (a log file, a pipe, a batch job) a plain line every 10 s with the time left.
// Runs the elastic gate first (cached per scene, docs/elastic.md) and refuses with exit status 3 when it fails;
// --skip-elastic-gate runs anyway. While running it writes checkpoint.h5 (numerics.checkpoint_every_steps,
// numerics.checkpoint_every_seconds) and on SIGINT / SIGTERM, then exits with 130 / 143; --resume continues from it.
// A run the watchdog stops (non-finite state, energy from nowhere) writes its results up to the last sound state
// with "completed": false and exits with status 1 (docs/reliability.md).
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "compare/gate/gate_cache.hpp"
#include "dem/driver/registry.hpp"
#include "dem/driver/summary.hpp"
#include "io/checkpoint.hpp"
#include "io/results.hpp"
#include "io/run_case.hpp"

namespace rbdem::cli {

namespace {

struct TestCommandOptions {
  std::string test;  // the protocol's name
  SceneOptions scene;
  std::vector<std::optional<double>> shorthands;  // the protocol's own options (ProtocolInfo::options), in order
  std::string out;
  bool skip_elastic_gate = false;
  bool resume = false;
  long interrupt_at_step = -1;  // tests: act as if SIGINT arrived at this step
  bool allow_supercritical_dt = false;  // tests: let numerics.dt exceed the critical step (provokes the watchdog)
  double progress_seconds = 10.0;       // wall time between the plain progress lines (not on a terminal)
};

// The progress of a run, called by the driver every 1000 steps (RunOptions::progress). On a terminal (stdout and
// stderr both) one line on stderr rewritten in place; otherwise a plain line on stdout every `every` seconds of
// wall time, flushed, so a log shows how far the run is. The time left is the strain still to go at the strain
// rate so far: after the peak, to the post-peak stop ((1 + loading.post_peak_strain) x the strain at the peak, or
// earlier when the stress drops to loading.stop_fraction of the peak); before it the stop is unknown ("?", with
// the bound loading.max_strain).
class ProgressPrinter {
 public:
  ProgressPrinter(const Scene& scene, bool in_place, double every)
      : scene_(scene), in_place_(in_place), every_(every), start_(Clock::now()) {}

  void operator()(const RunProgress& p) {
    const double now = std::chrono::duration<double>(Clock::now() - start_).count();
    if (p.peak > peak_) peak_ = p.peak, strain_at_peak_ = p.strain;
    if (!have_origin_) have_origin_ = true, t0_ = now, e0_ = p.strain;
    if (in_place_) {
      fmt::print(stderr, "\r  step {:>8}  strain {:.3e}  stress {:7.2f} MPa  peak {:7.2f} MPa  cracks {:>6}  left {:<8}",
                 p.step, p.strain, p.stress / 1e6, p.peak / 1e6, p.cracks, time_left(p, now, false));
      printed_ = true;
      return;
    }
    if (now - last_ < every_) return;
    last_ = now;
    fmt::print("  step {}, strain {:.3e}, stress {:.2f} MPa (peak {:.2f} MPa), {} cracks, {} elapsed, left {}\n",
               p.step, p.strain, p.stress / 1e6, p.peak / 1e6, p.cracks, duration_text(now), time_left(p, now, true));
    std::fflush(stdout);
  }
  // Ends the line rewritten in place.
  void finish() {
    if (printed_) fmt::print(stderr, "\n");
    printed_ = false;
  }

 private:
  using Clock = std::chrono::steady_clock;

  std::string time_left(const RunProgress& p, double now, bool with_bound) const {
    const double rate = now - t0_ > 0.5 && p.strain > e0_ ? (p.strain - e0_) / (now - t0_) : 0.0;  // strain / s
    if (!(rate > 0)) return "?";
    const double max_strain = scene_.loading.max_strain;
    const bool past_peak = p.cracks > 0 && p.stress < p.peak && strain_at_peak_ > 0;
    if (past_peak) {
      const double stop = std::min(max_strain, (1.0 + scene_.loading.post_peak_strain) * strain_at_peak_);
      return "<= " + duration_text(std::max(0.0, stop - p.strain) / rate);
    }
    if (!with_bound) return "?";
    return fmt::format("? (at most {} to loading.max_strain)", duration_text(std::max(0.0, max_strain - p.strain) / rate));
  }

  const Scene& scene_;
  bool in_place_;
  double every_;
  Clock::time_point start_;
  double last_ = 0, t0_ = 0, e0_ = 0, peak_ = 0, strain_at_peak_ = 0;
  bool have_origin_ = false, printed_ = false;
};

// The files of `dir` written since `since`, by name.
std::vector<std::string> files_written(const std::filesystem::path& dir, std::filesystem::file_time_type since) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
    if (entry.is_regular_file(ec) && entry.last_write_time(ec) >= since) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::atomic<bool> interrupted{false};
volatile std::sig_atomic_t last_signal = 0;
// When other processes held the cores, how the thread team shrank (dem/team.hpp); with RBDEM_STAGE_TIMES=1, where
// the wall time went (docs/performance.md, "Where a run's time goes").
void print_timing(const std::string& test, const TestResult& r) {
  const TestResult::Timing& t = r.timing;
  if (t.team.shrinks > 0)
    fmt::print("{}: note: other processes held some of the cores: the engine stepped on fewer threads for {:.1f} s "
               "(down to {} of its {}; the results do not depend on it)\n",
               test, t.team.smaller_seconds, t.team.smallest, r.threads);
  const char* env = std::getenv("RBDEM_STAGE_TIMES");
  if (!env || std::string(env) != "1" || t.steps.steps == 0) return;
  const StepTimes& s = t.steps;
  const double total = s.total(), pct = total > 0 ? 100 / total : 0;
  fmt::print("{}: time: start {:.2f} s, steps {:.2f} s ({:.1f} us each: bonds {:.0f} %, one-thread sections {:.0f} %, "
             "blocks {:.0f} %, events and detection {:.0f} % on {} steps, rest {:.0f} %), other {:.2f} s, {} threads\n",
             test, t.start_seconds, total, 1e6 * total / double(s.steps), s.bonds * pct, s.serial * pct,
             s.blocks * pct, s.events * pct, s.event_steps, s.rest * pct,
             r.wall_seconds - t.start_seconds - total, r.threads);
  if (s.busy_steps > 0) {
    const double us = 1e6 / double(s.busy_steps);
    fmt::print("{}: time: busy per step, mean / busiest thread: bond kernel {:.1f} / {:.1f} us, contacts and "
               "components {:.1f} / {:.1f} us, integration {:.1f} / {:.1f} us\n",
               test, s.busy_mean[0] * us, s.busy_max[0] * us, s.busy_mean[1] * us, s.busy_max[1] * us,
               s.busy_mean[2] * us, s.busy_max[2] * us);
  }
}

extern "C" void on_signal(int sig) {
  last_signal = sig;
  interrupted.store(true);
}

int run_test_command(const TestCommandOptions& opt) {
  namespace fs = std::filesystem;
  // A second of slack for file systems with coarse time stamps: files older than the command are not listed.
  const auto started = fs::file_time_type::clock::now() - std::chrono::seconds(1);
  const ProtocolInfo& info = protocol_info(opt.test);
  SceneOptions so = opt.scene;
  for (std::size_t k = info.options.size(); k-- > 0;)
    if (opt.shorthands[k])
      so.sets.insert(so.sets.begin(), fmt::format("{}={:.17g}", info.options[k].key, *opt.shorthands[k]));
  for (const auto& [key, value] : info.scene_defaults) so.sets.insert(so.sets.begin(), key + "=" + value);
  const Scene scene = resolve_scene(so);
  info.check(scene);
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
  if (scene.mesh.file.empty()) check_cost(scene, opt.test, 1, opt.scene.force, opt.scene.quiet);
  if (!opt.resume && !opt.skip_elastic_gate && !compare::require_elastic_gate(gate_scene(scene))) return check_failed;
  io::CaseOptions co;
  co.out = out;
  co.ready = [&](const Simulation& sim, bool mesh_cached) {
    const Specimen& sp = sim.specimen();
    const bool user_mesh = !scene.mesh.file.empty();
    const std::string beta =
        user_mesh && sp.count(BondKind::joint) > 0
            ? fmt::format("{:.4g} deg (measured from the mesh's joint edges)", joint_dip_deg(sp, 0.0))
            : fmt::format("{} deg", scene.joint_set.dip_deg);
    fmt::print("{}: {} blocks, {} bonds ({} joint), beta = {}{}{}\n", opt.test, sp.num_blocks(), sp.num_bonds(),
               sp.count(BondKind::joint), beta,
               info.confined ? fmt::format(", sigma_3 = {:.4g} MPa", scene.loading.confining_pressure / 1e6)
                             : std::string(),
               mesh_cached ? ", mesh from the cache" : "");
    if (user_mesh) {
      const std::string warning = mesh_scale_warning(scene.mesh.file, std::max(sp.width(), sp.height()));
      if (!warning.empty()) fmt::print("{}: warning: {}\n", opt.test, warning);
    }
    std::fflush(stdout);
  };
  RunOptions& uo = co.run;
  ProgressPrinter progress(scene, isatty(fileno(stdout)) && isatty(fileno(stderr)), opt.progress_seconds);
  if (!opt.scene.quiet) uo.progress = [&progress](const RunProgress& p) { progress(p); };
  uo.checkpoint = [&](const TestCheckpoint& c) { io::write_checkpoint(ckpt_file, c); };
  uo.cancel = &interrupted;
  uo.interrupt_at_step = opt.interrupt_at_step;
  uo.allow_supercritical_dt = opt.allow_supercritical_dt;
  if (opt.resume) {
    uo.resume = &resume_from;
    fmt::print("{}: resuming from {} at step {} (strain {:.4e})\n", opt.test, ckpt_file.string(), resume_from.steps(),
               resume_from.record.curve.empty() ? 0.0 : resume_from.record.curve.back().strain);
  }
  interrupted.store(false);
  auto old_int = std::signal(SIGINT, on_signal);
  auto old_term = std::signal(SIGTERM, on_signal);
  TestResult r;
  try {
    r = io::run_case(opt.test, scene, co).result;
  } catch (const RunCancelled& c) {
    std::signal(SIGINT, old_int), std::signal(SIGTERM, old_term);
    progress.finish();
    const int sig = last_signal != 0 ? int(last_signal) : SIGINT;
    fmt::print(stderr,
               "rbdem: interrupted ({}) at step {}: wrote the checkpoint {}. To continue, run the same command with "
               "--resume\n",
               sig == SIGTERM ? "SIGTERM" : "SIGINT", c.step, ckpt_file.string());
    return 128 + sig;
  } catch (...) {
    std::signal(SIGINT, old_int), std::signal(SIGTERM, old_term);
    progress.finish();
    throw;
  }
  std::signal(SIGINT, old_int), std::signal(SIGTERM, old_term);
  progress.finish();
  if (!r.completed) {
    fmt::print(stderr, "rbdem: run failed: {}\n", r.watchdog_message);
    fmt::print(stderr, "rbdem: wrote {}/summary.json with \"completed\": false (results up to the last sound state); "
                       "the last checkpoint, if any, is {}\n", opt.out, ckpt_file.string());
    return run_failed;
  }
  std::error_code ec;
  fs::remove(ckpt_file, ec);  // the run is complete: its results supersede the checkpoint
  fmt::print("{}, {} cracks (rock t/s {}/{}, joint t/s {}/{}), {}, {} steps of {:.3g} s, {:.1f} s wall\n",
             info.headline(r), r.crack_counts.total(), r.crack_counts.rock_tensile, r.crack_counts.rock_shear,
             r.crack_counts.joint_tensile, r.crack_counts.joint_shear, r.failure_mode, r.steps, r.dt, r.wall_seconds);
  if (info.notes)
    for (const std::string& note : info.notes(r)) fmt::print("{}: note: {}\n", opt.test, note);
  print_timing(opt.test, r);
  if (!r.quasi_static)
    fmt::print("{}: warning: the test was not quasi-static: {}\n", opt.test, r.quasi_static_reason);
  fmt::print("{}: wrote into {}: {}\n", opt.test, opt.out, fmt::join(files_written(out, started), ", "));
  return ok;
}

}  // namespace

Runner add_test_command(CLI::App& app, const ProtocolInfo& test) {
  auto opt = std::make_shared<TestCommandOptions>();
  opt->test = test.name;
  opt->out = "runs/" + test.name;
  CLI::App* cmd =
      app.add_subcommand(test.name, fmt::format("{}: summary.json, curve.csv, cracks.csv, result.h5", test.description));
  add_scene_options(*cmd, opt->scene);
  opt->shorthands.resize(test.options.size());
  for (std::size_t k = 0; k < test.options.size(); ++k)
    cmd->add_option(test.options[k].option, opt->shorthands[k], test.options[k].help);
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
  cmd->add_option("--progress-seconds", opt->progress_seconds,
                  "testing: wall time between the plain progress lines written when not on a terminal")
      ->group("");  // hidden
  return [opt]() { return run_test_command(*opt); };
}

}  // namespace rbdem::cli
