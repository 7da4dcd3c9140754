// Parameter studies. See study.hpp.
#include "study/study.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "common/parallel_map.hpp"
#include "theory/elasticity.hpp"
#include "dem/laws/parallel_bond.hpp"
#include "dem/mesh_cache.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/driver/registry.hpp"
#include "io/results.hpp"
#include "io/run_case.hpp"
#include "study/toml_file.hpp"

namespace rbdem::study {

namespace {

std::string case_value_label(const std::string& s) {
  std::string out;
  for (char c : s) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '_') ? c : '_';
  return out;
}

std::string beta_label(double beta) { return fmt::format("beta={:g}", beta); }

}  // namespace

StudySpec dip_study(const Scene& base, std::string name) {
  StudySpec s;
  s.name = std::move(name);
  s.description = "peak strength versus joint dip on the scene's specimen";
  s.base = base;
  return s;
}

StudySpec load_study(const std::filesystem::path& path) {
  const std::string where = path.string();
  const toml::table root = read_toml_file(path, "study", "shipped studies are in scenes/");
  check_keys(root, {"study", "axis"}, where);
  StudySpec spec;
  spec.source = path;
  const toml::table* st = root["study"].as_table();
  if (!st) throw SceneError(where + ": missing [study] table (name, base, dips, set)");
  check_keys(*st, {"name", "description", "test", "base", "dips", "realizations", "set"}, where + " [study]");
  if (auto t = st->get_as<std::string>("test")) {
    spec.test = t->get();
    try {
      protocol_info(spec.test);
    } catch (const SceneError& e) {
      throw SceneError(fmt::format("{}: study.test: {}", where, e.what()));
    }
  }
  spec.name = st->get_as<std::string>("name") ? st->get_as<std::string>("name")->get() : path.stem().string();
  if (auto d = st->get_as<std::string>("description")) spec.description = d->get();
  if (auto b = st->get_as<std::string>("base"); b && !b->get().empty()) {
    const auto base_path = path.parent_path() / b->get();
    spec.base = load_scene_file(base_path);
  }
  if (auto dips = st->get_as<toml::array>("dips")) {
    spec.dips.clear();
    for (const auto& d : *dips) {
      const double beta = toml_number(d, where + " study.dips");
      if (!(beta >= 0 && beta <= 90))
        throw SceneError(fmt::format("{}: study.dips holds {}: dips must lie in [0, 90] deg", where, beta));
      spec.dips.push_back(beta);
    }
    if (spec.dips.empty()) throw SceneError(where + ": study.dips is empty: list at least one dip");
  }
  if (const toml::node* n = st->get("realizations")) {
    const auto r = n->as_integer();
    if (!r || r->get() < 1 || r->get() > max_realizations)
      throw SceneError(fmt::format("{}: study.realizations = {} is not allowed: give a whole number of meshes per case "
                                   "in [1, {}] (1 = one mesh, the default; 5 gives a mean and a 95 % interval)",
                                   where, toml_value_text(*n, where + " study.realizations"), max_realizations));
    spec.realizations = int(r->get());
  }
  if (spec.base.mesh.file.empty())  // the test's own keys (a disc for the Brazilian test), before the study's set
    for (const auto& [key, value] : protocol_info(spec.test).scene_defaults) set_parameter(spec.base, key, value);
  if (auto set = st->get_as<toml::table>("set"))
    for (const auto& [k, v] : *set)
      set_parameter(spec.base, k.str(), toml_value_text(v, where + " study.set." + std::string(k.str())));
  validate(spec.base);

  if (auto axes = root["axis"].as_array()) {
    for (const auto& node : *axes) {
      const toml::table* at = node.as_table();
      if (!at) throw SceneError(where + ": every [[axis]] must be a table");
      check_keys(*at, {"name", "labels", "set"}, where + " [[axis]]");
      Axis axis;
      if (auto n = at->get_as<std::string>("name")) axis.name = n->get();
      else throw SceneError(where + ": an [[axis]] has no name");
      const std::string aw = where + " axis '" + axis.name + "'";
      if (auto labels = at->get_as<toml::array>("labels"))
        for (const auto& l : *labels) axis.labels.push_back(toml_value_text(l, aw + " labels"));
      const toml::table* set = at->get_as<toml::table>("set");
      if (!set || set->empty()) throw SceneError(aw + ": needs a set table of varied keys");
      for (const auto& [k, v] : *set) {
        const std::string key(k.str());
        std::vector<std::string> values;
        if (auto arr = v.as_array()) {
          for (const auto& x : *arr) values.push_back(toml_value_text(x, aw + " " + key));
        } else if (auto tab = v.as_table()) {
          check_keys(*tab, {"of", "factors"}, aw + " " + key);
          auto of = tab->get_as<std::string>("of");
          auto factors = tab->get_as<toml::array>("factors");
          if (!of || !factors) throw SceneError(aw + " " + key + ": a scaled value needs `of` (a key) and `factors`");
          const double ref = std::stod(parameter_text(spec.base, of->get()));
          for (const auto& f : *factors) values.push_back(fmt::format("{}", ref * toml_number(f, aw + " " + key)));
        } else {
          throw SceneError(aw + " " + key + ": give a list of values or { of = \"key\", factors = [...] }");
        }
        if (axis.labels.empty())
          for (const auto& x : values) axis.labels.push_back(x);
        if (values.size() != axis.labels.size())
          throw SceneError(fmt::format("{} {}: {} values for {} labels; give one value per label", aw, key,
                                       values.size(), axis.labels.size()));
        // Validate every value now, not in the middle of a long run.
        for (const auto& x : values) {
          Scene probe = spec.base;
          set_parameter(probe, key, x);
        }
        axis.values.push_back({key, values});
      }
      spec.axes.push_back(axis);
    }
  }
  return spec;
}

