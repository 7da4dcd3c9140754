// The uniaxial compression protocol. See ucs.hpp.
#include "dem/driver/ucs.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "dem/driver/monitors.hpp"
#include "dem/static_solve.hpp"
#include "dem/scene_keys.hpp"

namespace rbdem {

// --- uniaxial compression ---------------------------------------------------------------------------------------

Reading UcsProtocol::platen_reading(const Engine& engine) const {
  const Model& m = engine.model();
  const double area = m.width * m.thickness;
  Reading r;
  r.strain = engine.platen_displacement() / m.height;
  r.stress_top = engine.top_force() / area;
  r.stress_bottom = engine.bottom_force() / area;
  r.stress = 0.5 * (engine.top_force() + engine.bottom_force()) / area;
  r.lateral_strain = gauge_.strain(engine);
  return r;
}

Reading UcsProtocol::read(const Engine& engine) const { return platen_reading(engine); }

long UcsProtocol::max_steps(const Engine& engine, const TestRecord& record) const {
  const double H = engine.model().height, v = scene_.loading.platen_velocity;
  return long(std::ceil((scene_.loading.max_strain - record.elastic_start_strain) * H / (v * record.dt)));
}

StaticResult UcsProtocol::closure_solve(const Engine& engine, const std::atomic<int>* threads) const {
  StaticOptions so;
  so.threads = threads;
  so.platen_displacement = 1e-6 * engine.model().height;
  return solve_static(engine, so);
}

void UcsProtocol::prepare(const Engine& engine, const std::atomic<int>& threads) {
  if (scene_.numerics.elastic_start) prepared_closure_ = closure_solve(engine, &threads);
}

void UcsProtocol::start(Engine& engine, TestRecord& record) {
  if (!scene_.numerics.elastic_start) return;
  const StaticResult closure = prepared_closure_ ? std::move(*prepared_closure_) : closure_solve(engine);
  prepared_closure_.reset();
  start_along(engine, record, StaticResult{}, closure, 0.0);
}

// The model is linear until the first bond breaks: solve that part statically and hand over to the explicit run
// at a fraction of the first-break load. `base` with no displacements is the unloaded specimen.
void UcsProtocol::start_along(Engine& engine, TestRecord& record, const StaticResult& base, const StaticResult& st,
                              double base_stress) const {
  const Model& m = engine.model();
  const double H = m.height, v = scene_.loading.platen_velocity;
  const bool from_rest = base.ux.empty();
  const double first_break = from_rest ? st.first_break_factor : first_break_along(engine, base, st);
  const double base_strain = base.platen_displacement / H;
  const double max_factor = (scene_.loading.max_strain - base_strain) * H / st.platen_displacement;
  const double factor = std::min(scene_.numerics.elastic_start_fraction * first_break, 0.5 * max_factor);
  if (!(factor > 0 && std::isfinite(factor))) return;
  const double base_lateral = from_rest ? 0.0 : gauge_.strain_of(base.ux), lateral = gauge_.strain_of(st.ux);
  const int n = 20;
  for (int k = 1; k <= n; ++k) {
    const double f = factor * double(k) / double(n);
    CurvePoint p;
    p.step = -1;
    p.strain = base_strain + f * st.platen_displacement / H;
    p.time = f * st.platen_displacement / v;
    p.stress_top = base_stress + stress_of(f * st.top_force, m);
    p.stress_bottom = base_stress + stress_of(f * st.bottom_force, m);
    p.lateral_strain = base_lateral + f * lateral;
    record.curve.push_back(p);
  }
  if (from_rest) apply_static_state(engine, st, factor, v);
  else apply_static_path(engine, base, st, factor, v);
  record.elastic_start_strain = base_strain + factor * st.platen_displacement / H;
  // Sample the explicit part densely: about curve_points / 5 samples per first-break strain.
  const double per_step = v * record.dt / H;
  const double ramp = record.elastic_start_strain - base_strain;
  record.sample_every = std::max(1L, long(ramp / (0.2 * curve_points_) / per_step));
  Frame f = make_frame(engine, read(engine), "elastic_start");
  f.stress = base_stress + stress_of(0.5 * factor * (st.top_force + st.bottom_force), m);  // no step computed forces yet
  record.frames.push_back(std::move(f));
  const double interval = scene_.output.frame_strain_interval;
  record.next_frame = (std::floor(record.elastic_start_strain / interval) + 1.0) * interval;
}

bool UcsProtocol::stop_above(const Engine& engine, const Reading& reading, const TestRecord& record, double floor,
                             std::string& reason) const {
  if (engine.cracks().empty() || engine.steps() <= record.peak_step) return false;
  const bool dropped = reading.stress - floor < scene_.loading.stop_fraction * (record.peak - floor);
  const bool residual = reading.strain > (1.0 + scene_.loading.post_peak_strain) * record.at_peak.strain;
  if (!dropped && !residual) return false;
  reason = dropped ? "post_peak" : "post_peak_strain";
  return true;
}

bool UcsProtocol::stop(const Engine& engine, const Reading& reading, const TestRecord& record,
                       std::string& reason) const {
  return stop_above(engine, reading, record, 0.0, reason);
}

// --- confined compression -------------------------------------------------------------------------------------

StaticResult TriaxialProtocol::isotropic_state(const Engine& engine, double p, const std::atomic<int>* threads) {
  const Model& m = engine.model();
  const double target = p * m.width * m.thickness;  // N: the platen force of sigma_1 = p
  StaticOptions pressure;
  pressure.platen_displacement = 0.0;
  pressure.load = jacket_load(engine, p);
  pressure.threads = threads;
  StaticOptions closure;
  closure.threads = threads;
  closure.platen_displacement = 1e-6 * m.height;
  const StaticResult a = solve_static(engine, pressure);  // the jacket's pressure between fixed platens
  const StaticResult b = solve_static(engine, closure);   // a platen closure alone
  // sigma_1 = p: s closures on top of the pressure. Superposition holds while the linear parts' states agree; a
  // combined solve checks it and corrects s (secant on the platen force) until the force is p W t.
  double s = (target - a.top_force) / b.top_force;
  StaticResult state = superpose(a, 1.0, b, s);
  for (int it = 0; it < 10; ++it) {
    StaticOptions both = pressure;
    both.platen_displacement = s * closure.platen_displacement;
    state = solve_static(engine, both);
    const double miss = target - state.top_force;
    if (std::abs(miss) <= 1e-10 * target) break;
    s += miss / b.top_force;
  }
  return state;
}

bool TriaxialProtocol::prepares() const { return scene_.loading.confining_pressure > 0.0 || UcsProtocol::prepares(); }

// The static solves do not depend on the engine's confining pressure (the jacket's load is an input of each).
void TriaxialProtocol::prepare(const Engine& engine, const std::atomic<int>& threads) {
  const double p = scene_.loading.confining_pressure;
  if (!(p > 0.0)) {
    UcsProtocol::prepare(engine, threads);
    return;
  }
  prepared_isotropic_ = isotropic_state(engine, p, &threads);
  prepared_closure_ = closure_solve(engine, &threads);
}

void TriaxialProtocol::start(Engine& engine, TestRecord& record) {
  const double p = scene_.loading.confining_pressure;
  engine.set_confining_pressure(p);
  if (!(p > 0.0)) {
    UcsProtocol::start(engine, record);
    return;
  }
  const Model& m = engine.model();
  const double H = m.height, v = scene_.loading.platen_velocity;
  const StaticResult iso = prepared_isotropic_ ? std::move(*prepared_isotropic_) : isotropic_state(engine, p);
  prepared_isotropic_.reset();
  record.isotropic_strain = iso.platen_displacement / H;
  const double iso_lateral = gauge_.strain_of(iso.ux);
  const int n = 10;  // the isotropic stage on the curve (static: no time passes)
  for (int k = 1; k <= n; ++k) {
    const double f = double(k) / double(n);
    CurvePoint pt;
    pt.step = -1;
    pt.strain = f * record.isotropic_strain;
    pt.stress_top = pt.stress_bottom = f * p;
    pt.lateral_strain = f * iso_lateral;
    record.curve.push_back(pt);
  }
  const StaticResult axial = prepared_closure_ ? std::move(*prepared_closure_) : closure_solve(engine);
  prepared_closure_.reset();
  if (scene_.numerics.elastic_start) {
    start_along(engine, record, iso, axial, p);
  } else {
    apply_static_path(engine, iso, axial, 0.0, v);
    record.elastic_start_strain = record.isotropic_strain;
  }
}

bool TriaxialProtocol::stop(const Engine& engine, const Reading& reading, const TestRecord& record,
                            std::string& reason) const {
  return stop_above(engine, reading, record, scene_.loading.confining_pressure, reason);
}

void TriaxialProtocol::finish(const Engine& engine, const TestRecord& record, TestResult& result) const {
  result.confining_pressure = scene_.loading.confining_pressure;
  result.deviator_at_peak = record.peak - result.confining_pressure;
  result.isotropic_strain = record.isotropic_strain;
  result.jacket_edges_lost = engine.state().jacket_lost_max;
}

// --- the Brazilian test ---------------------------------------------------------------------------------------

BrazilianProtocol::BrazilianProtocol(const Scene& scene, const Topology& topo, int curve_points)
    : UcsProtocol(scene, topo, curve_points), topo_(topo) {}

void BrazilianProtocol::prepare(const Engine& engine, const std::atomic<int>& threads) {
  if (scene_.specimen.contact_arc_deg > 0.0) UcsProtocol::prepare(engine, threads);
}

void BrazilianProtocol::start(Engine& engine, TestRecord& record) {
  // Flattened ends: the platens load whole edges from the start, the model is linear, the static start applies. A
  // full disc touches the platens at points: the contact is nonlinear, the run explicit from the first touch.
  if (scene_.specimen.contact_arc_deg > 0.0) UcsProtocol::start(engine, record);
}

double BrazilianProtocol::stress_of(double force, const Model& m) const {
  return 2.0 * force / (std::numbers::pi * m.width * m.thickness);
}

Reading BrazilianProtocol::read(const Engine& engine) const {
  const Model& m = engine.model();
  Reading r;
  r.strain = engine.platen_displacement() / m.height;
  r.stress_top = stress_of(engine.top_force(), m);
  r.stress_bottom = stress_of(engine.bottom_force(), m);
  r.stress = stress_of(0.5 * (engine.top_force() + engine.bottom_force()), m);
  r.lateral_strain = gauge_.strain(engine);
  return r;
}

void BrazilianProtocol::finish(const Engine& engine, const TestRecord& record, TestResult& result) const {
  const Model& m = engine.model();
  result.diameter = m.width;
  result.tensile_strength = record.peak;
  result.peak_load = 0.5 * record.peak * std::numbers::pi * m.width * m.thickness;
  result.layer_angle_deg = 90.0 - scene_.joint_set.dip_deg;
  result.failure_mode = classify_brazilian(result.cracks, topo_);
}

std::string classify_brazilian(const std::vector<Crack>& cracks, const Topology& topo) {
  if (cracks.empty()) return "intact";
  const double xc = 0.5 * (topo.xmin + topo.xmax), radius = 0.5 * topo.width();
  double joint = 0, rock = 0, offset = 0;
  for (const Crack& c : cracks) {
    const double L = topo.bonds.length[std::size_t(c.bond)];
    if (c.kind == BondKind::joint) {
      joint += L;
    } else {
      rock += L;
      offset += L * std::abs(c.x - xc);
    }
  }
  const double share = joint / (joint + rock);
  if (share >= 0.5) return "layer_activation";
  if (share >= 0.2) return "mixed";
  return offset / rock < radius / 6.0 ? "central_fracture" : "non_central_fracture";
}

// --- running a test ---------------------------------------------------------------------------------------------

void check_test_scene(const std::string& test, const Scene& scene) {
  const bool disc = scene.specimen.shape == "disc";
  if (test == "brazilian" && !disc && scene.mesh.file.empty())
    throw SceneError("the Brazilian test loads a disc: set specimen.shape = \"disc\" (and specimen.diameter)");
  if (test != "brazilian" && disc)
    throw SceneError(fmt::format("rbdem {} compresses a rectangle between platens: specimen.shape = \"disc\" is for "
                                 "rbdem brazilian; set specimen.shape = \"rectangle\"",
                                 test));
  if (test != "triaxial" && scene.loading.confining_pressure > 0.0)
    throw SceneError(fmt::format("loading.confining_pressure = {} Pa: only rbdem triaxial applies a confining "
                                 "pressure; use rbdem triaxial, or set it to 0",
                                 scene.loading.confining_pressure));
}

TestResult run_test(const std::string& test, const Scene& scene, const Topology& topo, const RunOptions& options) {
  check_test_scene(test, scene);
  if (test == "triaxial") {
    TriaxialProtocol protocol(scene, topo, options.curve_points);
    return run_test(protocol, scene, topo, options);
  }
  if (test == "brazilian") {
    BrazilianProtocol protocol(scene, topo, options.curve_points);
    return run_test(protocol, scene, topo, options);
  }
  if (test != "ucs") throw std::invalid_argument("unknown test '" + test + "': ucs, triaxial or brazilian");
  UcsProtocol protocol(scene, topo, options.curve_points);
  return run_test(protocol, scene, topo, options);
}

TestResult run_ucs(const Scene& scene, const Topology& topo, const RunOptions& options) {
  return run_test("ucs", scene, topo, options);
}

namespace scene_keys {

// [loading]: the platens and the stop criteria of the compression tests.
void declare_loading(Keys& k) {
  k.add(positive("loading.platen_velocity", "m/s", 100.0, "closing speed of the top platen (bottom fixed)",
                 [](Scene& s) -> double& { return s.loading.platen_velocity; }));
  k.add(real("loading.platen_friction", "-", 0.0, 10.0, "Coulomb coefficient between platens and blocks",
             [](Scene& s) -> double& { return s.loading.platen_friction; }));
  k.add(real("loading.stop_fraction", "-", 0.0, 1.0,
             "stop when the stress falls below this fraction of the peak, after the peak",
             [](Scene& s) -> double& { return s.loading.stop_fraction; }, true));
  k.add(positive("loading.max_strain", "-", 1.0, "stop at this axial strain in any case",
                 [](Scene& s) -> double& { return s.loading.max_strain; }));
  k.add(positive("loading.post_peak_strain", "-", 1000.0,
                 "stop when the strain exceeds (1 + this) x the strain at the peak (residual phase reached)",
                 [](Scene& s) -> double& { return s.loading.post_peak_strain; }));
  k.add(real("loading.confining_pressure", "Pa", 0.0, 1e10,
             "lateral (confining) pressure of rbdem triaxial, on the specimen's sides as a jacket would apply it; "
             "ucs and brazilian refuse a value above 0",
             [](Scene& s) -> double& { return s.loading.confining_pressure; }));
  k.add(real("loading.fast_factor", "-", 1.0, 10.0,
             "while no bond breaks, the top platen speeds up to this multiple of platen_velocity, back to it at the "
             "next break (docs/model.md, Platens); 1 = constant speed",
             [](Scene& s) -> double& { return s.loading.fast_factor; }));
  k.add(positive("loading.quiet_transits", "-", 100.0,
                 "with fast_factor > 1: wave transits of the specimen without a break before the platen speeds up",
                 [](Scene& s) -> double& { return s.loading.quiet_transits; }));
}

}  // namespace scene_keys

}  // namespace rbdem
