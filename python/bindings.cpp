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
#include "dem/driver/ucs.hpp"
#include "dem/mesh_cache.hpp"
#include "dem/scene.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"
#include "dem/version.hpp"
#include "io/results.hpp"
#include "study/report.hpp"
#include "study/study.hpp"

namespace py = pybind11;

namespace rbdem::python {

namespace {

// One scene key set from Python: `origin` names where it came from in messages ("scene", "overrides").
struct Assignment {
  std::string origin, key, value;
};

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

template <class T, class F>
py::array_t<T> column(const std::vector<F>& rows, T (*get)(const F&)) {
  py::array_t<T> a(py::ssize_t(rows.size()));
  auto v = a.template mutable_unchecked<1>();
  for (std::size_t i = 0; i < rows.size(); ++i) v(py::ssize_t(i)) = get(rows[i]);
  return a;
}

py::array_t<double> array_of(const std::vector<double>& v) {
  py::array_t<double> a(py::ssize_t(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

// The curve.csv columns (io::write_curve_csv), one NumPy array each, plus the mean stress.
py::dict curve_arrays(const std::vector<CurvePoint>& c) {
  py::dict d;
  d["step"] = column<long, CurvePoint>(c, [](const CurvePoint& p) { return p.step; });
  d["time_s"] = column<double, CurvePoint>(c, [](const CurvePoint& p) { return p.time; });
  d["strain"] = column<double, CurvePoint>(c, [](const CurvePoint& p) { return p.strain; });
  d["stress_pa"] = column<double, CurvePoint>(c, [](const CurvePoint& p) { return p.stress(); });
  d["stress_top_pa"] = column<double, CurvePoint>(c, [](const CurvePoint& p) { return p.stress_top; });
  d["stress_bottom_pa"] = column<double, CurvePoint>(c, [](const CurvePoint& p) { return p.stress_bottom; });
  d["kinetic_j"] = column<double, CurvePoint>(c, [](const CurvePoint& p) { return p.kinetic; });
  d["strain_energy_j"] = column<double, CurvePoint>(c, [](const CurvePoint& p) { return p.strain_energy; });
  d["broken_rock_tensile"] = column<int, CurvePoint>(c, [](const CurvePoint& p) { return p.broken[0]; });
  d["broken_rock_shear"] = column<int, CurvePoint>(c, [](const CurvePoint& p) { return p.broken[1]; });
  d["broken_joint_tensile"] = column<int, CurvePoint>(c, [](const CurvePoint& p) { return p.broken[2]; });
  d["broken_joint_shear"] = column<int, CurvePoint>(c, [](const CurvePoint& p) { return p.broken[3]; });
  d["lateral_strain"] = column<double, CurvePoint>(c, [](const CurvePoint& p) { return p.lateral_strain; });
  d["volumetric_strain"] = column<double, CurvePoint>(c, [](const CurvePoint& p) { return volumetric_strain(p); });
  return d;
}

// The cracks.csv columns (io::write_cracks_csv); kind and mode as lists of strings (NumPy arrays in Python).
py::dict crack_arrays(const std::vector<Crack>& c, const std::vector<double>& orientation_deg) {
  py::dict d;
  d["time_s"] = column<double, Crack>(c, [](const Crack& k) { return k.time; });
  d["strain"] = column<double, Crack>(c, [](const Crack& k) { return k.strain; });
  d["x_m"] = column<double, Crack>(c, [](const Crack& k) { return k.x; });
  d["y_m"] = column<double, Crack>(c, [](const Crack& k) { return k.y; });
  std::vector<std::string> kind, mode;
  for (const auto& k : c) {
    kind.push_back(k.kind == BondKind::rock ? "rock" : "joint");
    mode.push_back(k.mode == BreakMode::shear ? "shear" : "tensile");
  }
  d["kind"] = kind;
  d["mode"] = mode;
  d["bond"] = column<int, Crack>(c, [](const Crack& k) { return k.bond; });
  d["sigma_pa"] = column<double, Crack>(c, [](const Crack& k) { return k.sigma; });
  d["tau_pa"] = column<double, Crack>(c, [](const Crack& k) { return k.tau; });
  d["orientation_deg"] = array_of(orientation_deg);
  return d;
}

py::list frame_list(const std::vector<Frame>& frames) {
  py::list l;
  for (const auto& f : frames) {
    py::dict d;
    d["step"] = f.step;
    d["time_s"] = f.time;
    d["strain"] = f.strain;
    d["stress_pa"] = f.stress;
    d["label"] = f.label;
    d["cracks"] = f.cracks;
    d["x_m"] = array_of(f.x);
    d["y_m"] = array_of(f.y);
    d["theta_rad"] = array_of(f.theta);
    l.append(d);
  }
  return l;
}

// The blocks of the specimen as meshed (before loading): centroid, area, mass and the layer of each block.
py::dict block_arrays(const Topology& topo) {
  py::dict d;
  d["x_m"] = array_of(topo.blocks.cx);
  d["y_m"] = array_of(topo.blocks.cy);
  d["area_m2"] = array_of(topo.blocks.area);
  d["mass_kg"] = array_of(topo.blocks.mass);
  py::array_t<int> layer(py::ssize_t(topo.blocks.layer.size()));
  std::copy(topo.blocks.layer.begin(), topo.blocks.layer.end(), layer.mutable_data());
  d["layer"] = layer;
  return d;
}

const char* status_name(compare::GateCheck::Status s) {
  switch (s) {
    case compare::GateCheck::Status::passed: return "passed";
    case compare::GateCheck::Status::failed: return "failed";
    default: return "not_applicable";
  }
}

// Exceptions the Python layer maps to its own classes (python/rbdem/__init__.py).
struct GateFailed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The Python exception a progress hook caught (KeyboardInterrupt from PyErr_CheckSignals, or the callback's own),
// raised again once the run has unwound.
struct PendingError {
  std::optional<py::error_already_set> error;
};

// Runs one test as `rbdem ucs|triaxial|brazilian --out OUT` does (apps/cmd_test.cpp), without the resume,
// checkpoint and printing of the command line. Returns the raw pieces; rbdem.Result wraps them.
py::dict run(const std::string& test, const std::string& file, const std::vector<Assignment>& scene_keys,
             std::optional<double> beta, const std::vector<Assignment>& overrides, bool force, bool skip_gate,
             const std::string& out, py::object progress) {
  std::vector<Assignment> sets = overrides;
  // As the CLI: the test's own keys go first, so an explicit override of the same key is refused by validation
  // or check_test_scene rather than silently replaced.
  if (test == "brazilian") sets.insert(sets.begin(), {"brazilian()", "specimen.shape", "disc"});
  const Scene scene = resolve(file, scene_keys, beta, sets, force);
  check_test_scene(test, scene);
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
  // Always installed, callback or not: it is where Ctrl-C is noticed.
  uo.progress = [&](const RunProgress& p) {
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

  TriMesh mesh;
  Topology topo;
  TestResult r;
  try {
    py::gil_scoped_release release;
    mesh = make_mesh_cached(scene);
    topo = build_topology(mesh, scene.specimen.thickness, scene.rock.density);
    r = run_test(test, scene, topo, uo);
    if (!out.empty()) io::write_run(out, scene, mesh, topo, r, r.threads);
  } catch (const RunCancelled&) {
    if (pending.error) throw *pending.error;
    throw;
  }
  if (pending.error) throw *pending.error;  // set after the driver's last cancel check: the run is complete

  py::dict d;
  d["summary_json"] = io::run_summary(scene, r).dump();
  d["scene_toml"] = to_toml(scene);
  d["curve"] = curve_arrays(r.curve);
  d["cracks"] = crack_arrays(r.cracks, r.crack_orientation_deg);
  d["frames"] = frame_list(r.frames);
  d["blocks"] = block_arrays(topo);
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
      if (!seen.insert(to_toml(g)).second) continue;
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
  if (spec.test == "triaxial") extras.envelopes = study::write_envelopes(results, out);
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

namespace pybind11::detail {
// A scene key from Python: (origin, key, value) with the value already as text (python/rbdem/__init__.py).
template <>
struct type_caster<rbdem::python::Assignment> {
  PYBIND11_TYPE_CASTER(rbdem::python::Assignment, const_name("tuple[str, str, str]"));
  bool load(handle src, bool convert) {
    make_caster<std::tuple<std::string, std::string, std::string>> t;
    if (!t.load(src, convert)) return false;
    auto [origin, key, v] = cast_op<std::tuple<std::string, std::string, std::string>>(std::move(t));
    value = {origin, key, v};
    return true;
  }
};
}  // namespace pybind11::detail

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
  m.def("scene_keys", []() {
    std::vector<std::tuple<std::string, std::string, std::string>> keys;
    for (const auto& p : rbdem::scene_parameters()) keys.emplace_back(p.key, p.unit, p.doc);
    return keys;
  });
}