void check_realizations(int realizations, const Scene& base) {
  if (realizations < 1 || realizations > max_realizations)
    throw SceneError(fmt::format("realizations = {} is not allowed: give a whole number of meshes per case in "
                                 "[1, {}] (1 = one mesh; 5 gives a mean and a 95 % interval)",
                                 realizations, max_realizations));
  if (realizations > 1 && !base.mesh.file.empty())
    throw SceneError(fmt::format("realizations = {} needs meshes rbdem makes, but the scene reads the user mesh "
                                 "mesh.file = \"{}\": drop mesh.file (or --mesh), or run one realization",
                                 realizations, base.mesh.file));
  if (realizations > 1 && base.mesh.seed > 1000000 - realizations + 1)
    throw SceneError(fmt::format("mesh.seed = {} leaves no room for {} realizations (seeds up to 1000000): use a "
                                 "smaller mesh.seed",
                                 base.mesh.seed, realizations));
}

std::vector<Case> expand(const StudySpec& spec) {
  std::vector<Case> partial(1);
  partial[0].scene = spec.base;
  partial[0].test = spec.test;
  for (const auto& axis : spec.axes) {
    std::vector<Case> next;
    for (const auto& c : partial)
      for (std::size_t l = 0; l < axis.labels.size(); ++l) {
        Case d = c;
        d.labels.push_back({axis.name, axis.labels[l]});
        for (const auto& [key, values] : axis.values) set_parameter(d.scene, key, values[l]);
        d.group += (d.group.empty() ? "" : "/") + axis.name + "=" + case_value_label(axis.labels[l]);
        next.push_back(std::move(d));
      }
    partial = std::move(next);
  }
  check_realizations(spec.realizations, spec.base);
  std::vector<Case> cases;
  for (const auto& c : partial)
    for (double beta : spec.dips)
      for (int r = 0; r < spec.realizations; ++r) {
        Case d = c;
        d.beta = beta;
        set_parameter(d.scene, "joint_set.dip_deg", fmt::format("{}", beta));
        d.point = (d.group.empty() ? "" : d.group + "/") + beta_label(beta);
        d.id = d.point;
        if (spec.realizations > 1) {
          // Seeds from the base scene's own, so that a study on mesh.seed = 10 runs the meshes 10, 11, ...
          d.realization = r;
          d.scene.mesh.seed = c.scene.mesh.seed + r;
          d.scene.mesh.strength_seed = c.scene.mesh.strength_seed + r;
          d.id += fmt::format("/seed={}", d.scene.mesh.seed);
        }
        validate(d.scene);
        protocol_info(d.test).check(d.scene);
        cases.push_back(std::move(d));
      }
  return cases;
}

