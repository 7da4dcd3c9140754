// The uniaxial compression protocol. See ucs.hpp.
#include "dem/driver/ucs.hpp"

#include <algorithm>
#include <cmath>

#include "dem/driver/monitors.hpp"
#include "dem/static_solve.hpp"
#include "dem/scene_keys.hpp"

namespace rbdem {

Reading UcsProtocol::platen_reading(const Engine& engine) const {
  const double H = engine.model().height, area = engine.model().width * engine.model().thickness;
  Reading r;
  r.strain = engine.platen_displacement() / H;
  r.stress_top = engine.top_force() / area;
  r.stress_bottom = engine.bottom_force() / area;
  r.stress = 0.5 * (engine.top_force() + engine.bottom_force()) / area;
  return r;
}

Reading UcsProtocol::read(const Engine& engine) const { return platen_reading(engine); }

long UcsProtocol::max_steps(const Engine& engine, const TestRecord& record) const {
  const double H = engine.model().height, v = scene_.loading.platen_velocity;
  return long(std::ceil((scene_.loading.max_strain - record.elastic_start_strain) * H / (v * record.dt)));
}

void UcsProtocol::start(Engine& engine, TestRecord& record) {
  if (scene_.numerics.elastic_start) elastic_start(engine, record);
}

// The model is linear until the first bond breaks: solve that part statically and hand over to the explicit run
// at a fraction of the first-break load.
void UcsProtocol::elastic_start(Engine& engine, TestRecord& record) const {
  const double H = engine.model().height, area = engine.model().width * engine.model().thickness;
  const double v = scene_.loading.platen_velocity;
  const StaticResult st = solve_static(engine, {1e-6 * H, false, 30});
  const double max_factor = scene_.loading.max_strain * H / st.platen_displacement;
  const double factor = std::min(scene_.numerics.elastic_start_fraction * st.first_break_factor, 0.5 * max_factor);
  if (!(factor > 0 && std::isfinite(factor))) return;
  const int n = 20;
  for (int k = 1; k <= n; ++k) {
    const double f = factor * double(k) / double(n);
    CurvePoint p;
    p.step = -1;
    p.strain = f * st.platen_displacement / H;
    p.time = f * st.platen_displacement / v;
    p.stress_top = f * st.top_force / area;
    p.stress_bottom = f * st.bottom_force / area;
    record.curve.push_back(p);
  }
  apply_static_state(engine, st, factor, v);
  record.elastic_start_strain = factor * st.platen_displacement / H;
  // Sample the explicit part densely: about curve_points / 5 samples per first-break strain.
  const double per_step = v * record.dt / H;
  record.sample_every = std::max(1L, long(record.elastic_start_strain / (0.2 * curve_points_) / per_step));
  Frame f = make_frame(engine, platen_reading(engine), "elastic_start");
  f.stress = 0.5 * factor * (st.top_force + st.bottom_force) / area;  // no step computed forces yet
  record.frames.push_back(std::move(f));
  const double interval = scene_.output.frame_strain_interval;
  record.next_frame = (std::floor(record.elastic_start_strain / interval) + 1.0) * interval;
}

bool UcsProtocol::stop(const Engine& engine, const Reading& reading, const TestRecord& record,
                       std::string& reason) const {
  if (engine.cracks().empty() || engine.steps() <= record.peak_step) return false;
  const bool dropped = reading.stress < scene_.loading.stop_fraction * record.peak;
  const bool residual = reading.strain > (1.0 + scene_.loading.post_peak_strain) * record.at_peak.strain;
  if (!dropped && !residual) return false;
  reason = dropped ? "post_peak" : "post_peak_strain";
  return true;
}

TestResult run_ucs(const Scene& scene, const Topology& topo, const RunOptions& options) {
  UcsProtocol protocol(scene, options.curve_points);
  return run_test(protocol, scene, topo, options);
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
}

}  // namespace scene_keys

}  // namespace rbdem
