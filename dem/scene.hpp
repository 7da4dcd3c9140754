// The scene: every input of a run, declared once with default, unit, allowed range and doc string.
//
// A scene is plain data (`Scene`) plus one registry (`scene_parameters()`) that names each key as
// "section.key" (the TOML layout of DESIGN.md), so parsing, `--set` overrides, validation, printing
// and JSON output all come from one table. SI units throughout (m, Pa, kg, s); angles in degrees.
// Anything a user can get wrong raises `SceneError` with the key, the value and the allowed range.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace rbdem {

struct SpecimenParams {
  int dimension = 2;                // 2: the plane slice (triangles) | 3: the solid (tetrahedra; dem/specimen_mesh3.hpp)
  // 2D: rectangle (compression tests) | disc (the Brazilian test); 3D: cylinder | prism. A 3D scene that does not
  // give the shape is a cylinder (Scene::given).
  std::string shape = "rectangle";
  double width = 0.05;              // m, horizontal extent (along x)
  double depth = 0.05;              // m, of a 3D prism along y
  double height = 0.10;             // m, vertical extent (load axis)
  double diameter = 0.05;           // m, of a disc specimen
  double contact_arc_deg = 10.0;    // deg, angle 2 alpha that each flattened end of a disc subtends at its centre
  double thickness = 1.0;           // m, out of plane (2D); the 3D disc's along its axis, 3D default 0.025
  std::string model = "plane_strain";  // continuum interpretation: plane_strain | plane_stress
};

struct JointSetParams {
  double dip_deg = 60.0;  // deg, dip of the joint planes from the horizontal (docs/theory.md, section 1)
  // deg, 3D: turns the strike about the vertical from the depth axis y (0: the x-z section is the 2D slice)
  double dip_direction_deg = 0.0;
  double spacing = 0.01;  // m, normal distance between joints
  double offset = 0.0;    // m, shift of the set along its normal, from the specimen centre
  bool enabled = true;    // false: intact rock, no joints
  double persistence = 1.0;  // -, joint length / (joint length + rock bridge length) along a joint; 1 = through-going
  double joint_length = 0.02;  // m, length of each joint piece of a non-persistent set (persistence < 1)
  double stagger = 0.5;   // -, shift of the joint pieces from one joint to the next, as a fraction of their period
  bool follows_set1 = false;  // second set only: dip_deg is measured from joint_set.dip_deg (turns with set 1)
};

struct MeshParams {
  double size = 0.001;    // m, target triangle (2D) or tetrahedron (3D) edge length; 3D default 0.003 (Scene::given)
  std::string file;       // optional user mesh (.msh, physical surfaces = layers); empty = generate
  int seed = 0;           // mesh realization; 0 = the unperturbed mesh (dem/specimen_mesh.hpp, mesh_specimen)
  int strength_seed = 0;  // realization of the bond strength factors of materials with a weibull_modulus
  bool structured = false;  // a structured grid of equal right triangles (rbdem shear; dem/specimen_mesh.hpp)
  std::string block_order = "mesh";  // the blocks' order: "mesh" (as meshed) or "hilbert" (mesh/block_order.hpp)
};

// Bond and contact parameters of one contact kind (rock inside a layer, joint across layers).
struct MaterialParams {
  double effective_modulus = 0;  // Pa, E*: k_n = E*/d for the linear part and the parallel bond
  double stiffness_ratio = 1.0;  // -, kappa = k_n/k_s
  double tensile_strength = 0;   // Pa, parallel bond tensile strength sigma_c
  double cohesion = 0;           // Pa, parallel bond cohesion c
  double friction_deg = 0;       // deg, parallel bond friction angle phi_b (shear strength)
  double contact_friction = 0;   // -, Coulomb coefficient mu of the linear part and later contacts
  double moment_factor = 1.0;    // -, beta_m, moment contribution to the bond's tensile stress
  double fracture_energy = 0;    // J/m^2, G_f of a softening bond (docs/model.md, "Softening bonds"); 0 = brittle
  bool slip_when_bonded = false; // linear part may slide while its parallel bond is intact (PFC's LPB)
  double weibull_modulus = 0;    // -, m of the bonds' Weibull strength factors (mean 1); 0 = every bond at the strength
  double stiffness_weibull_modulus = 0;  // -, m of the bonds' Weibull stiffness factors (mean 1); 0 = every bond at E*
  double dilation_deg = 0;       // deg, dilation angle i of its contacts: sliding opens them by |slip| tan(i)
};

struct RockParams : MaterialParams {
  double density = 2700.0;  // kg/m^3, block density
};

// A second rock material and a second joint material, and where they apply (dem/materials.hpp): `groups` is a comma
// separated list of layer names or numbers (rock2) or of interface names (joint2) of the mesh.
struct Rock2Params : RockParams {
  std::string groups;  // layers of this rock; empty = none
};
struct Joint2Params : MaterialParams {
  std::string groups;  // interfaces of this joint material besides the second generated set; empty = none
};

