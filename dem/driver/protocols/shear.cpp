// rbdem shear: direct shear of one joint (ISRM suggested method), under a constant normal load (CNL) or a constant
// normal stiffness (CNS). The specimen is a rectangle with one horizontal joint across it. Two rigid boxes hold its
// halves whole, so that the joint's bonds alone are sheared, evenly along its length, as in a shear box whose
// grout holds each half up to the joint: the lower box holds every block below the joint fixed, the upper box moves
// every block above it as one rigid body, along the joint at loading.shear_velocity, across it under a servo to the
// normal load, and holds it from turning. (Boxes that left the rock next to the joint free would load it in tension
// through its inclined bonds, and its tensile strength is of the order of the joint's shear strength: the rock
// would crack before the joint slid.) The specimen is meshed as a structured grid (mesh.structured, a scene
// default of the command), so that every joint bond has the same stiffness, carries the mean traction and breaks in
// the same step: the peak is the joint's envelope (docs/theory.md, section 9.6).
//
// The test has two stages, told apart by the upper box's speed along the joint (so that a resumed run goes on the
// same): first the normal load comes on with the box held along the joint, until the normal stress is within 0.1 %
// of loading.normal_stress; then the box moves along the joint until it has moved loading.max_shear_displacement.
// Under CNS the servo's load is sigma_n0 A + k A (v - v0), with v - v0 the dilation since the shear began. The
// curve's stress is the shear stress (the boxes' forces along the joint over its nominal area); its strain is the
// shear displacement over the joint's length. No block moves on its own, so no block's dynamics bounds the time
// step: it is chosen so that the box moves 1/200 of the joint's elastic slip at its cohesion per step.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "dem/driver/registry.hpp"
#include "dem/laws/parallel_bond.hpp"