namespace {

bool read_summary(const std::filesystem::path& file, const Scene& scene, nlohmann::json& out) {
  std::ifstream in(file);
  if (!in) return false;
  try {
    in >> out;
    // A case counts as done only with a complete result of the same scene: a run the watchdog stopped has
    // "completed": false, and a result left by another scene (an edited study, another rbdem's defaults) is rerun.
    return out.contains("peak_stress_pa") && out.contains("scene") && out.value("completed", true) == true &&
           out["scene"] == scene_json(scene);
  } catch (...) {
    return false;
  }
}

CaseResult run_one(const Case& c, const std::filesystem::path& dir, const std::atomic<bool>* cancel,
                   const std::atomic<int>* threads, int max_threads) {
  const auto t0 = std::chrono::steady_clock::now();
  std::filesystem::remove_all(dir);  // an interrupted run leaves partial files: start clean
  std::filesystem::create_directories(dir);
  io::CaseOptions co;
  co.out = dir;
  co.threads = max_threads;  // cases run side by side, each with the threads it is given (`threads`)
  co.run.cancel = cancel;
  co.run.thread_budget = threads;
  // The cores the case holds when it ends (one beside a running case, more once the others are done) compress its
  // result.h5.
  co.write_threads = [threads] { return threads ? threads->load() : 1; };
  const TestResult r = io::run_case(c.test, c.scene, co).result;
  if (!r.completed) throw std::runtime_error(r.watchdog_message);  // its summary says so; the case is not done
  CaseResult cr;
  cr.c = c;
  cr.summary = io::run_summary(c.scene, r);
  cr.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return cr;
}

}  // namespace

std::vector<int> share_cores(int cores, std::size_t holders, std::size_t running) {
  holders = std::max<std::size_t>({holders, running, 1});
  const std::size_t n = std::size_t(std::max(cores, 1));
  std::vector<int> t(running);
  for (std::size_t k = 0; k < running; ++k) t[k] = std::max(1, int(n / holders + (k < n % holders ? 1 : 0)));
  return t;
}

std::vector<CaseResult> run_cases(const std::vector<Case>& cases, const std::filesystem::path& out,
                                  const SweepOptions& options, int mpi_rank, int mpi_size) {
  std::filesystem::create_directories(out);
  std::vector<std::size_t> mine;
  for (std::size_t k = 0; k < cases.size(); ++k)
    if (int(k % std::size_t(std::max(mpi_size, 1))) == mpi_rank) mine.push_back(k);
  std::vector<CaseResult> results(cases.size());
  std::vector<char> have(cases.size(), 0);
  std::vector<std::size_t> todo;
  for (std::size_t k : mine) {
    nlohmann::json s;
    if (read_summary(out / cases[k].id / "summary.json", cases[k].scene, s)) {
      results[k].c = cases[k], results[k].summary = s, results[k].reused = true, have[k] = 1;
    } else {
      todo.push_back(k);
    }
  }
  // The cores of this process (--workers, else all) are shared by the cases running, as evenly as their number
  // allows; the cases that started first hold the cores left over. While cases wait in the queue a finished case's
  // cores go to the next; once the queue is empty they go to the cases still running, so the last and slowest cases
  // of a sweep end on all the cores. Results do not depend on the thread count.
  const int cores = std::max(1, options.workers > 0 ? options.workers : int(std::thread::hardware_concurrency()));
  const int workers = std::max(1, std::min(int(todo.size()), cores));
  auto cancel_set = [&]() { return options.cancel && options.cancel->load(); };
  std::mutex lock;
  std::string first_error;
  std::size_t done = mine.size() - todo.size();
  const auto threads = std::make_unique<std::atomic<int>[]>(todo.size());
  std::vector<char> running(todo.size(), 0);
  for (std::size_t n = 0; n < todo.size(); ++n) threads[n] = 1;
  std::size_t started = 0;
  // Under `lock`, when a case starts or ends. While cases wait, a share is kept for each worker (one is about to
  // take the next case).
  auto share = [&]() {
    std::vector<std::size_t> now;
    for (std::size_t n = 0; n < todo.size(); ++n)
      if (running[n]) now.push_back(n);
    const std::vector<int> t =
        share_cores(cores, started < todo.size() ? std::size_t(workers) : now.size(), now.size());
    for (std::size_t k = 0; k < now.size(); ++k) threads[now[k]] = t[k];
  };
  // One case: a failed case is recorded and the others go on; a cancelled one throws Cancelled, which stops the
  // workers (parallel_map hands out no more cases) and leaves run_cases.
  auto run_case = [&](std::size_t n) {
    if (cancel_set()) throw Cancelled();
    const std::size_t k = todo[n];
    {
      std::lock_guard<std::mutex> g(lock);
      running[n] = 1, ++started;
      share();
    }
    try {
      CaseResult r = run_one(cases[k], out / cases[k].id, options.cancel, &threads[n], cores);
      std::lock_guard<std::mutex> g(lock);
      running[n] = 0;
      share();
      results[k] = std::move(r);
      have[k] = 1;
      ++done;
      if (options.progress)
        fmt::print(stderr, "[{}/{}] {:<40} peak {:8.2f} MPa  {:<26} {:6.1f} s\n", done, mine.size(), cases[k].id,
                   results[k].summary["peak_stress_pa"].get<double>() / 1e6,
                   results[k].summary["failure_mode"].get<std::string>(), results[k].wall_seconds);
      if (options.on_done) options.on_done(results[k]);
    } catch (const RunCancelled&) {
      {
        std::lock_guard<std::mutex> g(lock);
        running[n] = 0;
        std::filesystem::remove_all(out / cases[k].id);
      }
      throw Cancelled();
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> g(lock);
      running[n] = 0;
      share();
      if (first_error.empty()) first_error = fmt::format("case {}: {}", cases[k].id, e.what());
    }
  };
  parallel_map(todo.size(), workers, run_case);
  if (cancel_set()) throw Cancelled();
  if (!first_error.empty()) throw std::runtime_error(first_error);
  std::vector<CaseResult> list;
  for (std::size_t k = 0; k < cases.size(); ++k)
    if (have[k]) list.push_back(results[k]);
  return list;
}

