// _rbdem: the compiled half of the Python module `rbdem` (python/rbdem/__init__.py is the API users call; the
// contract is docs/python.md). It calls the same library functions as the rbdem command (apps/cmd_test.cpp,
// cmd_elastic.cpp, cmd_verify.cpp, cmd_sweep.cpp): resolving the scene, the elastic gate, meshing, run_test,
// io::write_run. It never runs the executable.
//
// The GIL is released while C++ works (meshing, the gate, the explicit run, writing files) and taken back only for
// the progress hook, which the driver calls about every 1000 steps: there it runs the user's callback and
// PyErr_CheckSignals(), so Ctrl-C (or an exception in the callback) sets the driver's cancel flag, the driver stops
// at its next check (every 256 steps) and the Python exception is raised once the run has unwound.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <optional>
#include <regex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "compare/gate/elastic_gate.hpp"
#include "compare/gate/gate_cache.hpp"
#include "compare/verify/verify.hpp"
#include "dem/driver/registry.hpp"
#include "dem/record_columns.hpp"
#include "dem/scene.hpp"
#include "dem/version.hpp"
#include "io/results.hpp"
#include "io/run_case.hpp"
#include "study/report.hpp"
#include "study/study.hpp"
#include "python/binding_common.hpp"

namespace py = pybind11;

