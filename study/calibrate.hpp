// Calibration of micro parameters against macro targets with a quasi-Newton (Broyden / Levenberg-Marquardt)
// iteration in log space. The seed paper calibrated by trial and error in pairs; this does the same job
// systematically and reports every iteration.
//
// A targets file (TOML):
//   [calibrate]
//   base = "paper.toml"           # relative to this file; empty = built-in defaults
//   tolerance = 0.03              # stop when every target is met within this relative error
//   max_iterations = 8
//   dips = [0, 15, 30, 45, 60, 75, 90]   # for min_strength / min_angle / anisotropy targets
//   realizations = 1              # meshes per run: each target is the mean over this many meshes
//   confining = [0, 5e6, 10e6]    # Pa, the confined runs of friction_angle / cohesion targets
//   [calibrate.set]               # fixed overrides
//   [[parameter]]
//   name = "rock_strength"
//   keys = ["rock.cohesion", "rock.tensile_strength"]   # tied keys: key_k = value x ratio_k
//   ratios = [1.0, 0.5]
//   start = 11e6                  # default: the base scene's value of keys[0] / ratios[0]
//   min = 1e5
//   max = 1e10
//   [[target]]
//   quantity = "strength"         # see target_quantities below
//   beta = 90
//   value = 50e6
//
// Each evaluation runs what its targets read: uniaxial runs (strength, modulus, poisson and the dip-curve targets),
// Brazilian runs (tensile_strength) and confined runs at every `confining` pressure (friction_angle, cohesion of
// the strength envelope sigma_1 = sigma_c + k sigma_3). A run that is not quasi-static (its summary's verdict) is
// run again at half, then a quarter of the platen speed; an evaluation that stays dynamic is flagged and cannot make
// the calibration converge.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "dem/scene.hpp"
#include "study/study.hpp"

namespace rbdem::study {

struct CalibrationParameter {
  std::string name;
  std::vector<std::string> keys;
  std::vector<double> ratios;
  double start = 0, min = 0, max = 0;
};

// The target quantities: name, the test that measures it, whether it is read at one dip (`beta`), its unit.
struct TargetQuantity {
  const char* name;
  const char* test;     // "ucs", "brazilian" or "triaxial"
  bool at_dip;          // read at the target's beta; otherwise from the uniaxial dip curve over `dips`
  bool optimised;       // min_angle (a discrete quantity) is checked, not optimised
  const char* meaning;
};
const std::vector<TargetQuantity>& target_quantities();

struct CalibrationTarget {
  std::string quantity;  // one of target_quantities()
  double beta = 90;
  double value = 0;
  std::string label() const;
};

struct CalibrationSpec {
  Scene base;
  double tolerance = 0.03;
  int max_iterations = 8;
  std::vector<double> dips{0, 15, 30, 45, 60, 75, 90};
  int realizations = 1;
  std::vector<double> confining{0, 5e6, 10e6};
  std::vector<CalibrationParameter> parameters;
  std::vector<CalibrationTarget> targets;
};

// `overrides` (KEY=VALUE, the command line's --set) apply to the base scene after [calibrate.set] and before the
// parameters read their start values from it, so an override of a fitted key moves its start.
CalibrationSpec load_calibration(const std::filesystem::path& path, const std::vector<std::string>& overrides = {});

struct CalibrationIteration {
  int iteration = 0;
  std::string kind;                 // "start", "jacobian", "step", "backtrack"
  std::vector<double> parameters;   // values
  std::vector<double> measured;     // per target
  double max_error = 0;             // max |measured / target - 1| over the optimised targets
  bool quasi_static = true;         // every run of the evaluation (after the slower reruns)
  bool reused = false;              // every run found complete on disk (a resumed calibration)
};

struct CalibrationResult {
  std::vector<CalibrationIteration> history;
  Scene scene;                       // the best scene found
  CalibrationIteration best;
  bool converged = false;
  int evaluations = 0;
  double wall_seconds = 0;
};

struct CalibrateOptions {
  int workers = 0;                                 // runs at once; 0 = all cores
  const std::atomic<bool>* cancel = nullptr;       // set to stop: throws study::Cancelled, completed runs are kept
  std::function<void(const std::string&)> log;     // one line per evaluation
  std::function<void(const std::string&)> progress;  // one line per run
};

// Runs the calibration; every evaluation's runs go to out/eval_NN/ (Brazilian runs to eval_NN/brazilian/, confined
// ones to eval_NN/triaxial/, slower reruns to .../slower_2x/ and slower_4x/). Runs found complete with the same
// scene are reused, so a calibration run again in the same folder after an interruption continues where it stopped
// and ends with the same result.
CalibrationResult calibrate(const CalibrationSpec& spec, const std::filesystem::path& out,
                            const CalibrateOptions& options);

}  // namespace rbdem::study
