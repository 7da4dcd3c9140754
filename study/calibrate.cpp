// Calibration by Levenberg-Marquardt with Broyden updates in log space. See calibrate.hpp.
#include "study/calibrate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <toml++/toml.h>

#include "io/results.hpp"
#include "study/toml_file.hpp"

namespace rbdem::study {

std::string CalibrationTarget::label() const {
  if (quantity == "strength" || quantity == "modulus") return fmt::format("{}@{:g}", quantity, beta);
  return quantity;
}

namespace {

double number(const toml::node* node, const std::string& where) {
  if (!node) throw SceneError(where + ": missing");
  return toml_number(*node, where);
}

bool optimised(const CalibrationTarget& t) { return t.quantity != "min_angle"; }

}  // namespace

CalibrationSpec load_calibration(const std::filesystem::path& path) {
  const std::string where = path.string();
  const toml::table root = read_toml_file(path, "calibration", "shipped: scenes/calibrate_paper.toml");
  CalibrationSpec spec;
  for (const auto& [k, v] : root)
    if (k != "calibrate" && k != "parameter" && k != "target")
      throw SceneError(fmt::format("{}: unknown top-level key '{}' (expected [calibrate], [[parameter]], [[target]])",
                                   where, k.str()));
  if (const toml::table* c = root["calibrate"].as_table()) {
    for (const auto& [k, v] : *c)
      if (k != "base" && k != "tolerance" && k != "max_iterations" && k != "dips" && k != "set")
        throw SceneError(fmt::format("{} [calibrate]: unknown key '{}'", where, k.str()));
    if (auto b = c->get_as<std::string>("base"); b && !b->get().empty())
      spec.base = load_scene_file(path.parent_path() / b->get());
    if (c->contains("tolerance")) spec.tolerance = number(c->get("tolerance"), where + " calibrate.tolerance");
    if (c->contains("max_iterations"))
      spec.max_iterations = int(number(c->get("max_iterations"), where + " calibrate.max_iterations"));
    if (auto d = c->get_as<toml::array>("dips")) {
      spec.dips.clear();
      for (const auto& x : *d) spec.dips.push_back(number(&x, where + " calibrate.dips"));
    }
    if (auto set = c->get_as<toml::table>("set"))
      for (const auto& [k, v] : *set)
        set_parameter(spec.base, k.str(), toml_value_text(v, where + " " + std::string(k.str())));
  }
  if (!(spec.tolerance > 0 && spec.tolerance < 1))
    throw SceneError(where + ": calibrate.tolerance must lie in (0, 1), e.g. 0.03");
  if (auto params = root["parameter"].as_array())
    for (const auto& node : *params) {
      const toml::table* t = node.as_table();
      if (!t) throw SceneError(where + ": [[parameter]] must be tables");
      CalibrationParameter p;
      if (auto n = t->get_as<std::string>("name")) p.name = n->get();
      const std::string pw = where + " parameter '" + p.name + "'";
      if (auto keys = t->get_as<toml::array>("keys"))
        for (const auto& k : *keys) p.keys.push_back(toml_value_text(k, pw + " keys"));
      if (p.keys.empty()) throw SceneError(pw + ": give keys = [\"section.key\", ...]");
      if (auto ratios = t->get_as<toml::array>("ratios"))
        for (const auto& r : *ratios) p.ratios.push_back(number(&r, pw + " ratios"));
      if (p.ratios.empty()) p.ratios.assign(p.keys.size(), 1.0);
      if (p.ratios.size() != p.keys.size()) throw SceneError(pw + ": one ratio per key");
      for (const auto& k : p.keys) parameter_text(spec.base, k);  // unknown keys throw, naming the key
      p.start = t->contains("start") ? number(t->get("start"), pw + " start")
                                     : std::stod(parameter_text(spec.base, p.keys[0])) / p.ratios[0];
      p.min = t->contains("min") ? number(t->get("min"), pw + " min") : p.start / 100;
      p.max = t->contains("max") ? number(t->get("max"), pw + " max") : p.start * 100;
      if (!(p.start > 0 && p.min > 0 && p.min <= p.start && p.start <= p.max))
        throw SceneError(pw + ": needs 0 < min <= start <= max (the search runs in log space)");
      spec.parameters.push_back(p);
    }
  if (auto targets = root["target"].as_array())
    for (const auto& node : *targets) {
      const toml::table* t = node.as_table();
      if (!t) throw SceneError(where + ": [[target]] must be tables");
      CalibrationTarget g;
      if (auto q = t->get_as<std::string>("quantity")) g.quantity = q->get();
      static const std::set<std::string> known{"strength", "modulus", "min_strength", "anisotropy", "min_angle"};
      if (!known.count(g.quantity))
        throw SceneError(fmt::format("{}: target quantity '{}' unknown (strength, modulus, min_strength, anisotropy, "
                                     "min_angle)",
                                     where, g.quantity));
      if (t->contains("beta")) g.beta = number(t->get("beta"), where + " target beta");
      g.value = number(t->get("value"), where + " target " + g.quantity + " value");
      spec.targets.push_back(g);
    }
  const auto n_opt = std::count_if(spec.targets.begin(), spec.targets.end(), optimised);
  if (spec.parameters.empty() || n_opt == 0)
    throw SceneError(where + ": give at least one [[parameter]] and one [[target]] other than min_angle");
  if (std::size_t(n_opt) < spec.parameters.size())
    throw SceneError(fmt::format("{}: {} parameters but only {} targets: the problem is underdetermined; tie "
                                 "parameters together (keys + ratios) or add targets",
                                 where, spec.parameters.size(), n_opt));
  return spec;
}

namespace {

// The dips each evaluation runs: those of the strength and modulus targets and, when a target reads the whole dip
// curve (min_strength, anisotropy, min_angle), spec.dips.
std::set<double> evaluation_dips(const CalibrationSpec& spec) {
  bool need_dips = false;
  std::set<double> betas;
  for (const auto& t : spec.targets) {
    if (t.quantity == "strength" || t.quantity == "modulus") betas.insert(t.beta);
    else need_dips = true;
  }
  if (need_dips)
    for (double d : spec.dips) betas.insert(d);
  return betas;
}

// The base scene with every parameter's keys set to its value p[i] times the key's ratio, validated.
Scene scene_for(const CalibrationSpec& spec, const std::vector<double>& p) {
  Scene s = spec.base;
  for (std::size_t i = 0; i < spec.parameters.size(); ++i)
    for (std::size_t k = 0; k < spec.parameters[i].keys.size(); ++k)
      set_parameter(s, spec.parameters[i].keys[k], fmt::format("{}", p[i] * spec.parameters[i].ratios[k]));
  validate(s);
  return s;
}

// Every target's quantity from one evaluation's cases (their summaries, by dip).
std::vector<double> measure_targets(const CalibrationSpec& spec, const std::vector<CaseResult>& results) {
  std::map<double, const nlohmann::json*> at;
  for (const auto& r : results) at[r.c.beta] = &r.summary;
  std::vector<double> measured;
  for (const auto& t : spec.targets) {
    double v = 0;
    if (t.quantity == "strength") v = (*at.at(t.beta))["peak_stress_pa"].get<double>();
    else if (t.quantity == "modulus") v = (*at.at(t.beta))["youngs_modulus_pa"].get<double>();
    else {
      double mn = std::numeric_limits<double>::infinity(), arg = 0;
      for (double d : spec.dips) {
        const double s_d = (*at.at(d))["peak_stress_pa"].get<double>();
        if (s_d < mn) mn = s_d, arg = d;
      }
      if (t.quantity == "min_strength") v = mn;
      else if (t.quantity == "min_angle") v = arg;
      else v = (*at.at(90.0))["peak_stress_pa"].get<double>() / mn;  // anisotropy
    }
    measured.push_back(v);
  }
  return measured;
}

// The log line of one evaluation: its parameters, every target as measured (with its error, or its target where a
// percentage means nothing) and the max error.
std::string evaluation_line(const CalibrationSpec& spec, const CalibrationIteration& it) {
  std::string line = fmt::format("{:>2} {:<9}", it.iteration, it.kind);
  for (std::size_t i = 0; i < spec.parameters.size(); ++i)
    line += fmt::format(" {}={:.4g}", spec.parameters[i].name, it.parameters[i]);
  line += " |";
  for (std::size_t k = 0; k < spec.targets.size(); ++k) {
    const bool pct = spec.targets[k].quantity != "min_angle" && spec.targets[k].quantity != "anisotropy";
    line += pct ? fmt::format(" {}={:.4g} ({:+.1f}%)", spec.targets[k].label(), it.measured[k],
                              100 * (it.measured[k] / spec.targets[k].value - 1))
                : fmt::format(" {}={:.3g} (target {:g})", spec.targets[k].label(), it.measured[k],
                              spec.targets[k].value);
  }
  line += fmt::format(" | max error {:.1f}%", 100 * it.max_error);
  return line;
}

// The evaluations of one calibration: each runs the dip study of a parameter set under out/eval_NN, measures the
// targets, logs a line and is kept in result.history. Also the maps between parameters and the search's log space.
struct Evaluator {
  const CalibrationSpec& spec;
  std::vector<std::size_t> opt;  // indices of optimised targets
  std::set<double> betas;        // the dips each evaluation runs
  std::filesystem::path out;
  int workers = 0;
  const std::function<void(const std::string&)>& log;
  CalibrationResult& result;