std::vector<CaseResult> collect(const std::vector<Case>& cases, const std::filesystem::path& out) {
  std::vector<CaseResult> list;
  for (const auto& c : cases) {
    CaseResult r;
    if (read_summary(out / c.id / "summary.json", c.scene, r.summary)) {
      r.c = c, r.reused = true;
      list.push_back(std::move(r));
    }
  }
  return list;
}

// Jaeger's strength with the joint's effective interface envelope (contact_law.hpp: the linear part shares the
// traction with the bond), or with the joint bonds' own cohesion and friction (`bond_values`). With a second joint
// set, the weaker of the two planes of weakness governs (docs/theory.md, "Two planes of weakness"); a set with rock
// bridges slides on Jennings' combined envelope of joint and rock.
double jaeger_for(const Scene& scene, double beta, double strength_90, bool bond_values) {
  constexpr double deg = std::numbers::pi / 180.0;
  auto envelope = [&](const MaterialParams& m) {
    const double tan_phi = std::tan(m.friction_deg * deg);
    return bond_values ? MohrCoulomb{m.cohesion, tan_phi}
                       : interface_envelope(m.cohesion, tan_phi, m.contact_friction, m.slip_when_bonded);
  };
  auto sliding = [&](const MaterialParams& j, double dip, double persistence) {
    // Jennings' plane of a non-persistent joint: joint over the fraction k of the plane, rock bridges over the rest,
    // c = k c_j + (1 - k) c_r and tan phi = k tan phi_j + (1 - k) tan phi_r (docs/theory.md).
    const MohrCoulomb joint = envelope(j), rock = envelope(scene.rock);
    const double k = persistence;
    const MohrCoulomb env = k >= 1.0 ? joint
                                     : MohrCoulomb{k * joint.cohesion + (1.0 - k) * rock.cohesion,
                                                   k * joint.tan_phi + (1.0 - k) * rock.tan_phi};
    const double phi_deg = std::atan(env.tan_phi) / deg;
    const double b = dip > 90.0 ? 180.0 - dip : dip;  // the plane's angle to sigma_3 (symmetric about 90 deg)
    return theory::jaeger_strength({env.cohesion, phi_deg, strength_90, scene.loading.confining_pressure}, b);
  };
  double s = strength_90;
  if (scene.joint_set.enabled) s = std::min(s, sliding(scene.joint, beta, scene.joint_set.persistence));
  if (scene.joint_set2.enabled) {
    s = std::min(s, sliding(scene.joint2, second_set_dip_deg(scene, beta), scene.joint_set2.persistence));
  }
  return s;
}

