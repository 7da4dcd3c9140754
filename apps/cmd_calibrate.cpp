// rbdem calibrate: find micro parameters (bond strengths, moduli) that reproduce macro targets.
//
//   rbdem calibrate scenes/calibrate_paper.toml --out runs/cal      # writes calibrated.toml, calibration.csv
// Every evaluation's UCS runs are kept under --out/eval_NN/ for inspection.
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
};

int run_calibrate(const CalibrateOptions& opt) {
  study::CalibrationSpec spec = study::load_calibration(opt.targets);
  for (const auto& s : opt.sets) apply_override(spec.base, s);
  validate(spec.base);
  if (!opt.force) check_plausible(spec.base);
  fmt::print("calibrate: {} parameters, {} targets, tolerance {:.1f} %, at most {} iterations\n",
             spec.parameters.size(), spec.targets.size(), 100 * spec.tolerance, spec.max_iterations);
  std::filesystem::create_directories(opt.out);
  const auto r = study::calibrate(spec, opt.out, opt.workers, [](const std::string& line) {
    fmt::print("{}\n", line);
    std::fflush(stdout);
  });
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
  cmd->add_option("targets", opt->targets, "targets file (TOML; see scenes/calibrate_paper.toml)")->required();
  cmd->add_option("--out,-o", opt->out, "output folder")->capture_default_str();
  cmd->add_option("--set", opt->sets, "override a key of the base scene")->type_name("KEY=VALUE")->allow_extra_args(false);
  cmd->add_option("--workers,-j", opt->workers, "cases run at once (default: all cores)");
  add_force_flag(*cmd, opt->force);
  return [opt]() { return run_calibrate(*opt); };
}

}  // namespace rbdem::cli
