// PlatenTest: what the tests that load a specimen between two platens share (the uniaxial and confined compression
// tests and the Brazilian test of dem/driver/protocols/). The top platen closes at loading.platen_velocity, the
// bottom one is fixed; the curve's stress is the platens' force over the loaded area (a protocol may define it
// otherwise: stress_of); the run stops when the stress falls below loading.stop_fraction of the peak after the peak
// (or the strain passes (1 + loading.post_peak_strain) x the strain at the peak, or loading.max_strain). With
// numerics.elastic_start the linear part of the test is solved statically and the explicit run takes over at
// numerics.elastic_start_fraction of the first-break load (model only what the scene needs).
#pragma once

#include <limits>
#include <optional>

#include "dem/driver/protocol.hpp"

namespace rbdem {

class PlatenTest : public LoadingProtocol {
 public:
  PlatenTest(const Scene& scene, int curve_points) : scene_(scene), curve_points_(curve_points) {}
  void install(Simulation& sim) override;
  bool prepares() const override { return scene_.numerics.elastic_start; }
  void prepare(const Simulation& sim, const std::atomic<int>& threads) override;
  void start(Simulation& sim, TestRecord& record) override;
  Reading read(const Simulation& sim) const override;
  long max_steps(const Simulation& sim, const TestRecord& record) const override;
  bool stop(const Simulation& sim, const Reading& reading, const TestRecord& record,
            std::string& reason) const override;

 protected:
  // The curve's stress of a platen force F (N): F over the loaded area for the compression tests.
  virtual double stress_of(double force, const Simulation& sim) const { return force / platens(sim).area(); }
  const Platens& platens(const Simulation& sim) const { return *sim.find<Platens>(); }
  // The static start from `base` (empty: the unloaded specimen; or an isotropic state) along the platen path
  // `increment`, to numerics.elastic_start_fraction of the first break: the curve points of the ramp, the
  // simulation's state, the sampling interval and the first frame.
  void start_along(Simulation& sim, TestRecord& record, const StaticResult& base, const StaticResult& increment,
                   double base_stress) const;
  // The static solve of the uniaxial elastic start: the platen closure alone, from rest.
  StaticResult closure_solve(const Simulation& sim, const std::atomic<int>* threads = nullptr) const;
  // The highest curve stress (Pa) the static start may reach: a test that reverses or holds below the first break
  // starts its explicit run below its first turning point. No limit by default.
  virtual double start_stress_limit() const { return std::numeric_limits<double>::infinity(); }
  // N/m: the specimen's axial stiffness between the platens in the linear model, the mean platen force per unit of
  // platen closure (from the elastic start's closure solve, or a solve of its own when there was none).
  double axial_stiffness(const Simulation& sim);
  // m/s: the top platen's speed of the run (record.platen_velocity once the start set it, else the scene's).
  double velocity(const TestRecord& record) const;
  // m/s: the platen speed of the explicit run from a static start that reached `strain` and `stress` (the curve's)
  // from its base: loading.platen_velocity, or with loading.transit_strain_fraction > 0 the speed that follows the
  // rock.
  double rock_velocity(double strain, double stress, const Simulation& sim) const;
  // The load factor along `increment` whose strain and stress give rock_velocity, from the start's own `factor` (a
  // heterogeneous rock's is its weakest bond's) and no more than `cap`.
  double rate_factor(const Simulation& sim, const StaticResult& base, const StaticResult& increment, double factor,
                     double cap) const;
  // The share of a heterogeneous rock's bonds that would have broken, in the intact linear model, at the end of the
  // start that sets its loading rate (rate_factor).
  static constexpr double rate_break_share = 0.03;

  const Scene& scene_;
  int curve_points_;
  std::optional<StaticResult> prepared_closure_;  // prepare()'s closure_solve, taken by start()
  mutable std::optional<double> axial_stiffness_;  // N/m, known once a closure solve ran (start_along sets it)
};

// A test between platens, uniaxial or confined: with loading.confining_pressure > 0 a jacket applies it to the
// sides and the specimen is first brought statically to the isotropic state sigma_1 = sigma_3 (exact: the model
// is linear there), then the platens load it axially from a static start just below the first break along that
// path (numerics.elastic_start). The stop criteria and the signals apply to the deviator sigma_1 - sigma_3.
// rbdem triaxial, cyclic and hold share it.
class ConfinedPlatenTest : public PlatenTest {
 public:
  using PlatenTest::PlatenTest;
  void install(Simulation& sim) override;
  bool prepares() const override { return pressure() > 0.0 || PlatenTest::prepares(); }
  void prepare(const Simulation& sim, const std::atomic<int>& threads) override;
  void start(Simulation& sim, TestRecord& record) override;
  double stress_floor() const override { return pressure(); }

 protected:
  double pressure() const { return scene_.loading.confining_pressure; }

 private:
  std::optional<StaticResult> prepared_isotropic_;  // prepare()'s isotropic_state, taken by start()
};

// The static state of a hydrostatic stress sigma_1 = sigma_3 = p on a simulation with platens: the pressure p on
// the faces a jacket loads (Simulation::pressure_load) between fixed platens, and the platen closure that makes the
// platen stress p, found by superposing the two linear solutions (and re-solved until the linear parts' states
// agree). The start of a confined test.
StaticResult isotropic_state(const Simulation& sim, double pressure, const std::atomic<int>* threads = nullptr);

// The platen servo of a stress hold (rbdem hold, dem/driver/protocols/hold.cpp): the target `target` (Pa), the gain
// A / (10 sqrt(K M)) of the specimen's axial stiffness K (N/m), mass M (kg) and loaded area A (m^2), and the rate
// limit `max_velocity` (m/s). docs/theory.md states the rule.
PlatenServo hold_servo(double stiffness, double mass, double area, double target, double max_velocity);

}  // namespace rbdem