double student_t975(int dof) {
  // t_{0.975, dof} for dof = 1 .. 30 (the regularized incomplete beta function solved to 20 digits).
  static constexpr double table[30] = {
      12.706204736, 4.302652730, 3.182446305, 2.776445105, 2.570581836, 2.446911851, 2.364624252, 2.306004135,
      2.262157163,  2.228138852, 2.200985160, 2.178812830, 2.160368656, 2.144786688, 2.131449546, 2.119905299,
      2.109815578,  2.100922040, 2.093024054, 2.085963447, 2.079613845, 2.073873068, 2.068657610, 2.063898562,
      2.059538553,  2.055529439, 2.051830516, 2.048407142, 2.045229642, 2.042272456};
  if (dof < 1) throw std::invalid_argument(fmt::format("student_t975: {} degrees of freedom (need at least 1)", dof));
  if (dof <= 30) return table[dof - 1];
  const double z = 1.959963984540054, v = double(dof), z2 = z * z;
  return z + z * (z2 + 1) / (4 * v) + z * ((5 * z2 + 16) * z2 + 3) / (96 * v * v) +
         z * (((3 * z2 + 19) * z2 + 17) * z2 - 15) / (384 * v * v * v) +
         z * ((((79 * z2 + 776) * z2 + 1482) * z2 - 1920) * z2 - 945) / (92160 * v * v * v * v);
}

SampleStats sample_stats(const std::vector<double>& values) {
  SampleStats st;
  st.n = int(values.size());
  if (st.n == 0) return st;
  for (double v : values) st.mean += v;
  st.mean /= double(st.n);
  if (st.n == 1) {
    st.ci95 = std::nan("");
    return st;
  }
  double ss = 0;
  for (double v : values) ss += (v - st.mean) * (v - st.mean);
  st.sd = std::sqrt(ss / double(st.n - 1));
  st.ci95 = student_t975(st.n - 1) * st.sd / std::sqrt(double(st.n));
  return st;
}

namespace {

// The mean of every numeric field of the summaries (nested objects such as "cracks" too); text fields take
// their most frequent value (the first seen on a tie), anything else the first summary's.
nlohmann::json mean_summary(const std::vector<const nlohmann::json*>& summaries) {
  nlohmann::json out = *summaries.front();
  for (auto it = out.begin(); it != out.end(); ++it) {
    const std::string& key = it.key();
    if (it->is_number() || it->is_null()) {
      // The mean of the realizations where the value is defined (a signal such as the crack damage stress may be
      // null in some); null where none defines it.
      double sum = 0;
      int defined = 0;
      for (const auto* s : summaries)
        if (s->contains(key) && (*s)[key].is_number()) sum += (*s)[key].get<double>(), ++defined;
      if (defined > 0) *it = sum / double(defined);
    } else if (it->is_object()) {
      std::vector<const nlohmann::json*> inner;
      for (const auto* s : summaries)
        if (s->contains(key) && (*s)[key].is_object()) inner.push_back(&(*s)[key]);
      *it = mean_summary(inner);
    } else if (it->is_string()) {
      std::map<std::string, int> count;
      std::string best = it->get<std::string>();
      for (const auto* s : summaries)
        if (const auto v = s->value(key, std::string()); ++count[v] > count[best]) best = v;
      *it = best;
    }
  }
  return out;
}

std::string fmt_count(const nlohmann::json& v) { return fmt::format("{:.10g}", v.get<double>()); }

// The columns of one row of table.csv (and realizations.csv) after its id, group and axis labels.
std::string case_columns(const CaseResult& r, double strength_90) {
  const auto& s = r.summary;
  const auto& c = s["cracks"];
  const bool brazilian = protocol_info(r.c.test).tensile;
  std::string t = fmt::format(",{:g},{:.9g},{:.9g},{:.9g},{},{:.4g},{:.4g},{},{},{},{},{},{},{:.4g},{:.9g},{:.9g}",
                              r.c.beta, s["peak_stress_pa"].get<double>(), s["strain_at_peak"].get<double>(),
                              s["youngs_modulus_pa"].get<double>(), s["failure_mode"].get<std::string>(),
                              s.value("crack_band_angle_deg", 0.0), s.value("tensile_fraction", 0.0),
                              fmt_count(c["rock_tensile"]), fmt_count(c["rock_shear"]), fmt_count(c["joint_tensile"]),
                              fmt_count(c["joint_shear"]), fmt_count(s["steps"]), s.value("stop_reason", std::string()),
                              s.value("platen_force_mismatch", 0.0),
                              brazilian ? std::nan("") : jaeger_for(r.c.scene, r.c.beta, strength_90),
                              brazilian ? std::nan("") : jaeger_for(r.c.scene, r.c.beta, strength_90, true));
  t += fmt::format(",{},{:.9g},{:.9g},{:.6g},{:.9g},{:.9g},{:g}", r.c.test, s.value("confining_pressure_pa", 0.0),
                   s.value("deviator_at_peak_pa", std::nan("")), s.value("lateral_strain_at_peak", 0.0),
                   s.value("tensile_strength_pa", std::nan("")), s.value("peak_load_n", std::nan("")),
                   s.value("layer_angle_deg", std::nan("")));
  return t;
}

const char* case_header =
    "beta_deg,peak_stress_pa,strain_at_peak,youngs_modulus_pa,failure_mode,crack_band_angle_deg,"
    "tensile_fraction,cracks_rock_tensile,cracks_rock_shear,cracks_joint_tensile,cracks_joint_shear,steps,"
    "stop_reason,platen_force_mismatch,jaeger_pa,jaeger_bond_pa,test,confining_pressure_pa,deviator_at_peak_pa,"
    "lateral_strain_at_peak,tensile_strength_pa,peak_load_n,layer_angle_deg";

}  // namespace