namespace rbdem {

namespace {

constexpr const char* lower_box_name = "lower_box";
constexpr const char* upper_box_name = "upper_box";
// The servo's gain: the upper box moves alpha x (load - reaction) / K per step, K the stiffness of the bonds that
// tie it to the rest of the model (its instantaneous response) plus the CNS spring's: alpha < 1 never overshoots
// the instantaneous response, and 0.25 settles the normal load in a few hundred steps.
constexpr double servo_alpha = 0.25;
// The normal stress at which the shear begins, relative to loading.normal_stress.
constexpr double consolidation_tolerance = 1e-3;
// The most steps the normal load may take to come on (it takes a few hundred; the run ends if it never settles).
constexpr long consolidation_steps_max = 20000;

// The steps per elastic slip of the joint at its cohesion: the resolution of the shear (the peak comes after one to
// a few such slips).
constexpr double steps_per_cohesive_slip = 200.0;

// The blocks each box holds.
struct ShearBoxes {
  std::vector<int> lower, upper;  // ascending
};

// Finds the joint (every joint bond on one horizontal line) and splits the blocks at it. SceneError when the
// specimen has no joint or its joint bonds are not on one horizontal line (a user mesh).
ShearBoxes shear_boxes(const Specimen& s) {
  const double tol = 1e-6 * s.height();
  double y_min = 1e300, y_max = -1e300;
  for (std::size_t e = 0; e < s.num_bonds(); ++e)
    if (s.bonds.kind[e] == BondKind::joint)
      y_min = std::min(y_min, s.midpoint(e, 1)), y_max = std::max(y_max, s.midpoint(e, 1));
  if (y_min > y_max)
    throw SceneError("rbdem shear needs one joint across the specimen and this one has none: set joint_set.enabled = "
                     "true (with joint_set.dip_deg = 0)");
  if (y_max - y_min > tol)
    throw SceneError(fmt::format("rbdem shear needs one horizontal joint, and the specimen's joint bonds lie between "
                                 "y = {:.4g} m and {:.4g} m: give a mesh with one straight horizontal joint",
                                 y_min, y_max));
  const double joint_y = 0.5 * (y_min + y_max);
  ShearBoxes b;
  for (std::size_t k = 0; k < s.num_blocks(); ++k) (s.centroid(k, 1) < joint_y ? b.lower : b.upper).push_back(int(k));
  return b;
}

// The uniformity of the joint's bonds, k_mean / k_max with k = E* / d the stiffness per area of a bond whose blocks'
// centroids are d apart across it (k_mean weighted by the bonds' areas). The boxes slip every bond by the same
// amount, so a bond carries k / k_mean of the mean stress, normal and shear alike, and the stiffest one reaches its
// strength first, when the mean shear stress is (k_mean / k_max) c_j + sigma_n tan(phi_j): the joint's envelope
// with its cohesion scaled by this ratio (1 for bonds of one stiffness).
double joint_stiffness_uniformity(const Specimen& s) {
  double sum = 0, area = 0, k_max = 0;
  for (std::size_t e = 0; e < s.num_bonds(); ++e) {
    if (s.bonds.kind[e] != BondKind::joint) continue;
    const std::size_t i = std::size_t(s.bonds.i[e]), j = std::size_t(s.bonds.j[e]);
    double d = 0;
    for (int c = 0; c < s.dim; ++c) d += (s.centroid(j, c) - s.centroid(i, c)) * s.normal(e, c);
    const double k = 1.0 / std::abs(d);
    sum += k * s.bonds.size[e], area += s.bonds.size[e], k_max = std::max(k_max, k);
  }
  return k_max > 0 ? sum / area / k_max : 1.0;
}

const BlockGroup& box(const Simulation& sim, const char* name) {
  for (const Boundary* b : sim.boundaries())
    if (const auto* g = dynamic_cast<const BlockGroup*>(b); g && g->name() == name) return *g;
  throw std::logic_error(fmt::format("rbdem shear: the simulation has no block group '{}'", name));
}
BlockGroup& box(Simulation& sim, const char* name) {
  return const_cast<BlockGroup&>(box(static_cast<const Simulation&>(sim), name));
}

class ShearProtocol final : public LoadingProtocol {
 public:
  ShearProtocol(const Scene& scene, int curve_points) : scene_(scene), curve_points_(curve_points) {}
  std::string name() const override { return "shear"; }
  void install(Simulation& sim) override;
  double max_time_step(const Simulation& sim) const override;
  void start(Simulation& sim, TestRecord& record) override;
  Reading read(const Simulation& sim) const override;
  void control(Simulation& sim, const Reading& reading, const TestRecord& record) override;
  long max_steps(const Simulation& sim, const TestRecord& record) const override;
  bool stop(const Simulation& sim, const Reading& reading, const TestRecord& record,
            std::string& reason) const override;
  bool lateral_signals() const override { return false; }
  void results(const Simulation& sim, const TestRecord& record, TestResult& result) const override;
  void finish(const Simulation& sim, const TestRecord& record, TestResult& result) const override;

 private:
  double area(const Simulation& sim) const { return sim.specimen().width() * sim.specimen().thickness; }
  double sigma0() const { return scene_.loading.normal_stress; }
  MohrCoulomb envelope() const {
    const MaterialParams& j = scene_.joint;
    return interface_envelope(j.cohesion, std::tan(j.friction_deg * std::numbers::pi / 180.0), j.contact_friction,
                              j.slip_when_bonded);
  }
  static bool shearing(const BlockGroup& upper) { return upper.settings().value[0] != 0.0; }
  long shear_steps(double dt) const {
    return long(std::ceil(scene_.loading.max_shear_displacement / (scene_.loading.shear_velocity * dt)));
  }

