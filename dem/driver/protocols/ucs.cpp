// rbdem ucs: uniaxial compression. The specimen between two platens (dem/driver/platen_test.hpp), the top one
// closing at loading.platen_velocity, until the stress falls below loading.stop_fraction of the peak after the
// peak. Its own numbers are the shared ones (the peak, E50, the signals).
#include <fmt/format.h>

#include "dem/driver/platen_test.hpp"
#include "dem/driver/registry.hpp"

namespace rbdem {

namespace {

class UcsProtocol final : public PlatenTest {
 public:
  using PlatenTest::PlatenTest;
  std::string name() const override { return "ucs"; }
};

}  // namespace

ProtocolInfo ucs_protocol() {
  ProtocolInfo p;
  p.name = "ucs";
  p.description = "one uniaxial compression test";
  p.check = [](const Scene& scene) {
    if (scene.specimen.shape == "disc")
      throw SceneError("rbdem ucs compresses a rectangle between platens: specimen.shape = \"disc\" is for rbdem "
                       "brazilian; set specimen.shape = \"rectangle\"");
    refuse_confining_pressure("ucs", scene);
  };
  p.make = [](const Scene& scene, int curve_points) { return std::make_unique<UcsProtocol>(scene, curve_points); };
  p.headline = [](const TestResult& r) {
    return fmt::format("ucs: peak {:.2f} MPa at strain {:.3e}, E50 {:.2f} GPa", r.peak_stress / 1e6, r.strain_at_peak,
                       r.youngs_modulus / 1e9);
  };
  return p;
}

}  // namespace rbdem
