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

#include "dem/driver/registry.hpp"
#include "io/results.hpp"
#include "study/toml_file.hpp"

namespace rbdem::study {

const std::vector<TargetQuantity>& target_quantities() {
  static const std::vector<TargetQuantity> q{
      {"strength", "ucs", true, true, "uniaxial peak stress at beta (Pa)"},
      {"modulus", "ucs", true, true, "uniaxial Young's modulus E50 at beta (Pa)"},
      {"poisson", "ucs", true, true, "uniaxial Poisson's ratio at half the peak at beta"},
      {"tensile_strength", "brazilian", true, true, "Brazilian tensile strength at beta (Pa)"},
      {"friction_angle", "triaxial", true, true, "friction angle of the confined envelope at beta (deg)"},
      {"cohesion", "triaxial", true, true, "cohesion of the confined envelope at beta (Pa)"},
      {"min_strength", "ucs", false, true, "least uniaxial peak over dips (Pa)"},
      {"anisotropy", "ucs", false, true, "peak at 90 deg over the least peak over dips"},
      {"min_angle", "ucs", false, false, "dip of the least peak (deg; checked, not optimised)"},
  };
  return q;
}

namespace {

const TargetQuantity& quantity_of(const std::string& name) {
  for (const auto& q : target_quantities())
    if (name == q.name) return q;
  throw std::invalid_argument("unknown target quantity " + name);
}

}  // namespace

std::string CalibrationTarget::label() const {
  return quantity_of(quantity).at_dip ? fmt::format("{}@{:g}", quantity, beta) : quantity;
}

namespace {

double number(const toml::node* node, const std::string& where) {
  if (!node) throw SceneError(where + ": missing");
  return toml_number(*node, where);
}

bool optimised(const CalibrationTarget& t) { return quantity_of(t.quantity).optimised; }

std::vector<double> numbers(const toml::node* node, const std::string& where) {
  std::vector<double> v;
  const toml::array* a = node ? node->as_array() : nullptr;
  if (!a) throw SceneError(where + ": expected an array of numbers, e.g. [0, 5e6, 10e6]");
  for (const auto& x : *a) v.push_back(number(&x, where));
  return v;
}

}  // namespace

CalibrationSpec load_calibration(const std::filesystem::path& path, const std::vector<std::string>& overrides) {
  const std::string where = path.string();
  const toml::table root = read_toml_file(path, "calibration", "shipped: scenes/calibrate_paper.toml");
  CalibrationSpec spec;
  for (const auto& [k, v] : root)
    if (k != "calibrate" && k != "parameter" && k != "target")
      throw SceneError(fmt::format("{}: unknown top-level key '{}' (expected [calibrate], [[parameter]], [[target]])",
                                   where, k.str()));
  if (const toml::table* c = root["calibrate"].as_table()) {
    check_keys(*c, {"base", "tolerance", "max_iterations", "dips", "realizations", "confining", "set"},
               where + " [calibrate]");
    if (auto b = c->get_as<std::string>("base"); b && !b->get().empty())
      spec.base = load_scene_file(path.parent_path() / b->get());
    if (c->contains("tolerance")) spec.tolerance = number(c->get("tolerance"), where + " calibrate.tolerance");
    if (c->contains("max_iterations"))
      spec.max_iterations = int(number(c->get("max_iterations"), where + " calibrate.max_iterations"));
    if (c->contains("dips")) spec.dips = numbers(c->get("dips"), where + " calibrate.dips");
    if (c->contains("confining")) spec.confining = numbers(c->get("confining"), where + " calibrate.confining");
    if (c->contains("realizations"))
      spec.realizations = int(number(c->get("realizations"), where + " calibrate.realizations"));
    if (auto set = c->get_as<toml::table>("set"))
      for (const auto& [k, v] : *set)
        set_parameter(spec.base, k.str(), toml_value_text(v, where + " " + std::string(k.str())));
  }
  for (const auto& o : overrides) apply_override(spec.base, o);
  if (!(spec.tolerance > 0 && spec.tolerance < 1))
    throw SceneError(where + ": calibrate.tolerance must lie in (0, 1), e.g. 0.03");
  check_realizations(spec.realizations, spec.base);
  if (spec.confining.size() < 2 || std::set<double>(spec.confining.begin(), spec.confining.end()).size() < 2)
    throw SceneError(where + ": calibrate.confining needs two different pressures at least (Pa), e.g. [0, 5e6, 10e6]");
  if (auto params = root["parameter"].as_array())
    for (const auto& node : *params) {
      const toml::table* t = node.as_table();
      if (!t) throw SceneError(where + ": [[parameter]] must be tables");
      check_keys(*t, {"name", "keys", "ratios", "start", "min", "max"}, where + " [[parameter]]");
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
      check_keys(*t, {"quantity", "beta", "value"}, where + " [[target]]");
      CalibrationTarget g;
      if (auto q = t->get_as<std::string>("quantity")) g.quantity = q->get();
      if (std::none_of(target_quantities().begin(), target_quantities().end(),
                       [&](const TargetQuantity& q) { return g.quantity == q.name; })) {
        std::string list;
        for (const auto& q : target_quantities()) list += (list.empty() ? "" : ", ") + std::string(q.name);
        throw SceneError(fmt::format("{}: target quantity '{}' unknown ({})", where, g.quantity, list));
      }
      if (t->contains("beta")) g.beta = number(t->get("beta"), where + " target beta");
      if (t->contains("beta") && !quantity_of(g.quantity).at_dip)
        throw SceneError(fmt::format("{}: target {} reads the dip curve over calibrate.dips and takes no beta",
                                     where, g.quantity));
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

// The runs one evaluation needs, by test: the dips of the targets read at one dip and, for the targets read from the
// uniaxial dip curve (min_strength, anisotropy, min_angle), calibrate.dips.
struct Plan {
  std::map<std::string, std::set<double>> dips;  // test -> dips
};

Plan evaluation_plan(const CalibrationSpec& spec) {
  Plan plan;
  for (const auto& t : spec.targets) {
    const TargetQuantity& q = quantity_of(t.quantity);
    std::set<double>& dips = plan.dips[q.test];
    if (q.at_dip) dips.insert(t.beta);
    else dips.insert(spec.dips.begin(), spec.dips.end());
  }
  return plan;
}

// The cases of one test of an evaluation on the scene `s`: its dips, each on calibrate.realizations meshes and, for
// the confined test, at every calibrate.confining pressure.
std::vector<Case> plan_cases(const CalibrationSpec& spec, const Scene& s, const std::string& test,
                             const std::set<double>& dips) {
  StudySpec st = dip_study(s, "calibration");
  st.test = test;
  for (const auto& [key, value] : protocol_info(test).scene_defaults) set_parameter(st.base, key, value);
  st.dips.assign(dips.begin(), dips.end());
  st.realizations = spec.realizations;
  if (test == "triaxial") {
    Axis a;
    a.name = "confining";
    std::vector<std::string> values;
    for (double p : spec.confining) a.labels.push_back(fmt::format("{:g}", p)), values.push_back(fmt::format("{}", p));
    a.values.push_back({"loading.confining_pressure", values});
    st.axes.push_back(a);
  }
  return expand(st);
}

// Runs `cases` under `dir`. A run whose summary says it was not quasi-static runs again at half, then a quarter of
// its platen speed (its platen_velocity, or its transit_strain_fraction where the speed follows the rock; under
// dir/slower_2x, slower_4x) and its result replaces the first, unless a disc crushed under its flats; `quasi_static`
// says whether every run ends quasi-static.
std::vector<CaseResult> run_quasi_static(const std::vector<Case>& cases, const std::filesystem::path& dir,
                                         const SweepOptions& ro, const std::function<void(const std::string&)>& log,
                                         bool& quasi_static) {
  auto results = run_cases(cases, dir, ro);
  const auto dynamic = [](const CaseResult& r) { return !r.summary.value("quasi_static", true); };
  // A disc that crushed under its flats (its summary's crushed_at_flats) is dynamic at any platen speed: it is not
  // run again, and its reason names the flats (docs/model.md, "The Brazilian test").
  const auto crushed = [](const CaseResult& r) {
    const auto v = r.summary.find("crushed_at_flats");  // null where the run did not complete
    return v != r.summary.end() && v->is_number() && v->get<double>() > 0.5;
  };
  for (int factor = 2; factor <= 4; factor *= 2) {
    std::vector<std::size_t> slow;
    std::vector<Case> again;
    for (std::size_t k = 0; k < results.size(); ++k) {
      if (!dynamic(results[k])) continue;
      if (crushed(results[k])) {
        if (log && factor == 2)
          log(fmt::format("   {} {} not quasi-static ({}): not run again slower", cases[k].test, cases[k].id,
                          results[k].summary.value("quasi_static_reason", std::string())));
        continue;
      }
      Case c = cases[k];
      // A speed that follows the rock (loading.transit_strain_fraction) slows down through its fraction.
      const bool follows = c.scene.loading.transit_strain_fraction > 0.0;
      double& speed = follows ? c.scene.loading.transit_strain_fraction : c.scene.loading.platen_velocity;
      speed /= factor;
      if (log)
        log(fmt::format("   {} {} not quasi-static ({}): run again at loading.{} = {:g}{}", c.test, c.id,
                        results[k].summary.value("quasi_static_reason", std::string()),
                        follows ? "transit_strain_fraction" : "platen_velocity", speed, follows ? "" : " m/s"));
      slow.push_back(k), again.push_back(std::move(c));
    }
    if (slow.empty()) break;
    const auto redo = run_cases(again, dir / fmt::format("slower_{}x", factor), ro);
    for (std::size_t i = 0; i < slow.size(); ++i) results[slow[i]] = redo[i];
  }
  quasi_static = std::none_of(results.begin(), results.end(), dynamic);
  return results;
}

// What one evaluation measured: the mean summaries over the realizations by test and dip, and the confined envelope
// of each dip.
struct Readings {
  std::map<std::string, std::map<double, nlohmann::json>> at;  // test -> beta -> mean summary
  std::map<double, Envelope> envelope;                         // beta -> envelope of the confined runs
};

double reading(const Readings& rd, const std::string& test, double beta, const char* key, const CalibrationTarget& t) {
  const nlohmann::json* v = nullptr;
  if (auto i = rd.at.find(test); i != rd.at.end())
    if (auto j = i->second.find(beta); j != i->second.end()) v = &j->second;
  if (!v || !v->contains(key) || !(*v)[key].is_number())
    throw std::runtime_error(fmt::format("target {}: the {} run at beta = {:g} reports no {} (see its summary.json)",
                                         t.label(), test, beta, key));
  return (*v)[key].get<double>();
}

// Every target's quantity from one evaluation's readings.
std::vector<double> measure_targets(const CalibrationSpec& spec, const Readings& rd) {
  std::vector<double> measured;
  for (const auto& t : spec.targets) {
    double v = 0;
    if (t.quantity == "strength") v = reading(rd, "ucs", t.beta, "peak_stress_pa", t);
    else if (t.quantity == "modulus") v = reading(rd, "ucs", t.beta, "youngs_modulus_pa", t);
    else if (t.quantity == "poisson") v = reading(rd, "ucs", t.beta, "poisson_ratio_at_half_peak", t);
    else if (t.quantity == "tensile_strength") v = reading(rd, "brazilian", t.beta, "tensile_strength_pa", t);
    else if (t.quantity == "friction_angle") v = rd.envelope.at(t.beta).friction_deg;
    else if (t.quantity == "cohesion") v = rd.envelope.at(t.beta).cohesion_pa;
    else {
      double mn = std::numeric_limits<double>::infinity(), arg = 0;
      for (double d : spec.dips) {
        const double s_d = reading(rd, "ucs", d, "peak_stress_pa", t);
        if (s_d < mn) mn = s_d, arg = d;
      }
      if (t.quantity == "min_strength") v = mn;
      else if (t.quantity == "min_angle") v = arg;
      else v = reading(rd, "ucs", 90.0, "peak_stress_pa", t) / mn;  // anisotropy
    }
    measured.push_back(v);
  }
  return measured;
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
  if (!it.quasi_static) line += " | NOT quasi-static";
  if (it.reused) line += " (runs reused)";
  return line;
}

// The evaluations of one calibration: each runs the dip study of a parameter set under out/eval_NN, measures the
// targets, logs a line and is kept in result.history. Also the maps between parameters and the search's log space.
struct Evaluator {
  const CalibrationSpec& spec;
  const CalibrateOptions& options;
  std::filesystem::path out;
  CalibrationResult& result;
  std::vector<std::size_t> opt;  // indices of optimised targets
  Plan plan = evaluation_plan(spec);

  CalibrationIteration operator()(const std::vector<double>& p, const char* kind) {
    const Scene s = scene_for(spec, p);
    const auto dir = out / fmt::format("eval_{:02d}", result.evaluations);
    CalibrationIteration it;
    it.reused = true;
    SweepOptions ro;
    ro.workers = options.workers;
    ro.cancel = options.cancel;
    if (options.progress)
      ro.on_done = [&](const CaseResult& r) {
        options.progress(fmt::format("   eval {:02d} {} {}: peak {:.2f} MPa, {} steps, {:.1f} s", result.evaluations,
                                     r.c.test, r.c.id, r.summary.value("peak_stress_pa", 0.0) / 1e6,
                                     r.summary.value("steps", 0L), r.wall_seconds));
      };
    Readings rd;
    for (const auto& [test, dips] : plan.dips) {
      bool quasi_static = true;
      const auto results = run_quasi_static(plan_cases(spec, s, test, dips), test == "ucs" ? dir : dir / test, ro,
                                            options.log, quasi_static);
      it.quasi_static = it.quasi_static && quasi_static;
      for (const auto& r : results) it.reused = it.reused && r.reused;
      for (const auto& m : realization_means(results)) rd.at[test][m.mean.c.beta] = m.mean.summary;
      if (test == "triaxial")
        for (const auto& e : write_envelopes(results, dir / test)) rd.envelope[e.beta_deg] = e;
    }
    ++result.evaluations;
    it.kind = kind;
    it.parameters = p;
    it.measured = measure_targets(spec, rd);
    for (std::size_t j : opt)
      it.max_error = std::max(it.max_error, std::abs(it.measured[j] / spec.targets[j].value - 1));
    it.iteration = int(result.history.size());
    if (options.log) options.log(evaluation_line(spec, it));
    result.history.push_back(it);
    return it;
  }
  // log(measured / target) of the optimised targets: the residual the search drives to zero.
  Eigen::VectorXd residual(const CalibrationIteration& it) const {
    Eigen::VectorXd r(static_cast<Eigen::Index>(opt.size()));
    for (std::size_t j = 0; j < opt.size(); ++j)
      // A quantity of the wrong sign (a negative cohesion intercept) counts as a million times too small.
      r[long(j)] = std::log(std::max(it.measured[opt[j]] / spec.targets[opt[j]].value, 1e-6));
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
  csv += ",max_error,quasi_static\n";
  for (const auto& it : result.history) {
    csv += fmt::format("{},{}", it.iteration, it.kind);
    for (double v : it.parameters) csv += fmt::format(",{:.9g}", v);
    for (std::size_t k = 0; k < spec.targets.size(); ++k)
      csv += fmt::format(",{:.9g},{:.9g}", it.measured[k], spec.targets[k].value);
    csv += fmt::format(",{:.6g},{}\n", it.max_error, it.quasi_static ? 1 : 0);
  }
  io::write_text_atomic(out / "calibration.csv", csv);
  std::string header = fmt::format("# Calibrated by `rbdem calibrate` in {} evaluations ({:.0f} s): max target error {:.1f} % "
                                   "({}).\n",
                                   result.evaluations, result.wall_seconds, 100 * result.best.max_error,
                                   result.converged              ? "converged"
                                   : result.best.quasi_static ? "NOT converged within the iteration limit"
                                                              : "NOT converged: its best evaluation is not quasi-static");
  for (std::size_t k = 0; k < spec.targets.size(); ++k)
    header += fmt::format("#   {} = {:.4g} (target {:.4g})\n", spec.targets[k].label(), result.best.measured[k],
                          spec.targets[k].value);
  io::write_text_atomic(out / "calibrated.toml", header + "\n" + to_toml(result.scene));
}

}  // namespace

CalibrationResult calibrate(const CalibrationSpec& spec, const std::filesystem::path& out,
                            const CalibrateOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  CalibrationResult result;
  Evaluator evaluate{spec, options, out, result, {}};
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
  result.converged = result.best.max_error <= spec.tolerance && result.best.quasi_static;
  result.scene = scene_for(spec, result.best.parameters);
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_calibration(spec, result, out);
  return result;
}

}  // namespace rbdem::study
