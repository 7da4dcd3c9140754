// rbdem.Simulation's compiled core (python/rbdem/simulation.py wraps it; docs/python.md): a model built from a
// scene without running it, its state as NumPy arrays (copies), its boundary components, explicit steps, snapshots,
// and runs of a built-in protocol or of one written in Python through the same driver, monitors, checkpoints and
// writers as the command line.
//
// The GIL is released while C++ steps; a protocol written in Python takes it back in each of its hooks, and a
// KeyboardInterrupt or an exception there stops the run as the command line's Ctrl-C does (at the driver's next
// cancel check), then is raised once the run has unwound.
#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "dem/driver/driver.hpp"
#include "dem/measure.hpp"
#include "dem/driver/registry.hpp"
#include "dem/mesh_cache.hpp"
#include "dem/specimen_mesh3.hpp"
#include "dem/simulation.hpp"
#include "io/checkpoint.hpp"
#include "io/results.hpp"
#include "python/binding_common.hpp"

namespace rbdem::python {

namespace {

// An (n, k) array of item-major values (k per item); k = 1 gives the flat (n,) array.
py::array_t<double> matrix(const std::vector<double>& v, int k) {
  const py::ssize_t n = py::ssize_t(v.size()) / k;
  py::array_t<double> a = k == 1 ? py::array_t<double>(n) : py::array_t<double>({n, py::ssize_t(k)});
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

template <class T>
py::array_t<T> ints(const std::vector<T>& v) {
  py::array_t<T> a(py::ssize_t(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::array_t<bool> flags(const std::vector<std::uint8_t>& v) {
  py::array_t<bool> a(py::ssize_t(v.size()));
  for (std::size_t k = 0; k < v.size(); ++k) a.mutable_data()[k] = v[k] != 0;
  return a;
}

// The dict a run returns to rbdem.Result (the same keys as the test functions' run()).
py::dict result_dict(const Scene& scene, const TestResult& r, const Specimen& specimen, const std::string& out,
                     double seconds) {
  py::dict d;
  d["summary_json"] = io::run_summary(scene, r).dump();
  d["scene_toml"] = to_toml(scene);
  d["curve"] = curve_arrays(r.dimension, r.curve);
  d["cracks"] = record_arrays(r.dimension, r.cracks);
  d["frames"] = frame_list(r.frames);
  d["blocks"] = block_arrays(specimen);
  d["elastic_gate"] = py::none();
  d["out"] = out;
  d["seconds"] = seconds;
  return d;
}

// The reading of a test with platens (compression positive), or zeros without them: what a protocol written in
// Python records on the curve unless it reads for itself.
Reading platen_reading(const Simulation& sim) {
  Reading r;
  if (const Platens* p = sim.find<Platens>()) {
    r.strain = p->closure() / sim.specimen().height();
    r.stress_top = p->top_force() / p->area();
    r.stress_bottom = p->bottom_force() / p->area();
    r.stress = 0.5 * (r.stress_top + r.stress_bottom);
  }
  r.lateral_strain = sim.lateral_strain();
  return r;
}

// A protocol written in Python (python/rbdem/simulation.py, class Protocol), run by the shared driver. `hooks` is
// the Python adapter that calls the user's methods with the rbdem.Simulation: install(), start(), control(),
// done() -> bool, read() -> (strain, stress) or None, results() -> {key: value}; and its attributes name, every
// (steps between control() and done()) and max_steps. An exception in a hook is kept and cancels the run.
class PythonProtocol final : public LoadingProtocol {
 public:
  PythonProtocol(py::object hooks, PendingError& pending, std::atomic<bool>& cancel)
      : hooks_(std::move(hooks)), pending_(pending), cancel_(cancel) {
    name_ = hooks_.attr("name").cast<std::string>();
    every_ = std::max(1L, hooks_.attr("every").cast<long>());
    max_steps_ = hooks_.attr("max_steps").cast<long>();
    reads_ = hooks_.attr("reads").cast<bool>();
  }
  std::string name() const override { return name_; }
  // Each hook holds the GIL for as long as it touches a Python object (call() takes it again, nested).
  void install(Simulation&) override {
    py::gil_scoped_acquire acquire;
    call("install");
  }
  void start(Simulation&, TestRecord&) override {
    py::gil_scoped_acquire acquire;
    call("start");
  }
  Reading read(const Simulation& sim) const override {
    Reading r = platen_reading(sim);
    if (!reads_) return r;
    py::gil_scoped_acquire acquire;
    py::object v = call("read");
    if (v.is_none()) return r;
    try {
      const auto [strain, stress] = v.cast<std::pair<double, double>>();
      r.strain = strain, r.stress = r.stress_top = r.stress_bottom = stress;
    } catch (const py::cast_error&) {
      keep(py::type_error("Protocol.read() must return (strain, stress_pa) as two numbers, or None"));
    }
    return r;
  }
  void control(Simulation&, const Reading&, const TestRecord&) override {
    if (++count_ % every_ != 0) return;
    py::gil_scoped_acquire acquire;
    call("control");
  }
  long max_steps(const Simulation&, const TestRecord&) const override { return max_steps_; }
  bool stop(const Simulation&, const Reading&, const TestRecord&, std::string& reason) const override {
    if (count_ % every_ != 0) return false;
    py::gil_scoped_acquire acquire;
    py::object v = call("done");
    if (v.is_none() || !py::bool_(v)) return false;
    reason = "protocol";
    return true;
  }
  void results(const Simulation&, const TestRecord&, TestResult& result) const override {
    py::gil_scoped_acquire acquire;
    py::object v = call("results");
    if (v.is_none()) return;
    try {
      for (const auto& [key, value] : v.cast<std::vector<std::pair<std::string, double>>>())
        result.own.push_back({key, value, true});
    } catch (const py::cast_error&) {
      keep(py::type_error("Protocol.results() must return a dict of {name: number}"));
    }
  }

 private:
  // Calls hooks.<hook>() with the GIL; after a first exception no hook runs again (the run is stopping).
  py::object call(const char* hook) const {
    py::gil_scoped_acquire acquire;
    if (pending_.error) return py::none();
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      return hooks_.attr(hook)();
    } catch (py::error_already_set& e) {
      pending_.error = std::move(e);
      cancel_.store(true);
      return py::none();
    }
  }
  void keep(py::error_already_set&& e) const {
    pending_.error = std::move(e);
    cancel_.store(true);
  }
  void keep(const py::type_error& e) const {  // with the GIL held
    PyErr_SetString(PyExc_TypeError, e.what());
    keep(py::error_already_set());
  }

  py::object hooks_;
  PendingError& pending_;
  std::atomic<bool>& cancel_;
  std::string name_;
  long every_ = 1, max_steps_ = 0, count_ = 0;
  bool reads_ = false;
};

}  // namespace

// The model of one scene, built without running it.
class PySimulation {
 public:
  PySimulation(const std::string& file, const std::vector<Assignment>& scene_keys, std::optional<double> beta,
               const std::vector<Assignment>& overrides, bool force)
      : scene_(resolve(file, scene_keys, beta, overrides, force)) {
    py::gil_scoped_release release;
    if (scene_.specimen.dimension == 3) {  // the 3D model keeps its tetrahedral mesh alive beside it
      mesh3_ = std::make_unique<TetMesh>(mesh_scene3(scene_));
      sim_ = Simulation::create(scene_, *mesh3_);
    } else {
      const TriMesh mesh = make_mesh_cached(scene_);
      sim_ = Simulation::create(scene_, mesh);
    }
  }

  Simulation& sim() { return *sim_; }
  const Simulation& sim() const { return *sim_; }
  const Scene& scene() const { return scene_; }

  // Explicit steps. The time step, unless set, is numerics.dt or dt_safety x the stability limit of the model with
  // its boundaries, computed again after a boundary is added. Ctrl-C stops between chunks of steps.
  void step(long n) {
    if (running_) throw std::logic_error("step() inside a run: a protocol's hooks change the boundaries, the run steps");
    ensure_dt();
    for (long done = 0; done < n;) {
      const long chunk = std::min(n - done, 1000L);
      {
        py::gil_scoped_release release;
        sim_->run(chunk);
      }
      done += chunk;
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
  }
  double dt() {
    ensure_dt();
    return sim_->dt();
  }
  void set_dt(double dt) {
    const double limit = sim_->stability_limit();
    if (!(dt > 0.0) || dt > limit)
      throw SceneError(fmt::format("dt = {:.4g} s: the time step must be positive and at most the critical step {:.4g} s "
                                   "of this model and its boundaries (2 / sqrt(lambda_max))",
                                   dt, limit));
    sim_->set_dt(dt), dt_set_ = true;
  }
  void boundaries_changed() { dt_known_ = dt_set_; }

  py::dict run_builtin(const std::string& test, const std::string& out, py::object progress, bool resume,
                       long interrupt_at_step) {
    const ProtocolInfo& info = protocol_info(test);
    info.check(scene_);
    const std::unique_ptr<LoadingProtocol> protocol = info.make(scene_, RunOptions{}.curve_points);
    return run(*protocol, out, progress, resume, interrupt_at_step);
  }
  py::dict run_python(py::object hooks, const std::string& out, py::object progress, bool resume,
                      long interrupt_at_step) {
    PythonProtocol protocol(std::move(hooks), pending_, cancel_);
    return run(protocol, out, progress, resume, interrupt_at_step);
  }

 private:
  void ensure_dt() {
    if (dt_known_) return;
    sim_->set_dt(scene_.numerics.dt > 0 ? scene_.numerics.dt : scene_.numerics.dt_safety * sim_->stability_limit());
    dt_known_ = true;
  }

  // The driver copies its options' functions while the GIL is released: they hold no Python object themselves
  // (the callback is progress_, read with the GIL).
  RunOptions run_options(const std::string& out, long interrupt_at_step) {
    RunOptions uo;
    uo.cancel = &cancel_;
    uo.interrupt_at_step = interrupt_at_step;
    uo.progress = progress_hook(progress_, cancel_, pending_);
    if (!out.empty()) {
      const std::filesystem::path file = std::filesystem::path(out) / "checkpoint.h5";
      uo.checkpoint = [file](const TestCheckpoint& c) { io::write_checkpoint(file, c); };
    }
    return uo;
  }

  // A run of `protocol` on this simulation, which must be fresh: the protocol installs its boundaries. With `out`,
  // the run folder as the command line writes it (checkpoint.h5 on an interrupt; removed once complete); `resume`
  // continues out/checkpoint.h5.
  py::dict run(LoadingProtocol& protocol, const std::string& out, py::object progress, bool resume,
               long interrupt_at_step) {
    if (used_ || sim_->steps() > 0 || !sim_->boundaries().empty())
      throw SceneError("run(): this Simulation has stepped or has boundaries already; a run starts from a fresh "
                       "Simulation (the protocol installs its boundaries): make a new one");
    if (resume && out.empty()) throw SceneError("run(resume=True) needs out=, the folder of the interrupted run");
    if (!out.empty()) io::require_writable_dir(out);
    TestCheckpoint from;
    progress_ = std::move(progress);
    RunOptions uo = run_options(out, interrupt_at_step);
    if (resume) {
      const std::filesystem::path file = std::filesystem::path(out) / "checkpoint.h5";
      if (!std::filesystem::exists(file))
        throw SceneError(fmt::format("run(resume=True): there is no checkpoint {} to continue from", file.string()));
      from = io::read_checkpoint(file);
      uo.resume = &from;
    }
    used_ = running_ = true;
    pending_.error.reset(), cancel_.store(false);
    const auto t0 = std::chrono::steady_clock::now();
    TestResult r;
    try {
      py::gil_scoped_release release;
      r = run_test(protocol, *sim_, scene_, uo);
    } catch (const RunCancelled& c) {
      running_ = false;
      if (pending_.error) throw *pending_.error;
      throw std::runtime_error(fmt::format("run interrupted at step {}{}", c.step,
                                           c.checkpointed ? fmt::format(": checkpoint written in {}", out) : ""));
    } catch (...) {
      running_ = false;
      throw;
    }
    running_ = false;
    dt_known_ = true;
    if (pending_.error) throw *pending_.error;
    if (!out.empty()) {
      py::gil_scoped_release release;
      io::write_run(out, scene_, sim_->specimen(), r, r.threads);
      if (r.completed) std::filesystem::remove(std::filesystem::path(out) / "checkpoint.h5");
    }
    return result_dict(scene_, r, sim_->specimen(),
                       out, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }

  Scene scene_;
  std::unique_ptr<TetMesh> mesh3_;
  std::unique_ptr<Simulation> sim_;
  bool dt_known_ = false, dt_set_ = false, used_ = false, running_ = false;
  std::atomic<bool> cancel_{false};
  PendingError pending_;
  py::object progress_ = py::none();
};

namespace {

py::dict block_dict(const PySimulation& p) {
  const BlockStates t = p.sim().block_states();
  const Specimen& sp = p.sim().specimen();
  const int rot = rotation_dof(t.dim);
  py::dict d;
  d["position"] = matrix(t.position, t.dim);
  d["rotation"] = matrix(t.rotation, rot);
  d["velocity"] = matrix(t.velocity, t.dim);
  d["angular_velocity"] = matrix(t.angular_velocity, rot);
  d["force"] = matrix(t.force, t.dim);
  d["moment"] = matrix(t.moment, rot);
  d["reference_position"] = matrix(sp.blocks.centroid, t.dim);
  d[t.dim == 2 ? "area" : "volume"] = matrix(sp.blocks.measure, 1);
  std::vector<double> mass = sp.blocks.mass;
  for (double& m : mass) m *= p.scene().numerics.mass_scaling;
  d["mass"] = matrix(mass, 1);
  d["layer"] = ints(sp.blocks.layer);
  return d;
}

py::dict bond_dict(const PySimulation& p) {
  const BondStates t = p.sim().bond_states();
  const Specimen& sp = p.sim().specimen();
  const int rot = rotation_dof(t.dim);
  py::dict d;
  d["i"] = ints(sp.bonds.i), d["j"] = ints(sp.bonds.j);
  std::vector<std::string> kind;
  for (BondKind k : sp.bonds.kind) kind.push_back(name_of(k));
  d["kind"] = py::module_::import("numpy").attr("asarray")(kind, "<U5");
  d["material"] = ints(std::vector<int>(sp.bonds.material.begin(), sp.bonds.material.end()));
  d["size"] = matrix(sp.bonds.size, 1);
  d["intact"] = flags(t.intact);
  d["point"] = matrix(t.point, t.dim);
  d["normal"] = matrix(t.normal, t.dim);
  d["force"] = matrix(t.force, t.dim);
  d["moment"] = matrix(t.moment, rot);
  d["normal_force"] = matrix(t.normal_force, 1);
  d["shear_force"] = matrix(t.shear_force, 1);
  d["failure_index"] = matrix(t.failure_index, 1);
  d["damage"] = matrix(t.damage, 1);
  return d;
}

py::dict contact_dict(const PySimulation& p) {
  const ContactStates t = p.sim().contact_states();
  py::dict d;
  d["i"] = ints(t.i), d["j"] = ints(t.j);
  d["point"] = matrix(t.point, t.dim);
  d["normal"] = matrix(t.normal, t.dim);
  d["force"] = matrix(t.force, t.dim);
  d["normal_force"] = matrix(t.normal_force, 1);
  d["shear_force"] = matrix(t.shear_force, 1);
  return d;
}

py::dict energy_dict(const Energies& e) {
  py::dict d;
  d["kinetic_j"] = e.kinetic, d["strain_j"] = e.strain, d["damping_j"] = e.damping, d["friction_j"] = e.friction;
  d["work_j"] = e.work;
  return d;
}

py::dict specimen_dict(const Specimen& sp) {
  py::dict d;
  d["dimension"] = sp.dim;
  d["lo"] = std::vector<double>(sp.lo.begin(), sp.lo.begin() + sp.dim);
  d["hi"] = std::vector<double>(sp.hi.begin(), sp.hi.begin() + sp.dim);
  d["thickness"] = sp.thickness;
  d["layer_names"] = sp.layer_names;
  d["blocks"] = sp.num_blocks(), d["bonds"] = sp.num_bonds();
  return d;
}

const char* mode_name(GroupSettings::Mode m) {
  switch (m) {
    case GroupSettings::Mode::fixed: return "fixed";
    case GroupSettings::Mode::velocity: return "velocity";
    case GroupSettings::Mode::force: return "force";
    case GroupSettings::Mode::servo: return "servo";
    case GroupSettings::Mode::free: return "free";
  }
  return "?";
}

GroupSettings::Mode group_mode(const std::string& mode) {
  using M = GroupSettings::Mode;
  for (M m : {M::fixed, M::velocity, M::force, M::servo, M::free})
    if (mode == mode_name(m)) return m;
  throw SceneError(fmt::format("mode = '{}': a group's mode is 'fixed', 'velocity', 'force', 'servo' or 'free'",
                               mode));
}

std::vector<GroupSettings::Mode> group_modes(const std::vector<std::string>& modes) {
  std::vector<GroupSettings::Mode> out;
  for (const auto& m : modes) out.push_back(group_mode(m));
  return out;
}

// The Love-Weber region from the Python keywords (python/rbdem/simulation.py checks that at most one is given).
Region region_of(const std::string& kind, const std::vector<double>& lo, const std::vector<double>& hi,
                 double radius, const std::vector<int>& ids) {
  if (kind == "whole") return Region::whole();
  if (kind == "box") return Region::box(lo, hi);
  if (kind == "circle") return Region::circle(lo, radius);
  if (kind == "layers") return Region::layers(ids);
  if (kind == "blocks") return Region::blocks(ids);
  throw SceneError(fmt::format("region '{}': give a box, a circle, layers or blocks", kind));
}

// A dim x dim NumPy array of a stress tensor (Pa, tension positive).
py::array_t<double> tensor_array(const StressTensor& t) {
  py::array_t<double> a({py::ssize_t(t.dim), py::ssize_t(t.dim)});
  for (int r = 0; r < t.dim; ++r)
    for (int c = 0; c < t.dim; ++c) a.mutable_at(r, c) = t(r, c);
  return a;
}

py::dict network_dict(const ForceNetwork& n, int dim) {
  py::dict d;
  d["i"] = ints(n.i), d["j"] = ints(n.j);
  py::array_t<bool> contact(py::ssize_t(n.size()));
  for (std::size_t k = 0; k < n.size(); ++k) contact.mutable_data()[k] = n.kind[k] != 0;
  d["contact"] = contact;
  py::array_t<double> f({py::ssize_t(n.size()), py::ssize_t(dim)});
  std::copy(n.force.begin(), n.force.end(), f.mutable_data());
  d["force"] = f;
  py::array_t<double> fn(py::ssize_t(n.size()));
  std::copy(n.normal_force.begin(), n.normal_force.end(), fn.mutable_data());
  d["normal_force"] = fn;
  return d;
}

py::dict readings(const Boundary& b) {
  py::dict d;
  for (const auto& [key, value] : b.readings()) d[key.c_str()] = value;
  return d;
}

void bind_boundaries(py::module_& m) {
  py::class_<Boundary>(m, "Boundary")
      .def_property_readonly("name", &Boundary::name)
      .def_property_readonly("work", &Boundary::work)
      .def_property_readonly("energy", &Boundary::energy)
      .def("readings", &readings);
  py::class_<Platens, Boundary>(m, "Platens")
      .def_property_readonly("top_force", &Platens::top_force)
      .def_property_readonly("bottom_force", &Platens::bottom_force)
      .def_property_readonly("closure", &Platens::closure)
      .def_property_readonly("area", &Platens::area)
      .def_property_readonly("velocity", &Platens::velocity)
      .def_property_readonly("stress", &Platens::stress)
      .def_property_readonly("servo_active", &Platens::servo_active)
      .def_property_readonly("friction", &Platens::friction)
      .def("set_velocity", &Platens::set_velocity, py::arg("velocity"))
      .def(
          "set_servo",
          [](Platens& p, double target, double gain, double max_velocity) {
            p.set_servo({target, gain, max_velocity});
          },
          py::arg("target_stress"), py::arg("gain"), py::arg("max_velocity"));
  py::class_<Jacket, Boundary>(m, "Jacket")
      .def_property_readonly("pressure", &Jacket::pressure)
      .def("set_pressure", &Jacket::set_pressure, py::arg("pressure"))
      .def_property_readonly("faces_lost", &Jacket::faces_lost);
  py::class_<BlockGroup, Boundary>(m, "BlockGroup")
      .def_property_readonly("blocks", [](const BlockGroup& g) { return ints(g.blocks()); })
      .def_property_readonly("mode", [](const BlockGroup& g) { return std::string(mode_name(g.settings().mode)); })
      .def_property_readonly("modes",
                             [](const BlockGroup& g) {
                               std::vector<std::string> m;
                               for (int d = 0; d < int(g.settings().value.size()); ++d)
                                 m.push_back(mode_name(g.mode(d)));
                               return m;
                             })
      .def("set_modes", [](BlockGroup& g, const std::vector<std::string>& m) { g.set_modes(group_modes(m)); },
           py::arg("modes"))
      .def(
          "set_servo",
          [](BlockGroup& g, double gain, double max_velocity, double stiffness, double origin) {
            g.set_servo({gain, max_velocity, stiffness, origin});
          },
          py::arg("gain"), py::arg("max_velocity"), py::arg("stiffness"), py::arg("origin"))
      .def_property_readonly("velocity", &BlockGroup::velocity)
      .def("attachment_stiffness", &BlockGroup::attachment_stiffness)
      .def_property_readonly("value", [](const BlockGroup& g) { return g.settings().value; })
      .def("set_value", &BlockGroup::set_value, py::arg("value"))
      .def_property_readonly("force", &BlockGroup::force)
      .def_property_readonly("displacement", &BlockGroup::displacement);
}

// A boundary as its own Python class, kept alive by the simulation `owner` that holds it.
py::object boundary_object(Boundary* b, py::handle owner) {
  const auto policy = py::return_value_policy::reference_internal;
  if (auto* p = dynamic_cast<Platens*>(b)) return py::cast(p, policy, owner);
  if (auto* j = dynamic_cast<Jacket*>(b)) return py::cast(j, policy, owner);
  if (auto* g = dynamic_cast<BlockGroup*>(b)) return py::cast(g, policy, owner);
  return py::cast(b, policy, owner);
}

}  // namespace

void bind_simulation(py::module_& m) {
  py::register_exception<InstabilityError>(m, "InstabilityError", PyExc_RuntimeError);
  bind_boundaries(m);
  py::class_<Snapshot>(m, "Snapshot").def_property_readonly("dimension", [](const Snapshot& s) { return s.dim; });
  using S = PySimulation;
  py::class_<S>(m, "Simulation")
      .def(py::init<const std::string&, const std::vector<Assignment>&, std::optional<double>,
                    const std::vector<Assignment>&, bool>(),
           py::arg("file"), py::arg("scene_keys"), py::arg("beta"), py::arg("overrides"), py::arg("force"))
      .def_property_readonly("scene_toml", [](const S& s) { return to_toml(s.scene()); })
      .def_property_readonly("dimension", [](const S& s) { return s.sim().dimension(); })
      .def_property_readonly("specimen", [](const S& s) { return specimen_dict(s.sim().specimen()); })
      .def("step", &S::step, py::arg("n"))
      .def_property_readonly("time", [](const S& s) { return s.sim().time(); })
      .def_property_readonly("steps", [](const S& s) { return s.sim().steps(); })
      .def_property("dt", &S::dt, &S::set_dt)
      .def("stability_limit", [](const S& s) { return s.sim().stability_limit(); })
      .def("energies", [](const S& s) { return energy_dict(s.sim().energies()); })
      .def("cracks", [](const S& s) { return record_arrays(s.sim().dimension(), s.sim().cracks()); })
      .def("blocks", &block_dict)
      .def("bonds", &bond_dict)
      .def("contacts", &contact_dict)
      .def("lateral_strain", [](const S& s) { return s.sim().lateral_strain(); })
      .def(
          "boundaries",
          [](py::object self) {
            py::list l;
            for (Boundary* b : self.cast<S&>().sim().boundaries()) l.append(boundary_object(b, self));
            return l;
          })
      .def(
          "add_platens",
          [](S& s, double velocity, double friction) -> Platens& {
            Platens& p = s.sim().add_platens({velocity, friction});
            s.boundaries_changed();
            return p;
          },
          py::arg("velocity"), py::arg("friction"), py::return_value_policy::reference_internal)
      .def(
          "add_jacket",
          [](S& s, double pressure) -> Jacket& {
            Jacket& j = s.sim().add_jacket(pressure);
            s.boundaries_changed();
            return j;
          },
          py::arg("pressure"), py::return_value_policy::reference_internal)
      .def(
          "add_group",
          [](S& s, const std::string& name, std::vector<int> blocks, const std::string& mode,
             std::vector<double> value, const std::vector<std::string>& modes, std::vector<double> servo) -> BlockGroup& {
            GroupSettings g;
            g.name = name, g.blocks = std::move(blocks), g.mode = group_mode(mode), g.value = std::move(value);
            g.modes = group_modes(modes);
            if (servo.size() == 4) g.servo = {servo[0], servo[1], servo[2], servo[3]};
            BlockGroup& b = s.sim().add_group(g);
            s.boundaries_changed();
            return b;
          },
          py::arg("name"), py::arg("blocks"), py::arg("mode"), py::arg("value"), py::arg("modes"), py::arg("servo"),
          py::return_value_policy::reference_internal)
      .def(
          "stress",
          [](const S& s, const std::string& kind, const std::vector<double>& lo, const std::vector<double>& hi,
             double radius, const std::vector<int>& ids, bool bonds, bool contacts, bool boundaries) {
            const StressTensor t =
                average_stress(s.sim(), region_of(kind, lo, hi, radius, ids), {bonds, contacts, boundaries});
            return py::make_tuple(tensor_array(t), t.volume, t.blocks);
          },
          py::arg("kind"), py::arg("lo"), py::arg("hi"), py::arg("radius"), py::arg("ids"), py::arg("bonds"),
          py::arg("contacts"), py::arg("boundaries"))
      .def(
          "block_stresses",
          [](const S& s, bool bonds, bool contacts, bool boundaries) {
            const BlockStresses b = block_stresses(s.sim(), {bonds, contacts, boundaries});
            py::array_t<double> a({py::ssize_t(b.size()), py::ssize_t(b.dim), py::ssize_t(b.dim)});
            std::copy(b.stress.begin(), b.stress.end(), a.mutable_data());
            return a;
          },
          py::arg("bonds"), py::arg("contacts"), py::arg("boundaries"))
      .def("force_network", [](const S& s) { return network_dict(force_network(s.sim()), s.sim().dimension()); })
      .def("snapshot", [](const S& s) { return s.sim().snapshot(); })
      .def("restore", [](S& s, const Snapshot& snap) { s.sim().restore(snap); }, py::arg("snapshot"))
      .def("run_builtin", &S::run_builtin, py::arg("test"), py::arg("out"), py::arg("progress"), py::arg("resume"),
           py::arg("interrupt_at_step"))
      .def("run_python", &S::run_python, py::arg("hooks"), py::arg("out"), py::arg("progress"), py::arg("resume"),
           py::arg("interrupt_at_step"));
}

}  // namespace rbdem::python
