// rbdem triaxial: confined compression. The confining pressure sigma_3 = loading.confining_pressure acts on the
// specimen's sides as a jacket would (follower forces, dem/boundary/jacket.cpp). The specimen is first brought to
// the isotropic state sigma_1 = sigma_3 statically (exact: the model is linear there), then the platens load it
// axially to failure, from a static start just below the first break along that path when numerics.elastic_start
// is on. The stop criteria and the signals apply to the deviator sigma_1 - sigma_3.
#include <optional>

#include <fmt/format.h>

#include "dem/driver/platen_test.hpp"
#include "dem/driver/registry.hpp"

namespace rbdem {

namespace {

class TriaxialProtocol final : public PlatenTest {
 public:
  using PlatenTest::PlatenTest;
  std::string name() const override { return "triaxial"; }
  void install(Simulation& sim) override {
    PlatenTest::install(sim);
    sim.add_jacket(0.0);  // the pressure comes with start(), after the static solves at rest
  }
  bool prepares() const override { return pressure() > 0.0 || PlatenTest::prepares(); }
  void prepare(const Simulation& sim, const std::atomic<int>& threads) override;
  void start(Simulation& sim, TestRecord& record) override;
  double stress_floor() const override { return pressure(); }
  void results(const Simulation& sim, const TestRecord& record, TestResult& result) const override;

 private:
  double pressure() const { return scene_.loading.confining_pressure; }

  std::optional<StaticResult> prepared_isotropic_;  // prepare()'s isotropic_state, taken by start()
};

// The static solves do not depend on the jacket's pressure at rest (the pressure's load is an input of each).
void TriaxialProtocol::prepare(const Simulation& sim, const std::atomic<int>& threads) {
  if (!(pressure() > 0.0)) {
    PlatenTest::prepare(sim, threads);
    return;
  }
  prepared_isotropic_ = isotropic_state(sim, pressure(), &threads);
  prepared_closure_ = closure_solve(sim, &threads);
}

void TriaxialProtocol::start(Simulation& sim, TestRecord& record) {
  const double p = pressure();
  sim.find<Jacket>()->set_pressure(p);
  if (!(p > 0.0)) {
    PlatenTest::start(sim, record);
    return;
  }
  const double H = sim.specimen().height(), v = scene_.loading.platen_velocity;
  const StaticResult iso = prepared_isotropic_ ? std::move(*prepared_isotropic_) : isotropic_state(sim, p);
  prepared_isotropic_.reset();
  record.preload_strain = iso.platen_displacement / H;
  const double iso_lateral = sim.lateral_strain_of(iso);
  const int n = 10;  // the isotropic stage on the curve (static: no time passes)
  for (int k = 1; k <= n; ++k) {
    const double f = double(k) / double(n);
    CurvePoint pt;
    pt.step = -1;
    pt.strain = f * record.preload_strain;
    pt.stress_top = pt.stress_bottom = f * p;
    pt.lateral_strain = f * iso_lateral;
    record.curve.push_back(pt);
  }
  const StaticResult axial = prepared_closure_ ? std::move(*prepared_closure_) : closure_solve(sim);
  prepared_closure_.reset();
  if (scene_.numerics.elastic_start) {
    start_along(sim, record, iso, axial, p);
  } else {
    sim.apply_static(iso, axial, 0.0, v);
    record.elastic_start_strain = record.preload_strain;
  }
}

void TriaxialProtocol::results(const Simulation& sim, const TestRecord& record, TestResult& result) const {
  const Jacket& jacket = *sim.find<Jacket>();
  result.own = {{"deviator_at_peak_pa", record.peak - pressure(), true},
                {"axial_strain_at_peak", record.at_peak.strain, true},
                {"isotropic_strain", record.preload_strain, false},
                {"jacket_edges_lost", double(jacket.faces_lost_max()), false}};
}

}  // namespace

ProtocolInfo triaxial_protocol() {
  ProtocolInfo p;
  p.name = "triaxial";
  p.description = "one confined (triaxial) compression test: --confining sets sigma_3";
  p.confined = true;
  p.options = {{"--confining", "loading.confining_pressure",
                "confining pressure sigma_3 [Pa] (loading.confining_pressure), e.g. --confining 10e6"}};
  p.check = [](const Scene& scene) {
    if (scene.specimen.shape == "disc")
      throw SceneError("rbdem triaxial compresses a rectangle between platens: specimen.shape = \"disc\" is for "
                       "rbdem brazilian; set specimen.shape = \"rectangle\"");
  };
  p.make = [](const Scene& scene, int curve_points) {
    return std::make_unique<TriaxialProtocol>(scene, curve_points);
  };
  p.headline = [](const TestResult& r) {
    return fmt::format("triaxial: sigma_1 {:.2f} MPa, deviator {:.2f} MPa at sigma_3 {:.2f} MPa, axial strain {:.3e}, "
                       "lateral {:.3e}",
                       r.peak_stress / 1e6, r.own_value("deviator_at_peak_pa") / 1e6, r.confining_pressure / 1e6,
                       r.strain_at_peak, r.lateral_strain_at_peak);
  };
  p.notes = [](const TestResult& r) {
    std::vector<std::string> notes;
    if (const double lost = r.own_value("jacket_edges_lost"); lost > 0)
      notes.push_back(fmt::format("up to {:g} jacket edges carried no pressure (their blocks broke off the specimen)",
                                  lost));
    return notes;
  };
  return p;
}

}  // namespace rbdem