  const Scene& scene_;
  int curve_points_;
};

void ShearProtocol::install(Simulation& sim) {
  const ShearBoxes b = shear_boxes(sim.specimen());
  GroupSettings lower;
  lower.name = lower_box_name;
  lower.blocks = b.lower;
  sim.add_group(lower);
  GroupSettings upper;
  upper.name = upper_box_name;
  upper.blocks = b.upper;
  using Mode = GroupSettings::Mode;
  upper.modes = {Mode::velocity, Mode::servo, Mode::fixed};
  upper.value = {0.0, -sigma0() * area(sim), 0.0};  // held along the joint while the normal load comes on
  upper.servo = {1.0, 1.0, 0.0, 0.0};              // start() sets it from the model's stiffness and the time step
  sim.add_group(upper);
}

// The joint's elastic slip at its cohesion, c_j A / K_s with K_s the joint's shear stiffness (the bonds between the
// boxes), in steps_per_cohesive_slip steps at loading.shear_velocity.
double ShearProtocol::max_time_step(const Simulation& sim) const {
  const double ks = box(sim, upper_box_name).attachment_stiffness()[0];
  const double slip = envelope().cohesion * area(sim) / ks;
  return slip / (steps_per_cohesive_slip * scene_.loading.shear_velocity);
}

// The servo from the model's stiffness: gain alpha / (K dt); the rate limit lets the normal force change by at most
// 10 % of the normal load (or of the joint's cohesive strength when there is none) per step at that stiffness.
void ShearProtocol::start(Simulation& sim, TestRecord& record) {
  BlockGroup& upper = box(sim, upper_box_name);
  const double A = area(sim), dt = sim.dt();
  const double K = upper.attachment_stiffness()[1] + scene_.loading.normal_stiffness * A;
  const double scale = std::max(sigma0(), scene_.joint.cohesion) * A;
  GroupServo servo;
  servo.gain = servo_alpha / (K * dt);
  servo.max_velocity = std::max(scene_.loading.shear_velocity, 0.1 * scale / (K * dt));
  upper.set_servo(servo);  // no spring while the normal load comes on: the CNS spring starts with the shear
  record.sample_every = std::max(1L, shear_steps(dt) / std::max(curve_points_, 1));
}

Reading ShearProtocol::read(const Simulation& sim) const {
  const BlockGroup& upper = box(sim, upper_box_name);
  const BlockGroup& lower = box(sim, lower_box_name);
  const double A = area(sim);
  const std::vector<double> u = upper.displacement();
  Reading r;
  r.shear_displacement = u[0];
  r.strain = u[0] / sim.specimen().width();
  r.stress_top = -upper.force()[0] / A;  // the joint holds the upper box back
  r.stress_bottom = lower.force()[0] / A;
  r.stress = 0.5 * (r.stress_top + r.stress_bottom);
  r.normal_stress = upper.force()[1] / A;  // the joint pushes the upper box up
  r.dilation = shearing(upper) ? u[1] - upper.settings().servo.origin : 0.0;
  return r;
}

// Once the normal load has come on: the box moves along the joint, and under CNS the spring starts from here.
void ShearProtocol::control(Simulation& sim, const Reading& reading, const TestRecord&) {
  BlockGroup& upper = box(sim, upper_box_name);
  if (shearing(upper)) return;
  if (std::abs(reading.normal_stress - sigma0()) > consolidation_tolerance * sigma0()) return;
  GroupServo servo = upper.settings().servo;
  servo.stiffness = scene_.loading.normal_stiffness * area(sim);
  servo.origin = upper.displacement()[1];
  upper.set_servo(servo);
  upper.set_value({scene_.loading.shear_velocity, upper.settings().value[1], 0.0});
}

long ShearProtocol::max_steps(const Simulation& sim, const TestRecord& record) const {
  return consolidation_steps_max + shear_steps(record.dt > 0 ? record.dt : sim.dt());
}

bool ShearProtocol::stop(const Simulation&, const Reading& reading, const TestRecord&, std::string& reason) const {
  if (reading.shear_displacement < scene_.loading.max_shear_displacement) return false;
  reason = "max_shear_displacement";
  return true;
}

// The residual: the mean shear stress of the samples in the last quarter of the shear displacement past the peak.
double residual_shear_stress(const std::vector<CurvePoint>& curve, double peak_displacement) {
  if (curve.empty()) return 0.0;
  const double end = curve.back().shear_displacement;
  const double from = std::max(peak_displacement, 0.75 * end);
  double sum = 0;
  int n = 0;
  for (const CurvePoint& p : curve)
    if (p.step > 0 && p.shear_displacement > from) sum += p.stress(), ++n;
  return n > 0 ? sum / n : curve.back().stress();
}

void ShearProtocol::results(const Simulation& sim, const TestRecord& record, TestResult& result) const {
  const Reading end = read(sim);
  const MohrCoulomb env = envelope();
  const double uniformity = joint_stiffness_uniformity(sim.specimen());
  const double residual = residual_shear_stress(record.curve, record.at_peak.shear_displacement);
  result.own = {{"normal_stress_pa", sigma0(), false},
                {"normal_stiffness_pa_per_m", scene_.loading.normal_stiffness, false},
                {"peak_shear_stress_pa", record.peak, true},
                {"shear_displacement_at_peak_m", record.at_peak.shear_displacement, true},
                {"normal_stress_at_peak_pa", record.at_peak.normal_stress, true},
                {"residual_shear_stress_pa", residual, true},
                {"dilation_m", end.dilation, true},
                {"dilation_at_peak_m", record.at_peak.dilation, true},
                {"final_normal_stress_pa", end.normal_stress, true},
                {"final_shear_displacement_m", end.shear_displacement, true},
                {"joint_envelope_peak_pa", env.cohesion + sigma0() * env.tan_phi, false},
                {"joint_stiffness_uniformity", uniformity, false},
                {"first_break_peak_pa", uniformity * env.cohesion + sigma0() * env.tan_phi, false},
                {"joint_residual_pa", sigma0() * scene_.joint.contact_friction, false}};
}

// The failure: the joint slid once at least half of its length broke (classify_failure's shear slip asks for a dip
// of 15 to 75 deg, where an axial load resolves shear on a joint; here the boxes shear it directly). No block moves
// on its own, so the kinetic energy is the upper box's rigid motion, not a dynamic response: the test is
// quasi-static when the two boxes' forces along the joint agree (within 5 %, as the compression tests' platens
// must).
void ShearProtocol::finish(const Simulation& sim, const TestRecord&, TestResult& result) const {
  const Specimen& sp = sim.specimen();
  double joint = 0, broken = 0;
  for (std::size_t e = 0; e < sp.num_bonds(); ++e)
    if (sp.bonds.kind[e] == BondKind::joint) joint += sp.bonds.size[e];
  for (const Crack& c : result.cracks)
    if (c.kind == BondKind::joint) broken += c.size;
  if (broken >= 0.5 * joint) result.failure_mode = "shear_slip_along_joints";
  result.quasi_static = result.platen_force_mismatch <= 0.05 && result.peak_stress > 0;
  result.quasi_static_reason =
      result.quasi_static ? std::string()
                          : fmt::format("the boxes' forces along the joint differ by {:.1f} % while loading (limit "
                                        "5 %): lower loading.shear_velocity",
                                        100.0 * result.platen_force_mismatch);
}

// How many of the joint_set's planes cross a rectangle of height H (the mesher's rows: offset + k spacing from the
// centre, strictly inside).
int planes_inside(const JointSetParams& js, double height) {
  int n = 0;
  const double half = 0.5 * height, tol = 1e-9 * height;
  const long k0 = long(std::ceil((-half - js.offset) / js.spacing));
  const long k1 = long(std::floor((half - js.offset) / js.spacing));
  for (long k = k0; k <= k1; ++k)
    if (std::abs(js.offset + double(k) * js.spacing) < half - tol) ++n;
  return n;
}

void check_shear_scene(const Scene& scene) {
  if (scene.specimen.shape == "disc")
    throw SceneError("rbdem shear splits a rectangle along one joint: specimen.shape = \"disc\" is for rbdem "
                     "brazilian; set specimen.shape = \"rectangle\"");
  refuse_confining_pressure("shear", scene);
  if (scene.loading.fast_factor != 1.0)
    throw SceneError(fmt::format("loading.fast_factor = {} speeds up platens, and rbdem shear has none: set it to 1",
                                 scene.loading.fast_factor));
  if (scene.loading.mismatch_stop > 0.0)
    throw SceneError(fmt::format("loading.mismatch_stop = {} slows a platen, and rbdem shear has none: set it to 0",
                                 scene.loading.mismatch_stop));
  // A softening joint bond (fracture energy) under the rigid boxes keeps its sticking linear part loading while it
  // softens, and the shear stress climbs far past any envelope (250 MPa measured at 5 J/m^2): refused until the law
  // handles it.
  if (scene.joint.fracture_energy > 0.0)
    throw SceneError(fmt::format("joint.fracture_energy = {} J/m^2: rbdem shear runs brittle joint bonds only (a "
                                 "softening joint's sticking linear part keeps carrying shear while the bond "
                                 "softens); set joint.fracture_energy = 0",
                                 scene.joint.fracture_energy));
  if (!scene.mesh.file.empty()) return;  // a user mesh: install() checks its joint
  const JointSetParams& js = scene.joint_set;
  if (!js.enabled)
    throw SceneError("rbdem shear needs one joint across the specimen: set joint_set.enabled = true");
  if (js.dip_deg != 0.0)
    throw SceneError(fmt::format("rbdem shear shears a horizontal joint and joint_set.dip_deg = {}: set "
                                 "joint_set.dip_deg = 0",
                                 js.dip_deg));
  if (scene.joint_set2.enabled)
    throw SceneError("rbdem shear shears one joint: set joint_set2.enabled = false");
  if (const int n = planes_inside(js, scene.specimen.height); n != 1)
    throw SceneError(fmt::format("rbdem shear needs exactly one joint plane inside the specimen and joint_set.spacing "
                                 "= {} m with joint_set.offset = {} m puts {} in its height of {} m: set "
                                 "joint_set.spacing above the height (and joint_set.offset inside +-height/2)",
                                 js.spacing, js.offset, n, scene.specimen.height));
}

}  // namespace

ProtocolInfo shear_protocol() {
  ProtocolInfo p;
  p.name = "shear";
  p.description = "one direct shear test of a joint: --normal-stress sets sigma_n, --normal-stiffness k for CNS";
  // A structured mesh: every joint bond equally stiff, so the joint breaks all at once, at its envelope.
  p.scene_defaults = {{"joint_set.dip_deg", "0"},
                      {"joint_set.offset", "0"},
                      {"joint_set.spacing", "10"},
                      {"mesh.structured", "true"}};
  p.options = {{"--normal-stress", "loading.normal_stress",
                "normal stress on the joint sigma_n [Pa] (loading.normal_stress), e.g. --normal-stress 5e6"},
               {"--normal-stiffness", "loading.normal_stiffness",
                "constant normal stiffness k [Pa/m] (loading.normal_stiffness; 0 = constant normal load)"}};
  p.check = check_shear_scene;
  p.make = [](const Scene& scene, int curve_points) { return std::make_unique<ShearProtocol>(scene, curve_points); };
  p.headline = [](const TestResult& r) {
    const double k = r.own_value("normal_stiffness_pa_per_m");
    return fmt::format("shear: peak {:.2f} MPa at {:.3g} m, residual {:.2f} MPa, sigma_n {:.2f} MPa ({}), dilation "
                       "{:.3g} m",
                       r.own_value("peak_shear_stress_pa") / 1e6, r.own_value("shear_displacement_at_peak_m"),
                       r.own_value("residual_shear_stress_pa") / 1e6, r.own_value("normal_stress_pa") / 1e6,
                       k > 0 ? fmt::format("CNS, k = {:.3g} Pa/m, final {:.2f} MPa", k,
                                           r.own_value("final_normal_stress_pa") / 1e6)
                             : std::string("CNL"),
                       r.own_value("dilation_m"));
  };
  return p;
}

}  // namespace rbdem
