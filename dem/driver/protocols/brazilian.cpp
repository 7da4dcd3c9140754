// rbdem brazilian: a disc (specimen.shape = "disc") between two flat platens, loaded along its vertical diameter.
// Its top and bottom are flattened over the contact arc 2 alpha (specimen.contact_arc_deg, 10 deg by default, the
// contact of ISRM's curved jaws), so the platens load an arc as the jaws do and the start is linear: the static
// elastic start applies as in the compression tests. With a contact arc of 0 the platens touch single points, the
// contact grows with the load, and the run is explicit from the first touch. The curve's stress is the ISRM tensile
// stress 2 P / (pi D t) of the platen force P; its peak is the Brazilian tensile strength. Failure modes as the
// literature names them for layered discs: a central fracture across the layers, layer activation (splitting along
// the joints), mixed, or a fracture off the loaded diameter.
//
// A 3D scene (specimen.dimension = 3) loads the solid disc of dem/specimen_mesh3.hpp, its axis along y, between the
// same platens: t is then the disc's extent along its axis, and the flats are required (the 3D platens and the 3D
// static start load faces on the platen planes; a full disc touches them along a line, which no face lies on).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <fmt/format.h>

#include "dem/driver/platen_test.hpp"
#include "dem/driver/registry.hpp"
#include "dem/driver/summary.hpp"

namespace rbdem {

std::string classify_brazilian(const std::vector<Crack>& cracks, const Specimen& specimen) {
  if (cracks.empty()) return "intact";
  const double xc = specimen.centre(0), radius = 0.5 * specimen.width();
  double joint = 0, rock = 0, offset = 0;
  for (const Crack& c : cracks) {
    const double L = c.size;
    if (c.kind == BondKind::joint) {
      joint += L;
    } else {
      rock += L;
      offset += L * std::abs(c.position[0] - xc);
    }
  }
  const double share = joint / (joint + rock);
  if (share >= 0.5) return "layer_activation";
  if (share >= 0.2) return "mixed";
  return offset / rock < radius / 6.0 ? "central_fracture" : "non_central_fracture";
}

namespace {

// The times (s) of the breaks before `until_time` under a platen: within 1.5 block sizes of a flat's plane and no
// further from the loaded diameter than the flat's half-width and one block. A disc that crushes at its flats
// breaks these.
std::vector<double> platen_break_times(const std::vector<Crack>& cracks, const Specimen& specimen,
                                       double contact_arc_deg, double until_time) {
  const int axis = specimen.dim - 1;
  const double xc = specimen.centre(0), radius = 0.5 * specimen.width();
  const double lo = specimen.lo[std::size_t(axis)], hi = specimen.hi[std::size_t(axis)];
  // The blocks' size: the mean bond edge (2D), or the edge of an equilateral triangle of the mean face area (3D).
  double mean = 0;
  for (double a : specimen.bonds.size) mean += a;
  mean /= double(std::max<std::size_t>(specimen.bonds.size.size(), 1));
  const double h = specimen.dim == 2 ? mean : std::sqrt(mean / (0.25 * std::sqrt(3.0)));
  const double half_flat = radius * std::sin(0.5 * contact_arc_deg * std::numbers::pi / 180.0);
  std::vector<double> times;
  for (const Crack& c : cracks) {
    if (c.time > until_time) continue;
    const double depth = std::min(hi - c.position[std::size_t(axis)], c.position[std::size_t(axis)] - lo);
    if (depth <= 1.5 * h && std::abs(c.position[0] - xc) <= half_flat + h) times.push_back(c.time);
  }
  return times;
}

// Whether the run's platen forces differ by more than the quasi-static limit only in the `window` (s) after a
// break under a platen: every sample the verdict reads (explicit, before the peak, between 20 and 95 % of it; the
// first explicit one if there is none) that is over the limit comes that soon after such a break, and one does.
bool crushed_at_flats(const TestResult& r, const std::vector<double>& breaks, double window) {
  const double peak = r.peak_stress;
  std::vector<const CurvePoint*> read;
  const CurvePoint* first = nullptr;
  for (const CurvePoint& p : r.curve) {
    if (p.step <= 0 || p.strain >= r.strain_at_peak) continue;
    if (!first) first = &p;
    if (p.stress() >= 0.2 * peak && p.stress() <= 0.95 * peak) read.push_back(&p);
  }
  if (read.empty() && first) read.push_back(first);
  bool any = false;
  for (const CurvePoint* p : read) {
    if (!(std::abs(p->stress_top - p->stress_bottom) > quasi_static_force_mismatch_limit * p->stress())) continue;
    const bool after_break = std::any_of(breaks.begin(), breaks.end(),
                                         [&](double t) { return t <= p->time && p->time - t <= window; });
    if (!after_break) return false;
    any = true;
  }
  return any;
}

// The disc's thickness t: the slice's out-of-plane thickness (2D) or the solid's extent along its axis y (3D).
double disc_thickness(const Specimen& s) { return s.dim == 3 ? s.hi[1] - s.lo[1] : s.thickness; }

class BrazilianProtocol final : public PlatenTest {
 public:
  using PlatenTest::PlatenTest;
  std::string name() const override { return "brazilian"; }
  bool prepares() const override { return flattened() && PlatenTest::prepares(); }
  void prepare(const Simulation& sim, const std::atomic<int>& threads) override {
    if (flattened()) PlatenTest::prepare(sim, threads);
  }
  // Flattened ends: the platens load whole edges from the start, the model is linear, the static start applies. A
  // full disc touches the platens at points: the contact is nonlinear, the run explicit from the first touch.
  void start(Simulation& sim, TestRecord& record) override {
    if (flattened()) PlatenTest::start(sim, record);
    else record.platen_velocity = scene_.loading.platen_velocity;
  }
  bool lateral_signals() const override { return false; }
  void results(const Simulation& sim, const TestRecord& record, TestResult& result) const override {
    const Specimen& s = sim.specimen();
    result.own = {{"tensile_strength_pa", record.peak, true},
                  {"peak_load_n", 0.5 * record.peak * std::numbers::pi * s.width() * disc_thickness(s), true},
                  {"layer_angle_deg", 90.0 - scene_.joint_set.dip_deg, false},
                  {"diameter_m", s.width(), false},
                  {"platen_cracks_before_peak",
                   double(platen_break_times(sim.cracks(), s, scene_.specimen.contact_arc_deg, record.at_peak.time)
                              .size()),
                   true},
                  {"crushed_at_flats", 0.0, true}};
  }
  void finish(const Simulation& sim, const TestRecord& record, TestResult& result) const override {
    result.failure_mode = classify_brazilian(result.cracks, sim.specimen());
    // A disc that cracks under its flats before the peak unloads that platen at once: the platen forces differ
    // until the unloading has crossed the disc, a few hundred steps with the local damping (about three elastic
    // transits D / c), whatever the platen speed (docs/model.md, "The Brazilian test"). The advice is then the
    // flats, not the speed.
    const Specimen& s = sim.specimen();
    const auto breaks = platen_break_times(result.cracks, s, scene_.specimen.contact_arc_deg, record.at_peak.time);
    const double c = std::sqrt(scene_.rock.effective_modulus / (scene_.rock.density * scene_.numerics.mass_scaling));
    const bool crushed = !result.quasi_static && crushed_at_flats(result, breaks, 5.0 * s.width() / c);
    for (ResultValue& v : result.own)
      if (v.key == "crushed_at_flats") v.value = crushed ? 1.0 : 0.0;
    const auto advice = result.quasi_static_reason.find(": lower loading.platen_velocity");
    if (crushed && advice != std::string::npos)
      result.quasi_static_reason = fmt::format(
          "{}, each time after bonds broke under a platen ({} before the peak): a break there unloads its platen at "
          "once, at any platen speed; widen the flats (specimen.contact_arc_deg, 20 deg) or refine mesh.size",
          result.quasi_static_reason.substr(0, advice), breaks.size());
  }

