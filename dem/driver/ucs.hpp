// The compression tests and the Brazilian test, each a loading protocol on the test driver (dem/driver/driver.hpp).
//
// UcsProtocol: uniaxial compression. The specimen between two platens, the top one closing at
// loading.platen_velocity, run until the stress falls below loading.stop_fraction of the peak after the peak (or the
// strain passes (1 + loading.post_peak_strain) x the strain at the peak, or loading.max_strain). With
// numerics.elastic_start the linear part of the test is solved statically and the explicit run takes over at
// numerics.elastic_start_fraction of the first-break load (model only what the scene needs).
//
// TriaxialProtocol: confined compression. The confining pressure sigma_3 = loading.confining_pressure acts on the
// specimen's sides as a jacket would (follower forces, dem/stages/jacket.cpp). The specimen is first brought to the
// isotropic state sigma_1 = sigma_3 statically (exact: the model is linear there), then the platens load it axially
// to failure, from a static start just below the first break along that path when numerics.elastic_start is on.
// The stop criteria apply to the deviator sigma_1 - sigma_3.
//
// BrazilianProtocol: a disc (specimen.shape = "disc") between two flat platens, loaded along its vertical diameter.
// Its top and bottom are flattened over the contact arc 2 alpha (specimen.contact_arc_deg, 10 deg by default, the
// contact of ISRM's curved jaws), so the platens load an arc as the jaws do and the start is linear: the static
// elastic start applies as in the compression tests. With a contact arc of 0 the platens touch single points, the
// contact grows with the load, and the run is explicit from the first touch. The curve's stress is the ISRM tensile
// stress 2 P / (pi D t) of the platen force P; its peak is the Brazilian tensile strength. Failure modes as the
// literature names them for layered discs: a central fracture across the layers, layer activation (splitting along
// the joints), mixed, or a fracture off the loaded diameter.
#pragma once

#include <optional>

#include "dem/driver/driver.hpp"
#include "dem/driver/protocol.hpp"
#include "dem/static_solve.hpp"

namespace rbdem {

class UcsProtocol : public LoadingProtocol {
 public:
  UcsProtocol(const Scene& scene, const Topology& topo, int curve_points = 2000)
      : scene_(scene), curve_points_(curve_points), gauge_(topo) {}
  std::string name() const override { return "ucs"; }
  bool prepares() const override { return scene_.numerics.elastic_start; }
  void prepare(const Engine& engine, const std::atomic<int>& threads) override;
  void start(Engine& engine, TestRecord& record) override;
  Reading read(const Engine& engine) const override;
  long max_steps(const Engine& engine, const TestRecord& record) const override;
  bool stop(const Engine& engine, const Reading& reading, const TestRecord& record, std::string& reason) const override;

 protected:
  // Platen stresses, the axial and the lateral strain of the engine's current state.
  Reading platen_reading(const Engine& engine) const;
  // The curve's stress of a platen force (N): F / (W t) for the compression tests.
  virtual double stress_of(double force, const Model& m) const { return force / (m.width * m.thickness); }
  // The static start from `base` (the unloaded state, or an isotropic one) along the platen path `increment`, to
  // numerics.elastic_start_fraction of the first break: the curve points of the ramp, the engine's state, the
  // sampling interval and the first frame.
  void start_along(Engine& engine, TestRecord& record, const StaticResult& base, const StaticResult& increment,
                   double base_stress) const;
  // The stop criteria on the stress above `floor` (0 uniaxially, sigma_3 for a confined test).
  bool stop_above(const Engine& engine, const Reading& reading, const TestRecord& record, double floor,
                  std::string& reason) const;

  // The static solve of the uniaxial elastic start: the platen closure alone, from rest.
  StaticResult closure_solve(const Engine& engine, const std::atomic<int>* threads = nullptr) const;

  const Scene& scene_;
  int curve_points_;
  LateralGauge gauge_;
  std::optional<StaticResult> prepared_closure_;  // prepare()'s closure_solve, taken by start()
};

class TriaxialProtocol : public UcsProtocol {
 public:
  using UcsProtocol::UcsProtocol;
  std::string name() const override { return "triaxial"; }
  bool prepares() const override;
  void prepare(const Engine& engine, const std::atomic<int>& threads) override;
  void start(Engine& engine, TestRecord& record) override;
  bool stop(const Engine& engine, const Reading& reading, const TestRecord& record, std::string& reason) const override;
  void finish(const Engine& engine, const TestRecord& record, TestResult& result) const override;

  // The static isotropic state sigma_1 = sigma_3 = p: the pressure on the jacket and the platen closure that makes
  // the platen stress p, found by superposing the two linear solutions (and re-solved until the linear parts'
  // states agree).
  static StaticResult isotropic_state(const Engine& engine, double pressure,
                                      const std::atomic<int>* threads = nullptr);

 private:
  std::optional<StaticResult> prepared_isotropic_;  // prepare()'s isotropic_state, taken by start()
};

class BrazilianProtocol : public UcsProtocol {
 public:
  BrazilianProtocol(const Scene& scene, const Topology& topo, int curve_points = 2000);
  std::string name() const override { return "brazilian"; }
  bool prepares() const override { return scene_.specimen.contact_arc_deg > 0.0 && UcsProtocol::prepares(); }
  void prepare(const Engine& engine, const std::atomic<int>& threads) override;
  void start(Engine& engine, TestRecord& record) override;
  Reading read(const Engine& engine) const override;
  void finish(const Engine& engine, const TestRecord& record, TestResult& result) const override;
  // 2 F / (pi D t), the ISRM tensile stress of the load F on a disc of diameter D.
  double stress_of(double force, const Model& m) const override;

 private:
  const Topology& topo_;
};

// Failure modes of a layered Brazilian disc from its crack log (length-weighted): "layer_activation" when joint
// cracks make half or more of the crack length, "mixed" from a fifth, else "central_fracture" when the rock cracks lie
// along the loaded diameter (mean distance under a sixth of the radius) or "non_central_fracture"; "intact" without
// cracks.
std::string classify_brazilian(const std::vector<Crack>& cracks, const Topology& topo);

// Runs the test `test` ("ucs", "triaxial" or "brazilian") of `scene` on `topo`. Throws SceneError when the scene
// does not suit the test (a Brazilian test needs specimen.shape = "disc"; only the confined test takes a confining
// pressure).
TestResult run_test(const std::string& test, const Scene& scene, const Topology& topo, const RunOptions& options = {});
// The uniaxial test.
TestResult run_ucs(const Scene& scene, const Topology& topo, const RunOptions& options = {});
// Refuses a scene that does not suit the test, with the key and the fix.
void check_test_scene(const std::string& test, const Scene& scene);

}  // namespace rbdem