// Beds of rock and rock2 by position along the first joint set's normal, the same at every dip (dem/materials.hpp).
// Lists are comma separated (a TOML array of strings works too).
struct BedsParams {
  std::string pattern;    // the rock of consecutive beds, repeated ("rock, rock2"); empty = no beds
  std::string thickness;  // m, the thickness of each bed of the pattern; empty = joint_set.spacing each
  double origin = 0.0;    // m, where bed 0 starts along the normal, from the joint at joint_set.offset
};

struct LoadingParams {
  double platen_velocity = 0.01;  // m/s, closing speed of the top platen (bottom fixed); quasi-static: docs/model.md
  double platen_friction = 0.0;   // -, Coulomb coefficient between platens and blocks
  double stop_fraction = 0.7;     // -, stop when the stress falls below this fraction of the peak
  double max_strain = 0.01;       // -, stop at this axial strain whatever happens
  double post_peak_strain = 1.0;  // -, stop when the strain exceeds (1 + this) x the strain at the peak
  double confining_pressure = 0.0;  // Pa, lateral pressure of a confined (triaxial) test; 0 = uniaxial
  double fast_factor = 1.0;       // -, the top platen's speed while no bond breaks, x platen_velocity; 1 = constant
  double quiet_transits = 3.0;    // -, wave transits without a break before the platen speeds up
  int quiet_breaks = 0;           // -, breaks a quiet spell may hold (over quiet_transits transits); 0 = none
  // -, > 0: the fast platen changes its speed no faster than makes the specimen's inertial force (its mass times
  // the platen's acceleration) this fraction of the platen force; 0 = up in one wave transit, down in a quarter
  double ramp_force_fraction = 0.0;
  double mismatch_stop = 0.0;     // -, > 0: the top platen slows as it pushes harder than the bottom one sees
  // -, > 0: the platen speed follows the rock: the platen closes this fraction of the elastic start's strain per
  // wave transit of the specimen (PlatenTest, docs/model.md "Loading rate"); 0 = platen_velocity as given
  double transit_strain_fraction = 0.0;
  // rbdem shear (direct shear of one joint, dem/driver/protocols/shear.cpp)
  double normal_stress = 5e6;            // Pa, the normal stress on the joint at the start of the shear
  double normal_stiffness = 0.0;         // Pa/m, the normal stiffness of a CNS test; 0 = constant normal load
  double shear_velocity = 0.01;          // m/s, the upper box's speed along the joint
  double max_shear_displacement = 5e-6;  // m, the shear displacement at which the test ends
  // rbdem cyclic: loading-unloading cycles to cycles levels equally spaced up to cycle_max_stress (of sigma_1 -
  // sigma_3), each unloaded to cycle_unload_stress, then to failure or a stop.
  int cycles = 4;                     // -, the number of cycles
  double cycle_max_stress = 16e6;     // Pa, the highest level (of the deviator); level k = k / cycles x this
  double cycle_unload_stress = 1e6;   // Pa, the stress (of the deviator) each cycle unloads to
  bool cycle_to_failure = true;       // -, after the last cycle: load to failure (true) or stop
  // rbdem hold: the platen servo holds the stress sigma_1 = hold_stress for hold_steps explicit steps.
  double hold_stress = 10e6;          // Pa
  int hold_steps = 10000;             // -
};

struct NumericsParams {
  double damping = 0.7;         // -, Cundall local damping coefficient alpha
  double dt_safety = 0.6;       // -, fraction of the critical time step used
  double dt = 0.0;              // s, requested step; 0 = automatic (dt_safety x critical)
  double mass_scaling = 1.0;    // -, density multiplier (>= 1) for quasi-static runs; reported
  int threads = 0;              // -, OpenMP threads; 0 = all cores
  bool elastic_start = true;    // start failure runs from the static elastic state below first break
  double elastic_start_fraction = 0.99; // -, of the first-break load at which the explicit run takes over
  bool skip_bonded_pairs = true;         // no narrow phase for pairs joined by an intact bond (saving b)
  bool search_free_faces_only = true;    // contact search only among blocks with a free face (saving c)
  bool update_after_breaks = true;       // contact lists updated, not rebuilt, after bond breaks (saving d)
  int checkpoint_every_steps = 0;        // -, explicit steps between checkpoints of rbdem ucs (0 = off)
  double checkpoint_every_seconds = 600.0;  // s, wall time between checkpoints of rbdem ucs (0 = off)
};

struct OutputParams {
  double frame_strain_interval = 2.5e-5;  // -, block positions are saved every this much axial strain
};