std::vector<PointResult> realization_means(const std::vector<CaseResult>& results) {
  std::vector<PointResult> points;
  std::map<std::string, std::size_t> index;
  for (const auto& r : results) {
    const std::string key = r.c.point.empty() ? r.c.id : r.c.point;
    auto [it, fresh] = index.try_emplace(key, points.size());
    if (fresh) points.emplace_back();
    points[it->second].realizations.push_back(&r);
  }
  for (auto& p : points) {
    std::vector<const nlohmann::json*> summaries;
    std::vector<double> peaks, tensile;
    for (const auto* r : p.realizations) {
      summaries.push_back(&r->summary);
      peaks.push_back(r->summary["peak_stress_pa"].get<double>());
      if (r->summary.contains("tensile_strength_pa"))
        tensile.push_back(r->summary["tensile_strength_pa"].get<double>());
    }
    p.mean.c = p.realizations.front()->c;
    p.mean.summary = mean_summary(summaries);
    p.mean.reused = p.realizations.front()->reused;
    for (const auto* r : p.realizations) p.mean.wall_seconds += r->wall_seconds;
    p.peak = sample_stats(peaks);
    if (tensile.size() == peaks.size()) p.tensile = sample_stats(tensile);
  }
  return points;
}

std::vector<GroupSummary> write_tables(const std::vector<CaseResult>& all, const std::filesystem::path& out) {
  const bool realizations =
      std::any_of(all.begin(), all.end(), [](const CaseResult& r) { return r.c.realization >= 0; });
  const std::vector<PointResult> points = realization_means(all);
  std::vector<CaseResult> results;  // one per case: the means over its realizations
  for (const auto& p : points) results.push_back(p.mean);

  // Group strengths at beta = 90 (Jaeger's intact strength) and minima.
  std::map<std::string, std::vector<const CaseResult*>> groups;
  std::vector<std::string> order;
  for (const auto& r : results) {
    if (!groups.count(r.c.group)) order.push_back(r.c.group);
    groups[r.c.group].push_back(&r);
  }
  // Jaeger's intact strength per group: measured where no joint can slide, at beta = 90 deg (load along the layers),
  // else at 0 deg (across them). With two joint sets the second may slide at either: the larger of the two. A group
  // with neither case has none (NaN: "n/a" in the report), never its own largest peak, which would make Jaeger
  // agree with the run at that dip by construction.
  std::map<std::string, double> s90;
  for (const auto& [g, list] : groups) {
    double at90 = -1, at0 = -1;
    for (const auto* r : list) {
      const double p = r->summary["peak_stress_pa"].get<double>();
      if (r->c.beta == 90.0) at90 = p;
      if (r->c.beta == 0.0) at0 = p;
    }
    const bool two_sets = !list.empty() && list.front()->c.scene.joint_set2.enabled;
    const double anchor = two_sets ? std::max(at90, at0) : (at90 > 0 ? at90 : at0);
    s90[g] = anchor > 0 ? anchor : std::nan("");
  }

  std::vector<std::string> axis_names;
  if (!results.empty())
    for (const auto& [a, l] : results.front().c.labels) axis_names.push_back(a);
  std::string head = "id,group";
  for (const auto& a : axis_names) head += "," + a;
  auto row_start = [](const CaseResult& r, const std::string& id) {
    std::string t = id + "," + r.c.group;
    for (const auto& [a, l] : r.c.labels) t += "," + l;
    return t;
  };
  std::string t = head + "," + case_header;
  if (realizations)
    t += ",realizations,peak_stress_sd_pa,peak_stress_ci95_pa,peak_stress_ci95_low_pa,peak_stress_ci95_high_pa,"
         "tensile_strength_sd_pa,tensile_strength_ci95_pa";
  t += "\n";
  for (const auto& p : points) {
    const CaseResult& r = p.mean;
    t += row_start(r, realizations ? r.c.point : r.c.id) + case_columns(r, s90[r.c.group]);
    if (realizations)
      t += fmt::format(",{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}", p.peak.n, p.peak.sd, p.peak.ci95,
                       p.peak.mean - p.peak.ci95, p.peak.mean + p.peak.ci95,
                       p.tensile.n ? p.tensile.sd : std::nan(""), p.tensile.n ? p.tensile.ci95 : std::nan(""));
    t += "\n";
  }
  io::write_text_atomic(out / "table.csv", t);
  if (realizations) {
    // Every realization as its own row; Jaeger with the case's mean strength at 90 deg, as in table.csv.
    std::string rt = head + ",point,realization,mesh_seed," + case_header + "\n";
    for (const auto& p : points)
      for (const auto* r : p.realizations)
        rt += row_start(*r, r->c.id) + fmt::format(",{},{},{}", r->c.point, r->c.realization, r->c.scene.mesh.seed) +
              case_columns(*r, s90[r->c.group]) + "\n";
    io::write_text_atomic(out / "realizations.csv", rt);
  }

  std::vector<GroupSummary> summaries;
  std::string g = "group,min_beta_deg,min_strength_pa,jaeger_min_beta_deg,jaeger_min_pa,strength_90_pa,"
                  "anisotropy_ratio\n";
  for (const auto& name : order) {
    GroupSummary gs;
    gs.group = name;
    gs.min_strength_pa = std::numeric_limits<double>::infinity();
    const Scene* scene = nullptr;
    for (const auto* r : groups[name]) {
      const double p = r->summary["peak_stress_pa"].get<double>();
      if (p < gs.min_strength_pa) gs.min_strength_pa = p, gs.min_beta_deg = r->c.beta;
      scene = &r->c.scene;
    }
    gs.strength_90_pa = s90[name];
    gs.anisotropy_ratio = gs.min_strength_pa > 0 ? gs.strength_90_pa / gs.min_strength_pa : std::nan("");
    if (scene && scene->joint_set.enabled) {
      const MaterialParams& j = scene->joint;
      const MohrCoulomb env = interface_envelope(j.cohesion, std::tan(j.friction_deg * 3.14159265358979323846 / 180.0),
                                                 j.contact_friction, j.slip_when_bonded);
      const double phi = std::atan(env.tan_phi) * 180.0 / 3.14159265358979323846;
      gs.jaeger_min_beta_deg = theory::jaeger_min_angle_deg(phi);
      // At the angle of the minimum, sliding under the group's confinement (uniaxially 2 c cos phi / (1 - sin phi)).
      const double sliding = theory::jaeger_sliding_strength(
          {env.cohesion, phi, gs.strength_90_pa, scene->loading.confining_pressure}, gs.jaeger_min_beta_deg);
      gs.jaeger_min_pa = std::isfinite(gs.strength_90_pa) ? std::min(sliding, gs.strength_90_pa) : std::nan("");
    }
    g += fmt::format("{},{:g},{:.9g},{:g},{:.9g},{:.9g},{:.4g}\n", name, gs.min_beta_deg, gs.min_strength_pa,
                     gs.jaeger_min_beta_deg, gs.jaeger_min_pa, gs.strength_90_pa, gs.anisotropy_ratio);
    summaries.push_back(gs);
  }
  io::write_text_atomic(out / "groups.csv", g);
  return summaries;
}

