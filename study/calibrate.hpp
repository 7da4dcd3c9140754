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
//   [calibrate.set]               # fixed overrides
//   [[parameter]]
//   name = "rock_strength"
//   keys = ["rock.cohesion", "rock.tensile_strength"]   # tied keys: key_k = value x ratio_k
//   ratios = [1.0, 0.5]
//   start = 11e6                  # default: the base scene's value of keys[0] / ratios[0]
//   min = 1e5
//   max = 1e10
//   [[target]]
//   quantity = "strength"         # strength | modulus (E50) | min_strength | anisotropy | min_angle (checked only)
//   beta = 90
//   value = 50e6
#pragma once

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

struct CalibrationTarget {
  std::string quantity;  // strength, modulus, min_strength, anisotropy, min_angle
  double beta = 90;
  double value = 0;
  std::string label() const;
};

struct CalibrationSpec {
  Scene base;
  double tolerance = 0.03;
  int max_iterations = 8;
  std::vector<double> dips{0, 15, 30, 45, 60, 75, 90};
  std::vector<CalibrationParameter> parameters;
  std::vector<CalibrationTarget> targets;
};

CalibrationSpec load_calibration(const std::filesystem::path& path);

struct CalibrationIteration {
  int iteration = 0;
  std::string kind;                 // "start", "jacobian", "step", "backtrack"
  std::vector<double> parameters;   // values
  std::vector<double> measured;     // per target
  double max_error = 0;             // max |measured / target - 1| over the optimised targets
};

struct CalibrationResult {
  std::vector<CalibrationIteration> history;
  Scene scene;                       // the best scene found
  CalibrationIteration best;
  bool converged = false;
  int evaluations = 0;
  double wall_seconds = 0;
};

// Runs the calibration; every evaluation's cases go to out/eval_NN/. `log` receives one line per evaluation.
CalibrationResult calibrate(const CalibrationSpec& spec, const std::filesystem::path& out, int workers,
                            const std::function<void(const std::string&)>& log);

}  // namespace rbdem::study