namespace rbdem::python {

// Sets the keys in order, naming the Python argument instead of the CLI's --set in the messages.
void apply_assignments(Scene& scene, const std::vector<Assignment>& sets) {
  for (const auto& a : sets) {
    try {
      set_parameter(scene, a.key, a.value);
    } catch (const SceneError& e) {
      std::string msg = e.what();
      if (msg.starts_with("--set: ")) msg.erase(0, 7);
      throw SceneError(fmt::format("{}: {}", a.origin, msg));
    }
  }
}

// The scene of a Python call, as the CLI's resolve_scene (apps/cli_common.cpp) makes it: defaults <- file <- the
// dict scene's keys <- beta <- overrides, validated, then checked for likely unit mistakes unless `force`.
Scene resolve(const std::string& file, const std::vector<Assignment>& scene_keys, std::optional<double> beta,
              const std::vector<Assignment>& overrides, bool force) {
  Scene scene = file.empty() ? Scene{} : load_scene_file(file);
  apply_assignments(scene, scene_keys);
  if (beta) {
    if (!scene.mesh.file.empty())
      throw SceneError(fmt::format("beta={:g} cannot be used with the mesh file {} (mesh.file): the mesh fixes the "
                                   "layers' dip; make a mesh at that dip (rbdem mesh) or leave out beta",
                                   *beta, scene.mesh.file));
    apply_assignments(scene, {{fmt::format("beta={:g}", *beta), "joint_set.dip_deg", fmt::format("{:.17g}", *beta)}});
  }
  apply_assignments(scene, overrides);
  validate(scene);
  if (!force) check_plausible(scene);
  return scene;
}

py::array_t<double> array_of(const std::vector<double>& v) {
  py::array_t<double> a(py::ssize_t(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

std::function<void(const RunProgress&)> progress_hook(const py::object& progress, std::atomic<bool>& cancel,
                                                      PendingError& pending) {
  return [&progress, &cancel, &pending](const RunProgress& p) {
    if (cancel.load()) return;
    py::gil_scoped_acquire acquire;
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (!progress.is_none()) progress(p.step, p.strain, p.stress, p.peak, p.cracks);
    } catch (py::error_already_set& e) {
      pending.error = std::move(e);
      cancel.store(true);
    }
  };
}

// The curve's table, plus the mean platen stress (stress_pa) for convenience.
py::dict curve_arrays(int dim, const std::vector<CurvePoint>& curve) {
  py::dict d = record_arrays(dim, curve);
  std::vector<double> stress;
  for (const auto& p : curve) stress.push_back(p.stress());
  d["stress_pa"] = array_of(stress);
  return d;
}

// Each frame as a dict: its table's scalars and its pose components (x_m, y_m, theta_rad in 2D).
py::list frame_list(const std::vector<Frame>& frames) {
  py::list l;
  for (const auto& f : frames) {
    py::dict d;
    Frame::fields(f.dim, [&](const Field& field, auto get) { d[field.name] = get(f); });
    for (int c = 0; c < pose_size(f.dim); ++c)
      d[(std::string(pose_name(f.dim, c)) + "_" + pose_unit(f.dim, c)).c_str()] =
          array_of(std::vector<double>(f.component(c), f.component(c) + f.blocks()));
    l.append(d);
  }
  return l;
}

// The blocks of the specimen as meshed (before loading): centroid, area, mass and the layer of each block.
py::dict block_arrays(const Specimen& sp) {
  py::dict d;
  const char* axis[3] = {"x_m", "y_m", "z_m"};
  for (int k = 0; k < sp.dim; ++k) {
    std::vector<double> c(sp.num_blocks());
    for (std::size_t b = 0; b < c.size(); ++b) c[b] = sp.centroid(b, k);
    d[axis[k]] = array_of(c);
  }
  d[sp.dim == 2 ? "area_m2" : "volume_m3"] = array_of(sp.blocks.measure);
  d["mass_kg"] = array_of(sp.blocks.mass);
  py::array_t<int> layer(py::ssize_t(sp.blocks.layer.size()));
  std::copy(sp.blocks.layer.begin(), sp.blocks.layer.end(), layer.mutable_data());
  d["layer"] = layer;
  return d;
}

namespace {

const char* status_name(compare::GateCheck::Status s) {
  switch (s) {
    case compare::GateCheck::Status::passed: return "passed";
    case compare::GateCheck::Status::failed: return "failed";
    default: return "not_applicable";
  }
}

// Runs one test as `rbdem ucs|triaxial|brazilian --out OUT` does (apps/cmd_test.cpp), without the resume,
// checkpoint and printing of the command line. Returns the raw pieces; rbdem.Result wraps them.
py::dict run(const std::string& test, const std::string& file, const std::vector<Assignment>& scene_keys,
             std::optional<double> beta, const std::vector<Assignment>& overrides, bool force, bool skip_gate,
             const std::string& out, py::object progress) {
  const ProtocolInfo& info = protocol_info(test);
  std::vector<Assignment> sets = overrides;
  // As the CLI: the test's own keys go first, so an explicit override of the same key is refused by validation
  // or the protocol's check rather than silently replaced.
  for (const auto& [key, value] : info.scene_defaults) sets.insert(sets.begin(), {test + "()", key, value});
  const Scene scene = resolve(file, scene_keys, beta, sets, force);
  info.check(scene);
  const auto t0 = std::chrono::steady_clock::now();
  if (!out.empty()) io::require_writable_dir(out);

  py::dict gate;
  if (!skip_gate) {
    compare::GateCheck c;
    {
      py::gil_scoped_release release;
      c = compare::check_elastic_gate(compare::gate_scene(scene));
    }
    if (c.status == compare::GateCheck::Status::failed)
      throw GateFailed(fmt::format(
          "{}\nthe elastic gate failed: {}. The DEM does not reproduce the elastic response of the FE model of the "
          "same blocks' rock with the joints as interfaces within elastic.tolerance (docs/elastic.md, \"What to do "
          "when the gate fails\"); pass skip_elastic_gate=True to run anyway",
          c.table, c.summary));
    gate["status"] = status_name(c.status);
    gate["from_cache"] = c.from_cache;
    gate["summary"] = c.summary;
    gate["note"] = c.note;
    gate["key"] = c.key;
  }

  std::atomic<bool> cancel{false};
  PendingError pending;
  RunOptions uo;
  uo.cancel = &cancel;
  uo.progress = progress_hook(progress, cancel, pending);

  io::CaseRun run;
  try {
    py::gil_scoped_release release;
    io::CaseOptions co;
    co.out = out;
    co.run = uo;
    run = io::run_case(test, scene, co);
  } catch (const RunCancelled&) {
    if (pending.error) throw *pending.error;
    throw;
  }
  if (pending.error) throw *pending.error;  // set after the driver's last cancel check: the run is complete

  const TestResult& r = run.result;
  py::dict d;
  d["summary_json"] = io::run_summary(scene, r).dump();
  d["scene_toml"] = to_toml(scene);
  d["curve"] = curve_arrays(r.dimension, r.curve);
  d["cracks"] = record_arrays(r.dimension, r.cracks);
  d["frames"] = frame_list(r.frames);
  d["blocks"] = block_arrays(run.specimen);
  d["elastic_gate"] = skip_gate ? py::object(py::none()) : py::object(gate);
  d["out"] = out;
  d["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return d;
}

std::string resolve_toml(const std::string& file, const std::vector<Assignment>& scene_keys, std::optional<double> beta,
                         const std::vector<Assignment>& overrides, bool force) {
  return to_toml(resolve(file, scene_keys, beta, overrides, force));
}

// `rbdem elastic --out OUT`: the gate's measurements over every dip, stored in the gate's cache as the command does.
py::dict elastic_gate(const std::string& file, const std::vector<Assignment>& scene_keys,
                      const std::vector<Assignment>& overrides, bool force, const std::string& out, bool fields) {
  const Scene scene = resolve(file, scene_keys, std::nullopt, overrides, force);
  compare::ElasticGateOptions go;
  go.fields = fields;
  compare::ElasticReport report;
  std::string json;
  {
    py::gil_scoped_release release;
    report = compare::run_elastic_gate(scene, go);
    const nlohmann::json j = compare::elastic_json(report, scene);
    json = j.dump();
    if (!out.empty()) {
      std::filesystem::create_directories(out);
      io::write_text_atomic(std::filesystem::path(out) / "elastic.json", j.dump(1) + "\n");
    }
    compare::store_elastic_gate(scene, report);
  }
  py::dict d;
  d["passed"] = report.gate.passed;
  d["comparison"] = report.gate.comparison;
  d["max_deviation"] = report.gate.max_deviation;
  d["worst_beta_deg"] = report.gate.worst_beta_deg;
  d["tolerance"] = report.gate.tolerance;
  d["message"] = report.gate.message;
  d["reason"] = report.gate.reason;
  d["table"] = compare::elastic_table(report);
  d["json"] = json;
  return d;
}

// Waits for `work` on a thread of its own with the GIL released, checking for Ctrl-C every 0.1 s; on one it sets
// `cancel` and lets `work` finish, then raises KeyboardInterrupt. For the calls that have no progress hook.
template <class Work>
void run_interruptible(std::atomic<bool>& cancel, Work work) {
  std::exception_ptr failure;
  std::atomic<bool> done{false};
  std::thread worker([&]() {
    try {
      work();
    } catch (...) {
      failure = std::current_exception();
    }
    done.store(true);
  });
  std::optional<py::error_already_set> interrupt;
  while (!done.load()) {
    {
      py::gil_scoped_release release;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    if (!interrupt && PyErr_CheckSignals() != 0) {
      interrupt.emplace();  // fetches the KeyboardInterrupt; raised once `work` has stopped
      cancel.store(true);
    }
  }
  {
    py::gil_scoped_release release;
    worker.join();
  }
  if (interrupt) throw *interrupt;
  if (failure) std::rethrow_exception(failure);
}

// `rbdem verify [--quick] [--only REGEX] --out OUT`, without the figures (those need python/rbdem_figures.py).
// Returns the verify.json text.
std::string verify(bool quick, const std::string& only, const std::string& out) {
  std::regex filter;
  try {
    filter = std::regex(only.empty() ? std::string(".*") : only);
  } catch (const std::regex_error& e) {
    throw SceneError(fmt::format("only='{}' is not a regular expression ({}); e.g. only='dem\\.'", only, e.what()));
  }
  std::vector<verify::CaseSpec> cases;
  for (auto& c : verify::catalogue())
    if ((!quick || c.quick) && std::regex_search(c.name, filter)) cases.push_back(std::move(c));
  if (cases.empty()) throw SceneError(fmt::format("only='{}' matches no case; rbdem.verify_cases() lists them", only));
  const std::filesystem::path dir(out);
  std::filesystem::create_directories(dir);
  verify::Context ctx;
  ctx.quick = quick;
  ctx.out = dir;
  std::vector<verify::CaseResult> results;
  std::atomic<bool> cancel{false};
  const auto t0 = std::chrono::steady_clock::now();
  run_interruptible(cancel, [&]() {
    for (const auto& c : cases) {
      if (cancel.load()) return;
      results.push_back(verify::run_case(c, ctx));
      results.back().figure.clear();  // no figure is drawn here
    }
  });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  io::write_text_atomic(dir / "verify.json", verify::verify_json(results, ctx, seconds).dump(1) + "\n");
  io::write_text_atomic(dir / "verify.md", verify::verify_markdown(results, ctx, seconds));
  return verify::verify_json(results, ctx, seconds).dump();
}

std::vector<std::pair<std::string, bool>> verify_cases() {
  std::vector<std::pair<std::string, bool>> names;
  for (const auto& c : verify::catalogue()) names.emplace_back(c.name, c.quick);
  return names;
}

// `rbdem sweep STUDY --out OUT [--set ...] [--workers N]` in this process (no MPI): the cases' checks, the elastic
// gate once per elastic scene, the cases (a rerun skips complete ones), table.csv, groups.csv, timing.csv,
// envelope.csv of a confined study and report.md. Returns the case summaries (JSON text per case) in case order.
py::list sweep(const std::string& study_file, const std::vector<Assignment>& overrides, const std::string& out,
               int workers, bool skip_gate, bool force) {
  study::StudySpec spec = study::load_study(study_file);
  apply_assignments(spec.base, overrides);
  validate(spec.base);
  const auto t0 = std::chrono::steady_clock::now();
  io::require_writable_dir(out);
  const auto cases = study::expand(spec);
  for (const auto& c : cases) {
    try {
      if (!force) check_plausible(c.scene);
    } catch (const SceneError& e) {
      throw SceneError(fmt::format("case {}: {}", c.id, e.what()));
    }
  }
  std::string gate_markdown;
  if (!skip_gate) {
    std::set<std::string> seen;
    for (const auto& c : cases) {
      const Scene g = compare::gate_scene(c.scene);
      if (!seen.insert(compare::elastic_gate_key(g)).second) continue;  // once per elastic behaviour, not per dip
      compare::GateCheck check;
      {
        py::gil_scoped_release release;
        check = compare::check_elastic_gate(g);
      }
      if (check.status == compare::GateCheck::Status::failed)
        throw GateFailed(fmt::format("{}\nthe elastic gate failed for {} ({}); fix the scene (a finer mesh.size "
                                     "usually) or pass skip_elastic_gate=True",
                                     check.table, c.group.empty() ? "the base scene" : c.group, check.summary));
      if (check.status == compare::GateCheck::Status::passed)
        gate_markdown += (c.group.empty() ? "" : "**" + c.group + "**\n\n") + "```\n" + check.table + "```\n\n";
    }
  }
  std::atomic<bool> cancel{false};
  study::SweepOptions so;
  so.workers = workers;
  so.cancel = &cancel;
  std::vector<study::CaseResult> ran;
  try {
    run_interruptible(cancel, [&]() { ran = study::run_cases(cases, out, so); });
  } catch (const study::Cancelled&) {
    throw std::runtime_error("sweep cancelled");  // only when cancel was set, and then KeyboardInterrupt wins
  }
  // Everything from disk, with this call's timings and whether it ran the case or found it complete.
  auto results = study::collect(cases, out);
  for (auto& r : results)
    for (const auto& mine : ran)
      if (mine.c.id == r.c.id) r.reused = mine.reused, r.wall_seconds = mine.wall_seconds;
  const auto groups = study::write_tables(results, out);
  study::write_timing(results, out);
  study::ReportExtras extras;
  if (protocol_info(spec.test).confined) extras.envelopes = study::write_envelopes(results, out);
  extras.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  extras.workers = workers > 0 ? workers : int(std::max(1u, std::thread::hardware_concurrency()));
  extras.elastic_gate_markdown = gate_markdown;
  study::write_report(spec, results, groups, out, extras);
  py::list l;
  for (const auto& r : results) {
    py::dict d;
    d["id"] = r.c.id;
    d["group"] = r.c.group;
    d["beta_deg"] = r.c.beta;
    d["reused"] = r.reused;
    d["summary_json"] = r.summary.dump();
    l.append(d);
  }
  return l;
}

}  // namespace

}  // namespace rbdem::python


PYBIND11_MODULE(_rbdem, m) {
  using namespace rbdem::python;
  m.doc() = "rbdem's compiled core; use the package `rbdem` (docs/python.md)";
  // SceneError and the failed gate get Python classes of their own; __init__.py derives its public ones from them.
  py::register_exception<rbdem::SceneError>(m, "SceneError", PyExc_ValueError);
  py::register_exception<GateFailed>(m, "ElasticGateFailed", PyExc_RuntimeError);
  m.def("version", []() { return rbdem::version_text(); });
  m.def("resolve_scene", &resolve_toml, py::arg("file"), py::arg("scene_keys"), py::arg("beta"), py::arg("overrides"),
        py::arg("force"));
  m.def("run", &run, py::arg("test"), py::arg("file"), py::arg("scene_keys"), py::arg("beta"), py::arg("overrides"),
        py::arg("force"), py::arg("skip_gate"), py::arg("out"), py::arg("progress"));
  m.def("elastic_gate", &elastic_gate, py::arg("file"), py::arg("scene_keys"), py::arg("overrides"), py::arg("force"),
        py::arg("out"), py::arg("fields"));
  m.def("verify", &verify, py::arg("quick"), py::arg("only"), py::arg("out"));
  m.def("verify_cases", &verify_cases);
  m.def("sweep", &sweep, py::arg("study_file"), py::arg("overrides"), py::arg("out"), py::arg("workers"),
        py::arg("skip_gate"), py::arg("force"));
  bind_simulation(m);
  m.def("scene_keys", []() {
    std::vector<std::tuple<std::string, std::string, std::string>> keys;
    for (const auto& p : rbdem::scene_parameters()) keys.emplace_back(p.key, p.unit, p.doc);
    return keys;
  });
}
