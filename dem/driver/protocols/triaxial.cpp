// rbdem triaxial: confined compression. The confining pressure sigma_3 = loading.confining_pressure acts on the
// specimen's sides as a jacket would (follower forces, dem/boundary/jacket.cpp). The specimen is first brought to
// the isotropic state sigma_1 = sigma_3 statically (exact: the model is linear there), then the platens load it
// axially to failure, from a static start just below the first break along that path when numerics.elastic_start
// is on (ConfinedPlatenTest, dem/driver/platen_test.hpp). The stop criteria and the signals apply to the deviator
// sigma_1 - sigma_3.
#include <fmt/format.h>

#include "dem/driver/platen_test.hpp"
#include "dem/driver/registry.hpp"

namespace rbdem {

namespace {

class TriaxialProtocol final : public ConfinedPlatenTest {
 public:
  using ConfinedPlatenTest::ConfinedPlatenTest;
  std::string name() const override { return "triaxial"; }
  void results(const Simulation& sim, const TestRecord& record, TestResult& result) const override;
};

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
