// The uniaxial compression test: the specimen between two platens, the top one closing at
// loading.platen_velocity, run until the stress falls below loading.stop_fraction of the peak after the peak (or
// the strain passes (1 + loading.post_peak_strain) x the strain at the peak, or loading.max_strain). With
// numerics.elastic_start the linear part of the test is solved statically and the explicit run takes over at
// numerics.elastic_start_fraction of the first-break load (model only what the scene needs).
#pragma once

#include "dem/driver/driver.hpp"
#include "dem/driver/protocol.hpp"

namespace rbdem {

class UcsProtocol : public LoadingProtocol {
 public:
  explicit UcsProtocol(const Scene& scene, int curve_points = 2000) : scene_(scene), curve_points_(curve_points) {}
  std::string name() const override { return "ucs"; }
  void start(Engine& engine, TestRecord& record) override;
  Reading read(const Engine& engine) const override;
  long max_steps(const Engine& engine, const TestRecord& record) const override;
  bool stop(const Engine& engine, const Reading& reading, const TestRecord& record, std::string& reason) const override;

 protected:
  // Platen stresses and the axial strain of the engine's current state.
  Reading platen_reading(const Engine& engine) const;
  // The static elastic start under the platens alone (the UCS part of every compression protocol).
  void elastic_start(Engine& engine, TestRecord& record) const;

  const Scene& scene_;
  int curve_points_;
};

// Runs the uniaxial compression test of `scene` on `topo`.
TestResult run_ucs(const Scene& scene, const Topology& topo, const RunOptions& options = {});

}  // namespace rbdem