struct ElasticGateParams {
  double tolerance = 0.05;  // -, largest relative DEM/Amadei modulus difference accepted
};

struct Scene {
  SpecimenParams specimen;
  JointSetParams joint_set;
  JointSetParams joint_set2;  // a second joint set, off by default (enabled = false)
  MeshParams mesh;
  RockParams rock;
  MaterialParams joint;
  Joint2Params joint2;  // the second set's joints, and any interface the scene names
  Rock2Params rock2;    // layers the scene names
  BedsParams beds;      // or: rock and rock2 in beds along the joint normal
  LoadingParams loading;
  NumericsParams numerics;
  ElasticGateParams elastic;
  OutputParams output;
  // The keys given explicitly (scene file, --set, set_parameter), in order. Three defaults follow the dimension:
  // when specimen.dimension is set, specimen.shape, mesh.size and specimen.thickness take that dimension's default
  // unless given (2D: "rectangle", 0.001 m and 1 m; 3D: "cylinder", mesh3_default_size and disc3_default_thickness),
  // whatever the order of the keys.
  std::vector<std::string> given;

  Scene();  // the paper's specimen with the calibrated defaults
};

// m, the tetrahedron edge length of a 3D scene that does not set mesh.size (about 40,000 tets in the cylinder).
inline constexpr double mesh3_default_size = 0.003;
// m, the thickness of a 3D Brazilian disc that does not set specimen.thickness: ISRM's (1978) suggested method asks
// for a thickness about the radius, 25 mm for the default 50 mm disc.
inline constexpr double disc3_default_thickness = 0.025;

// What a user can get wrong in a scene; the message names the key, the value and the fix.
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class ParamKind { real, integer, boolean, choice, text };

struct ParamInfo {
  std::string key;   // "section.name"
  ParamKind kind;
  std::string unit;  // "Pa", "m", "deg", "-", ...
  std::string doc;
  double min = 0, max = 0;        // allowed range for real and integer keys
  bool min_exclusive = false;     // (min, max] instead of [min, max]
  std::vector<std::string> choices;  // for choice keys
};

// The registry, in file order.
const std::vector<ParamInfo>& scene_parameters();

// Reads a TOML scene file over the defaults. Unknown keys, wrong types and out-of-range values throw.
Scene load_scene_file(const std::filesystem::path& path);
// Parses TOML text (for tests and embedded scenes); `origin` names the source in messages.
Scene parse_scene(std::string_view toml_text, std::string_view origin = "scene");
// Applies one "section.key=value" override (the --set option).
void apply_override(Scene& scene, std::string_view assignment);
// Sets one key from its textual value, with the same checks as the file reader.
void set_parameter(Scene& scene, std::string_view key, std::string_view value);
// Checks every value against its range and the cross-key rules; throws SceneError on the first problem.
void validate(const Scene& scene);
// Refuses values that pass every range but are almost surely a unit mistake: a stress key (unit Pa) written in MPa
// or GPa (a modulus below 1 MPa, a strength, pressure or stress below 1 kPa but above 0), a bond strength at or above
// its modulus. Separate from validate() so that the command line can skip it with --force.
void check_plausible(const Scene& scene);

// The second joint set's dip from the horizontal in [0, 180) when the first set dips `first_dip_deg`
// (joint_set2.follows_set1 resolved; a set at beta is the same as at beta + 180 deg).
double second_set_dip_deg(const Scene& scene, double first_dip_deg);

// The beds of [beds]: bed k of the pattern is rock2 (rock2[k]) or rock and `thickness[k]` m thick; the pattern
// repeats along the first joint set's normal with the period sum(thickness), bed 0 starting at
// joint_set.offset + beds.origin from the specimen centre. Empty when beds.pattern is empty. Throws SceneError
// naming the key for a name that is not rock or rock2, a thickness that is not a positive number, or a count of
// thicknesses that is not the pattern's.
struct BedSequence {
  std::vector<bool> rock2;
  std::vector<double> thickness;  // m
  double start = 0;               // m, along the normal from the specimen centre
  bool empty() const { return rock2.empty(); }
  double period() const;
  // The bed that holds position s (m, along the normal from the specimen centre), 0 .. size - 1.
  std::size_t bed_at(double s) const;
};
BedSequence bed_sequence(const Scene& scene);

// Whether any layer can be made of rock2 (rock2.groups or a bed of the pattern).
bool uses_rock2(const Scene& scene);

// The value of one key as text (for printing and tables).
std::string parameter_text(const Scene& scene, std::string_view key);
// The resolved scene as TOML (with units as comments) and as JSON.
std::string to_toml(const Scene& scene);
void to_json(nlohmann::json& j, const Scene& scene);
nlohmann::json scene_json(const Scene& scene);

// A reference table of every key (for --help and docs/scene.md).
std::string parameter_reference();

}  // namespace rbdem
