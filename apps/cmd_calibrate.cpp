// rbdem calibrate: find micro parameters (bond strengths, moduli) that reproduce macro targets.
//
//   rbdem calibrate scenes/calibrate_paper.toml --out runs/cal      # writes calibrated.toml, calibration.csv
// Every evaluation's runs are kept under --out/eval_NN/ for inspection. The base scene and the scene of the
// parameters' start values are checked for likely unit mistakes before anything runs (--force skips that). Ctrl-C
// (SIGINT) or SIGTERM stops it with the completed runs kept; `--resume` in the same --out continues where it stopped
// and ends with the result of an uninterrupted calibration (each evaluation is deterministic; completed runs of the
// same scene are reused).
#include <algorithm>
#include <atomic>
#include <csignal>
#include <thread>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "study/calibrate.hpp"

namespace rbdem::cli {

namespace {

struct CalibrateOptions {
  std::string targets;
  std::string out = "runs/calibrate";
  std::vector<std::string> sets;
  int workers = 0;
  bool force = false;
  bool resume = false;
};

std::atomic<bool> interrupted{false};
volatile std::sig_atomic_t last_signal = 0;
extern "C" void on_calibrate_signal(int sig) {
  last_signal = sig;
  interrupted.store(true);
}

// An --out folder that holds an earlier calibration is continued only with --resume.
void check_out_folder(const CalibrateOptions& opt) {
  const std::filesystem::path out(opt.out);
  const bool earlier = std::filesystem::exists(out / "eval_00") || std::filesystem::exists(out / "calibration.csv");
  if (earlier && !opt.resume)
    throw SceneError(fmt::format("--out {} holds an earlier calibration: add --resume to continue it (its completed "
                                 "runs are reused where the scene is the same), or choose another --out",
                                 opt.out));
}

// The scene the calibration starts from: the base with every parameter at its start value (as study/calibrate.cpp
// sets them: key = value x ratio). A start of 200e9 for rock.cohesion is as much a unit mistake as a base value.
Scene start_scene(const study::CalibrationSpec& spec) {
  Scene s = spec.base;
  for (const auto& p : spec.parameters)
    for (std::size_t k = 0; k < p.keys.size(); ++k)
      set_parameter(s, p.keys[k], fmt::format("{}", p.start * p.ratios[k]));
  return s;
}

int run_calibrate(const CalibrateOptions& opt) {
  study::CalibrationSpec spec =
      load_input(opt.targets, InputKind::calibration,
                 [&](const auto& f) { return study::load_calibration(f, opt.sets); });
  validate(spec.base);
  if (!opt.force) {
    check_plausible(spec.base);
    try {
      check_plausible(start_scene(spec));
    } catch (const SceneError& e) {
      throw SceneError(fmt::format("{}: the start values of [[parameter]]: {}", opt.targets, e.what()));
    }
  }
  // Each evaluation runs its dips side by side, one case per worker.
  const int workers = opt.workers > 0 ? opt.workers : int(std::max(1u, std::thread::hardware_concurrency()));
  if (spec.base.mesh.file.empty())
    check_cost(spec.base, "calibrate", std::min(workers, int(spec.dips.size())), opt.force, false);
  fmt::print("calibrate: {} parameters, {} targets, tolerance {:.1f} %, at most {} iterations\n",
             spec.parameters.size(), spec.targets.size(), 100 * spec.tolerance, spec.max_iterations);
  check_out_folder(opt);
  std::filesystem::create_directories(opt.out);
  const auto print = [](const std::string& line) {
    fmt::print("{}\n", line);
    std::fflush(stdout);
  };
  study::CalibrateOptions co;
  co.workers = opt.workers;
  co.cancel = &interrupted;
  co.log = print;
  co.progress = print;
  interrupted.store(false);
  auto previous = std::signal(SIGINT, on_calibrate_signal);
  auto previous_term = std::signal(SIGTERM, on_calibrate_signal);
  study::CalibrationResult r;
  try {
    r = study::calibrate(spec, opt.out, co);
  } catch (const study::Cancelled&) {
    std::signal(SIGINT, previous), std::signal(SIGTERM, previous_term);
    fmt::print(stderr,
               "calibrate: interrupted; the completed runs are kept in {}: `rbdem calibrate {} --out {} --resume` "
               "continues\n",
               opt.out, opt.targets, opt.out);
    return last_signal == SIGTERM ? 143 : 130;
  } catch (...) {
    std::signal(SIGINT, previous), std::signal(SIGTERM, previous_term);
    throw;
  }
  std::signal(SIGINT, previous), std::signal(SIGTERM, previous_term);
  fmt::print("calibrate: {} after {} evaluations ({:.0f} s); best max error {:.1f} %\n",
             r.converged ? "converged" : "NOT converged", r.evaluations, r.wall_seconds, 100 * r.best.max_error);
  for (std::size_t i = 0; i < spec.parameters.size(); ++i)
    fmt::print("  {} = {:.6g}\n", spec.parameters[i].name, r.best.parameters[i]);
  fmt::print("calibrate: wrote {}/calibrated.toml and calibration.csv\n", opt.out);
  return r.converged ? ok : check_failed;
}

}  // namespace

Runner add_calibrate_command(CLI::App& app) {
  auto opt = std::make_shared<CalibrateOptions>();
  CLI::App* cmd = app.add_subcommand("calibrate", "fit micro parameters to macro targets; writes a ready scene");
  cmd->add_option("targets", opt->targets, "targets file (TOML with a [calibrate] table; see scenes/calibrate_paper.toml)")
      ->required();
  cmd->add_option("--out,-o", opt->out, "output folder")->capture_default_str();
  cmd->add_option("--set", opt->sets, "override a key of the base scene")->type_name("KEY=VALUE")->allow_extra_args(false);
  cmd->add_option("--workers,-j", opt->workers, "cases run at once (default: all cores)");
  cmd->add_flag("--resume", opt->resume,
                 "continue an interrupted calibration in --out (completed runs of the same scene are reused)");
  add_force_flag(*cmd, opt->force);
  return [opt]() { return run_calibrate(*opt); };
}

}  // namespace rbdem::cli