  CalibrationIteration operator()(const std::vector<double>& p, const char* kind) {
    const Scene s = scene_for(spec, p);
    StudySpec st = dip_study(s, "calibration");
    st.dips.assign(betas.begin(), betas.end());
    const auto dir = out / fmt::format("eval_{:02d}", result.evaluations);
    SweepOptions ro;
    ro.workers = workers;
    const auto results = run_cases(expand(st), dir, ro);
    ++result.evaluations;
    CalibrationIteration it;
    it.kind = kind;
    it.parameters = p;
    it.measured = measure_targets(spec, results);
    for (std::size_t j : opt)
      it.max_error = std::max(it.max_error, std::abs(it.measured[j] / spec.targets[j].value - 1));
    it.iteration = int(result.history.size());
    log(evaluation_line(spec, it));
    result.history.push_back(it);
    return it;
  }
  // log(measured / target) of the optimised targets: the residual the search drives to zero.
  Eigen::VectorXd residual(const CalibrationIteration& it) const {
    Eigen::VectorXd r(static_cast<Eigen::Index>(opt.size()));
    for (std::size_t j = 0; j < opt.size(); ++j)
      r[long(j)] = std::log(it.measured[opt[j]] / spec.targets[opt[j]].value);
    return r;
  }
  Eigen::VectorXd to_x(const std::vector<double>& p) const {
    Eigen::VectorXd x(static_cast<Eigen::Index>(p.size()));
    for (std::size_t i = 0; i < p.size(); ++i) x[long(i)] = std::log(p[i]);
    return x;
  }
  // The parameters of a point in log space, clamped to [min, max].
  std::vector<double> to_p(const Eigen::VectorXd& x) const {
    std::vector<double> p(spec.parameters.size());
    for (std::size_t i = 0; i < p.size(); ++i)
      p[i] = std::clamp(std::exp(x[long(i)]), spec.parameters[i].min, spec.parameters[i].max);
    return p;
  }
};

// Levenberg-Marquardt from the point x (residual r) with Broyden's updates of the Jacobian J (all three updated in
// place), until the best evaluation is within the tolerance, the step vanishes or spec.max_iterations steps are
// spent. A step that does not lower the residual is kept in the history as "rejected" and raises the damping.
void broyden_search(Evaluator& evaluate, Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd& J) {
  const CalibrationSpec& spec = evaluate.spec;
  CalibrationResult& result = evaluate.result;
  double lambda = 1e-3;
  for (int iter = 0; iter < spec.max_iterations && result.best.max_error > spec.tolerance; ++iter) {
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    Eigen::MatrixXd A = JtJ;
    A.diagonal() += lambda * JtJ.diagonal().cwiseMax(1e-12);
    Eigen::VectorXd dx = A.ldlt().solve(-J.transpose() * r);
    const double cap = std::log(3.0);
    if (dx.cwiseAbs().maxCoeff() > cap) dx *= cap / dx.cwiseAbs().maxCoeff();
    const Eigen::VectorXd xn = evaluate.to_x(evaluate.to_p(x + dx));
    const Eigen::VectorXd step = xn - x;
    if (step.norm() < 1e-6) break;
    const auto it = evaluate(evaluate.to_p(xn), "step");
    const Eigen::VectorXd rn = evaluate.residual(it);
    J += ((rn - r) - J * step) * step.transpose() / step.squaredNorm();  // Broyden's update
    if (it.max_error < result.best.max_error) result.best = it;
    if (rn.squaredNorm() < r.squaredNorm()) {
      x = xn, r = rn, lambda = std::max(lambda / 3, 1e-6);
    } else {
      lambda *= 4;
      result.history.back().kind = "rejected";
    }
  }
}

// calibration.csv (every evaluation) and calibrated.toml (the best scene, its errors in a header).
void write_calibration(const CalibrationSpec& spec, const CalibrationResult& result, const std::filesystem::path& out) {
  std::string csv = "iteration,kind";
  for (const auto& p : spec.parameters) csv += "," + p.name;
  for (const auto& t : spec.targets) csv += "," + t.label() + "," + t.label() + "_target";
  csv += ",max_error\n";
  for (const auto& it : result.history) {
    csv += fmt::format("{},{}", it.iteration, it.kind);
    for (double v : it.parameters) csv += fmt::format(",{:.9g}", v);
    for (std::size_t k = 0; k < spec.targets.size(); ++k)
      csv += fmt::format(",{:.9g},{:.9g}", it.measured[k], spec.targets[k].value);
    csv += fmt::format(",{:.6g}\n", it.max_error);
  }
  io::write_text_atomic(out / "calibration.csv", csv);
  std::string header = fmt::format("# Calibrated by `rbdem calibrate` in {} evaluations ({:.0f} s): max target error {:.1f} % "
                                   "({}).\n",
                                   result.evaluations, result.wall_seconds, 100 * result.best.max_error,
                                   result.converged ? "converged" : "NOT converged within the iteration limit");
  for (std::size_t k = 0; k < spec.targets.size(); ++k)
    header += fmt::format("#   {} = {:.4g} (target {:.4g})\n", spec.targets[k].label(), result.best.measured[k],
                          spec.targets[k].value);
  io::write_text_atomic(out / "calibrated.toml", header + "\n" + to_toml(result.scene));
}

}  // namespace

CalibrationResult calibrate(const CalibrationSpec& spec, const std::filesystem::path& out, int workers,
                            const std::function<void(const std::string&)>& log) {
  const auto t0 = std::chrono::steady_clock::now();
  CalibrationResult result;
  Evaluator evaluate{spec, {}, evaluation_dips(spec), out, workers, log, result};
  for (std::size_t k = 0; k < spec.targets.size(); ++k)
    if (optimised(spec.targets[k])) evaluate.opt.push_back(k);
  const std::size_t n = spec.parameters.size(), m = evaluate.opt.size();

  std::vector<double> p0(n);
  for (std::size_t i = 0; i < n; ++i) p0[i] = spec.parameters[i].start;
  CalibrationIteration cur = evaluate(p0, "start");
  result.best = cur;
  Eigen::VectorXd x = evaluate.to_x(p0), r = evaluate.residual(cur);
  // Initial Jacobian d log(measured) / d log(parameter) by forward differences of 15 %.
  Eigen::MatrixXd J(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(n));
  const double h = std::log(1.15);
  if (cur.max_error > spec.tolerance)
    for (std::size_t i = 0; i < n; ++i) {
      Eigen::VectorXd xi = x;
      xi[long(i)] += h;
      const auto it = evaluate(evaluate.to_p(xi), "jacobian");
      J.col(long(i)) = (evaluate.residual(it) - r) / h;
      if (it.max_error < result.best.max_error) result.best = it;
    }
  broyden_search(evaluate, x, r, J);
  result.converged = result.best.max_error <= spec.tolerance;
  result.scene = scene_for(spec, result.best.parameters);
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_calibration(spec, result, out);
  return result;
}

}  // namespace rbdem::study