void write_timing(const std::vector<CaseResult>& results, const std::filesystem::path& out) {
  std::string t = "id,reused,wall_seconds,run_wall_seconds,steps\n";
  for (const auto& r : results)
    t += fmt::format("{},{},{:.3f},{:.3f},{}\n", r.c.id, r.reused ? 1 : 0, r.wall_seconds,
                     r.summary.value("wall_seconds", 0.0), r.summary["steps"].get<long>());
  io::write_text_atomic(out / "timing.csv", t);
}

std::vector<Envelope> write_envelopes(const std::vector<CaseResult>& results, const std::filesystem::path& out) {
  std::map<double, std::vector<std::pair<double, double>>> by_dip;  // beta -> (sigma_3, sigma_1)
  std::map<double, const Scene*> scene_of;
  for (const auto& r : results) {
    by_dip[r.c.beta].push_back({r.summary.value("confining_pressure_pa", 0.0), r.summary["peak_stress_pa"].get<double>()});
    scene_of[r.c.beta] = &r.c.scene;
  }
  std::vector<Envelope> envelopes;
  std::string t = "beta_deg,points,slope,intercept_pa,friction_deg,cohesion_pa,slope_0_10mpa,slope_0_10mpa_se,"
                  "jaeger_slope,jaeger_slip_range\n";
  for (auto& [beta, pts] : by_dip) {
    std::sort(pts.begin(), pts.end());
    Envelope e;
    e.beta_deg = beta;
    e.points = int(pts.size());
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const auto& [x, y] : pts) sx += x, sy += y, sxx += x * x, sxy += x * y;
    const double n = double(pts.size()), den = n * sxx - sx * sx;
    if (pts.size() >= 2 && den > 0) {
      e.slope = (n * sxy - sx * sy) / den;
      e.intercept_pa = (sy - e.slope * sx) / n;
      const double sin_phi = (e.slope - 1.0) / (e.slope + 1.0);
      e.friction_deg = std::asin(std::clamp(sin_phi, -1.0, 1.0)) * 180.0 / std::numbers::pi;
      e.cohesion_pa = e.intercept_pa * (1.0 - sin_phi) / (2.0 * std::sqrt(std::max(0.0, 1.0 - sin_phi * sin_phi)));
    }
    // The slope between sigma_3 = 0 and 10 MPa from the mean peak at each (every realization of a study with
    // realizations), and its standard error from their scatter: sqrt(s_0^2 / n_0 + s_10^2 / n_10) / 10 MPa.
    e.slope_0_10 = e.slope_0_10_se = std::nan("");
    std::vector<double> at0, at10;
    for (const auto& [x, y] : pts) {
      if (std::abs(x) < 1.0) at0.push_back(y);
      if (std::abs(x - 10e6) < 1.0) at10.push_back(y);
    }
    if (!at0.empty() && !at10.empty()) {
      const SampleStats s0 = sample_stats(at0), s10 = sample_stats(at10);
      e.slope_0_10 = (s10.mean - s0.mean) / 10e6;
      if (s0.n > 1 && s10.n > 1)
        e.slope_0_10_se = std::sqrt(s0.sd * s0.sd / s0.n + s10.sd * s10.sd / s10.n) / 10e6;
    }
    const Scene& s = *scene_of[beta];
    const MaterialParams& j = s.joint;
    const MohrCoulomb env = interface_envelope(j.cohesion, std::tan(j.friction_deg * std::numbers::pi / 180.0),
                                               j.contact_friction, j.slip_when_bonded);
    const double b = beta * std::numbers::pi / 180.0, phi = std::atan(env.tan_phi);
    const double denom = (1.0 - env.tan_phi / std::tan(b)) * std::sin(2.0 * b);
    e.slip_range = s.joint_set.enabled && b > phi && beta < 90.0 && denom > 0;
    e.jaeger_slope = e.slip_range ? 1.0 + 2.0 * env.tan_phi / denom : std::numeric_limits<double>::infinity();
    t += fmt::format("{:g},{},{:.6g},{:.9g},{:.4g},{:.9g},{:.6g},{:.6g},{:.6g},{}\n", beta, e.points, e.slope,
                     e.intercept_pa, e.friction_deg, e.cohesion_pa, e.slope_0_10, e.slope_0_10_se, e.jaeger_slope,
                     e.slip_range ? 1 : 0);
    envelopes.push_back(e);
  }
  io::write_text_atomic(out / "envelope.csv", t);
  return envelopes;
}

}  // namespace rbdem::study