 protected:
  // 2 F / (pi D t), the ISRM tensile stress of the load F on a disc of diameter D and thickness t.
  double stress_of(double force, const Simulation& sim) const override {
    return 2.0 * force / (std::numbers::pi * sim.specimen().width() * disc_thickness(sim.specimen()));
  }

 private:
  bool flattened() const { return scene_.specimen.contact_arc_deg > 0.0; }
};

}  // namespace

ProtocolInfo brazilian_protocol() {
  ProtocolInfo p;
  p.name = "brazilian";
  p.description = "one Brazilian (diametral compression) test of a disc";
  p.tensile = true;
  p.scene_defaults = {{"specimen.shape", "disc"}};
  p.check = [](const Scene& scene) {
    if (scene.specimen.shape != "disc" && scene.mesh.file.empty())
      throw SceneError("the Brazilian test loads a disc: set specimen.shape = \"disc\" (and specimen.diameter)");
    refuse_confining_pressure("brazilian", scene);
    if (scene.specimen.dimension == 3 && scene.mesh.file.empty() && !(scene.specimen.contact_arc_deg > 0.0))
      throw SceneError("specimen.contact_arc_deg = 0: the 3D Brazilian disc is loaded on its flats (the 3D platens "
                       "and static start load faces on the platen planes); give a contact arc, e.g. 10 deg (ISRM)");
    if (scene.loading.transit_strain_fraction > 0.0 && !(scene.specimen.contact_arc_deg > 0.0))
      throw SceneError("loading.transit_strain_fraction sets the platen speed from the static elastic start, which a "
                       "disc touched at points (specimen.contact_arc_deg = 0) has not: give a contact arc, or set "
                       "loading.transit_strain_fraction = 0 and loading.platen_velocity");
  };
  p.make = [](const Scene& scene, int curve_points) {
    return std::make_unique<BrazilianProtocol>(scene, curve_points);
  };
  p.headline = [](const TestResult& r) {
    return fmt::format("brazilian: tensile strength {:.3f} MPa (peak load {:.4g} N, layers at {:g} deg to the load)",
                       r.own_value("tensile_strength_pa") / 1e6, r.own_value("peak_load_n"),
                       r.own_value("layer_angle_deg"));
  };
  return p;
}

}  // namespace rbdem
