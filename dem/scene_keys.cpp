// The scene's keys: every section's keys with their unit, allowed range, default (the Scene's member
// initialisers, dem/scene.hpp) and doc string, and the builders they are written with. dem/scene.cpp collects the
// sections in the order of dem/scene_keys.hpp; parsing, --set, validation, printing, JSON and
// `rbdem --help-scene` all come from them. The keys live here, beside each other, so that the scene is a leaf of
// the libraries (the meshing, the DEM core and the driver all read it); each section names the module that reads
// it.
#include "dem/scene_keys.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include <fmt/format.h>

namespace rbdem::scene_keys {

// --- the builders --------------------------------------------------------------------------------------------------

Entry real(std::string key, std::string unit, double lo, double hi, std::string doc,
           std::function<double&(Scene&)> get, bool lo_exclusive) {
  ParamInfo info{std::move(key), ParamKind::real, std::move(unit), std::move(doc), lo, hi, lo_exclusive, {}};
  return {std::move(info), [get](Scene& s) -> ValueRef { return &get(s); }};
}
Entry positive(std::string key, std::string unit, double hi, std::string doc, std::function<double&(Scene&)> get) {
  return real(std::move(key), std::move(unit), 0.0, hi, std::move(doc), std::move(get), true);
}
Entry integer(std::string key, std::string unit, int lo, int hi, std::string doc, std::function<int&(Scene&)> get) {
  ParamInfo info{std::move(key), ParamKind::integer, std::move(unit), std::move(doc), double(lo), double(hi), false, {}};
  return {std::move(info), [get](Scene& s) -> ValueRef { return &get(s); }};
}
Entry boolean(std::string key, std::string doc, std::function<bool&(Scene&)> get) {
  ParamInfo info{std::move(key), ParamKind::boolean, "-", std::move(doc), 0, 1, false, {}};
  return {std::move(info), [get](Scene& s) -> ValueRef { return &get(s); }};
}
Entry choice(std::string key, std::vector<std::string> choices, std::string doc,
             std::function<std::string&(Scene&)> get) {
  ParamInfo info{std::move(key), ParamKind::choice, "-", std::move(doc), 0, 0, false, std::move(choices)};
  return {std::move(info), [get](Scene& s) -> ValueRef { return &get(s); }};
}
Entry text(std::string key, std::string doc, std::function<std::string&(Scene&)> get) {
  ParamInfo info{std::move(key), ParamKind::text, "-", std::move(doc), 0, 0, false, {}};
  return {std::move(info), [get](Scene& s) -> ValueRef { return &get(s); }};
}

// --- [elastic]: read by the elastic gate (compare/gate/elastic_gate.hpp) -------------------------------------------

void declare_elastic(Keys& k) {
  k.add(positive("elastic.tolerance", "-", 1.0,
                 "elastic gate: largest relative difference accepted between the DEM's apparent modulus and the FE twin's "
                 "(the FE model with the joints as interfaces, on the same mesh) at any dip",
                 [](Scene& s) -> double& { return s.elastic.tolerance; }));
}

// --- [specimen] [joint_set] [joint_set2] [mesh]: read by the meshing (dem/specimen_mesh.cpp) -----------------------
namespace {
// The keys of one joint set; `section` is "joint_set" or "joint_set2".
void declare_joint_set(Keys& k, const std::string& section, std::function<JointSetParams&(Scene&)> set) {
  const bool second = section == "joint_set2";
  const std::string p = section + ".";
  k.add(real(p + "dip_deg", "deg", second ? -180.0 : 0.0, second ? 180.0 : 90.0,
             second ? "dip of the second set from the horizontal (or from joint_set.dip_deg when follows_set1 = "
                      "true); above 90 deg the set dips the other way"
                    : "joint dip from the horizontal; the load is vertical (0 = joints normal to the load)",
             [set](Scene& s) -> double& { return set(s).dip_deg; }));
  k.add(real(p + "dip_direction_deg", "deg", -360.0, 360.0,
             "3D only: the azimuth of the dip, turning the strike about the vertical from the depth axis y "
             "(0: strike along y, so the x-z section is the 2D slice; 90: strike along -x); taken modulo 360",
             [set](Scene& s) -> double& { return set(s).dip_direction_deg; }));
  k.add(positive(p + "spacing", "m", 100.0, "normal distance between neighbouring joints",
                 [set](Scene& s) -> double& { return set(s).spacing; }));
  k.add(real(p + "offset", "m", -100.0, 100.0,
             "shift of the joint set along its normal; 0 puts a joint through the specimen centre",
             [set](Scene& s) -> double& { return set(s).offset; }));
  k.add(boolean(p + "enabled",
                second ? "true adds a second joint set (its joints get the [joint2] material)"
                       : "false gives intact rock (no joints)",
                [set](Scene& s) -> bool& { return set(s).enabled; }));
  k.add(real(p + "persistence", "-", 0.0, 1.0,
             "joint length / (joint length + rock bridge length) along each joint; 1 = through-going joints; below 1 "
             "each joint is a row of pieces joint_length long separated by intact rock bridges",
             [set](Scene& s) -> double& { return set(s).persistence; }, true));
  k.add(positive(p + "joint_length", "m", 100.0, "length of each joint piece when persistence < 1",
                 [set](Scene& s) -> double& { return set(s).joint_length; }));
  k.add(real(p + "stagger", "-", 0.0, 1.0,
             "shift of the joint pieces from one joint to the next along the set, as a fraction of their period "
             "(joint + bridge length); 0.5 = en echelon",
             [set](Scene& s) -> double& { return set(s).stagger; }));
  if (second)
    k.add(boolean(p + "follows_set1",
                  "true: dip_deg is measured from joint_set.dip_deg, so the two sets keep their angle when a study "
                  "turns the first set",
                  [set](Scene& s) -> bool& { return set(s).follows_set1; }));
}
}  // namespace

// [specimen], [joint_set], [joint_set2], [mesh]: the specimen geometry and its mesh.
void declare_geometry(Keys& k) {
  // [specimen]
  k.add(integer("specimen.dimension", "-", 2, 3,
                "2: the plane slice through the dip (triangular blocks, the seed paper's model); 3: the solid "
                "specimen (tetrahedral blocks, face bonds; shape cylinder, prism or disc, mesh.size default 0.003 m)",
                [](Scene& s) -> int& { return s.specimen.dimension; }));
  k.add(choice("specimen.shape", {"rectangle", "disc", "cylinder", "prism"},
               "2D: rectangle, width x height (uniaxial and confined compression), or disc, diameter (the Brazilian "
               "test); 3D: cylinder, diameter x height (the default of a 3D scene), prism, width x depth x height, "
               "or disc, diameter x thickness (the Brazilian test, axis along y)",
               [](Scene& s) -> std::string& { return s.specimen.shape; }));
  k.add(positive("specimen.width", "m", 100.0, "specimen width (horizontal, along x) of a rectangle or a 3D prism",
                 [](Scene& s) -> double& { return s.specimen.width; }));
  k.add(positive("specimen.depth", "m", 100.0,
                 "depth (horizontal, along y, the strike of joints of dip direction 0) of a 3D prism",
                 [](Scene& s) -> double& { return s.specimen.depth; }));
  k.add(positive("specimen.height", "m", 100.0,
                 "specimen height (load axis, vertical) of a rectangle, a cylinder or a prism",
                 [](Scene& s) -> double& { return s.specimen.height; }));
  k.add(positive("specimen.diameter", "m", 100.0,
                 "diameter of a disc (the Brazilian test; loaded along the vertical) or of a 3D cylinder",
                 [](Scene& s) -> double& { return s.specimen.diameter; }));
  k.add(real("specimen.contact_arc_deg", "deg", 0.0, 60.0,
             "a disc's (2D or 3D) top and bottom are flattened over this angle 2 alpha (the contact arc of "
             "loading jaws, ISRM: about 10 deg), so that the flat platens load an arc rather than a point; 0 = a "
             "full disc",
             [](Scene& s) -> double& { return s.specimen.contact_arc_deg; }));
  k.add(positive("specimen.thickness", "m", 100.0,
                 "2D: out-of-plane thickness t (bond area A = L t); 3D: the disc's thickness along its axis y "
                 "(default 0.025 m in 3D, ISRM: about the radius)",
                 [](Scene& s) -> double& { return s.specimen.thickness; }));
  k.add(choice("specimen.model", {"plane_strain", "plane_stress"},
               "2D interpretation of the continuum constants (FE model and Amadei's formula)",
               [](Scene& s) -> std::string& { return s.specimen.model; }));
  // [joint_set], [joint_set2]
  declare_joint_set(k, "joint_set", [](Scene& s) -> JointSetParams& { return s.joint_set; });
  declare_joint_set(k, "joint_set2", [](Scene& s) -> JointSetParams& { return s.joint_set2; });
  // [mesh]
  k.add(positive("mesh.size", "m", 1.0,
                 "target element edge length h: of the triangles in 2D, of the tetrahedra in 3D (one rigid block per "
                 "element); a 3D scene that does not set it takes 0.003",
                 [](Scene& s) -> double& { return s.mesh.size; }));
  k.add(integer("mesh.seed", "-", 0, 1000000,
                 "mesh realization: 0 = the reference mesh; another seed grades the nodes along every side and joint "
                 "(+-2.5 %, same segment count) so gmsh lays a different mesh of the same size and quality; the same "
                 "seed gives the same mesh (docs/studies.md, \"Realizations\")",
                 [](Scene& s) -> int& { return s.mesh.seed; }));
  k.add(integer("mesh.strength_seed", "-", 0, 1000000,
                 "realization of the bond strength factors of the materials with a weibull_modulus, and of the "
                 "stiffness factors of those with a stiffness_weibull_modulus (the same seed gives the same bonds on "
                 "the same mesh); a study's realizations = N runs seeds 0 .. N-1 of "
                 "both this and mesh.seed",
                 [](Scene& s) -> int& { return s.mesh.strength_seed; }));
  k.add(boolean("mesh.structured",
                "true meshes a rectangle with horizontal through-going joints (or none) as a structured grid of equal "
                "right triangles, so that every joint bond has the same stiffness; rbdem shear sets it (docs/model.md)"
                "; not for a user mesh (mesh.file)",
                [](Scene& s) -> bool& { return s.mesh.structured; }));
  k.add(choice("mesh.block_order", {"mesh", "hilbert"},
               "the order of the blocks (and so of the bonds) in the engine's arrays: \"mesh\" as gmsh made or the "
               "file holds the elements; \"hilbert\" along a Hilbert curve through their centroids, so that "
               "neighbours lie near in memory and few bonds cross two threads' ranges (faster on many threads; a "
               "different summation order, so results differ from \"mesh\" in round-off and, after the first "
               "cracks, in detail; docs/performance.md)",
               [](Scene& s) -> std::string& { return s.mesh.block_order; }));
  k.add(text("mesh.file", "user mesh (.msh; physical surfaces = layers); empty = mesh the specimen",
             [](Scene& s) -> std::string& { return s.mesh.file; }));
}

// --- [rock] [joint] [joint2] [rock2] [beds]: read by the model (dem/model.cpp) --------------------------------------------
// The keys of one material; `section` is "rock", "joint", "joint2" or "rock2".
void add_material(Keys& k, const std::string& section, std::function<MaterialParams&(Scene&)> m) {
  const std::string p = section + ".";
  const std::string what = section == "rock"    ? "bonds inside a layer"
                           : section == "joint"  ? "bonds across layers (joints)"
                           : section == "joint2" ? "joints of the second set and of the interfaces joint2.groups names"
                                                 : "bonds inside the layers of rock2 (rock2.groups or beds.pattern)";
  k.add(positive(p + "effective_modulus", "Pa", 1e14,
                 "effective modulus E* of " + what + ": k_n = E*/d (linear part and parallel bond)",
                 [m](Scene& s) -> double& { return m(s).effective_modulus; }));
  k.add(positive(p + "stiffness_ratio", "-", 100.0, "normal to shear stiffness ratio kappa = k_n/k_s of " + what,
                 [m](Scene& s) -> double& { return m(s).stiffness_ratio; }));
  k.add(positive(p + "tensile_strength", "Pa", 1e12, "parallel bond tensile strength sigma_c of " + what,
                 [m](Scene& s) -> double& { return m(s).tensile_strength; }));
  k.add(positive(p + "cohesion", "Pa", 1e12, "parallel bond cohesion c of " + what,
                 [m](Scene& s) -> double& { return m(s).cohesion; }));
  k.add(real(p + "friction_deg", "deg", 0.0, 89.0,
             "parallel bond friction angle phi_b: shear strength c - sigma_n tan(phi_b) of " + what,
             [m](Scene& s) -> double& { return m(s).friction_deg; }));
  k.add(real(p + "contact_friction", "-", 0.0, 10.0,
             "Coulomb coefficient mu of the linear part and of contacts after breakage, " + what,
             [m](Scene& s) -> double& { return m(s).contact_friction; }));
  k.add(real(p + "moment_factor", "-", 0.0, 1.0,
             "moment contribution factor beta_m in the bond tensile stress of " + what,
             [m](Scene& s) -> double& { return m(s).moment_factor; }));
  k.add(real(p + "fracture_energy", "J/m^2", 0.0, 1e6,
             "fracture energy G_f of " + what + ": after its strength is reached a bond softens linearly and "
             "breaks when it has dissipated G_f per unit bond area, whatever the mesh (crack band); 0 = "
             "brittle, as in the seed paper (breaks at its strength)",
             [m](Scene& s) -> double& { return m(s).fracture_energy; }));
  k.add(real(p + "weibull_modulus", "-", 0.0, 100.0,
             "heterogeneity of " + what + ": each bond's tensile strength and cohesion are the stated values times a "
             "factor drawn from a Weibull distribution of this modulus m, scaled to mean 1 (coefficient of variation "
             "0.36 at m = 3, 0.12 at m = 10); the fracture energy stays the same; 0 = every bond at the stated "
             "strength (mesh.strength_seed picks the realization)",
             [m](Scene& s) -> double& { return m(s).weibull_modulus; }));
  // A rock's grain-scale stiffness scatter only: the FE model with the joints gives each joint edge its
  // material's compliance, so a scattered joint would not be compared like with like.
  if (section == "rock" || section == "rock2")
    k.add(real(p + "stiffness_weibull_modulus", "-", 0.0, 100.0,
               "stiffness heterogeneity of " + what + " (2D): each bond's effective modulus is E* times a factor "
               "drawn from a Weibull distribution of this modulus m, scaled to mean 1 (coefficient of variation 0.52 "
               "at m = 2, 0.36 at m = 3), independent of the strength factors; stiff and soft bonds side by side "
               "load their neighbours unevenly, so cracks start below the peak (crack initiation); 0 = every bond "
               "at E* (mesh.strength_seed picks the realization)",
               [m](Scene& s) -> double& { return m(s).stiffness_weibull_modulus; }));
  k.add(real(p + "dilation_deg", "deg", 0.0, 45.0,
             "dilation angle i of the contacts of " + what + " after breakage (Patton's asperities): while a contact "
             "slides, its normal opening grows by |slip| tan(i), so a sliding joint dilates; 0 = a flat interface",
             [m](Scene& s) -> double& { return m(s).dilation_deg; }));
  k.add(boolean(p + "slip_when_bonded",
                "true: the linear part slides at mu F_n even while the parallel bond is intact (PFC's linear "
                "parallel bond); false: a bonded interface sticks until its bond breaks, " + what,
                [m](Scene& s) -> bool& { return m(s).slip_when_bonded; }));
}

// [rock], [joint], [joint2], [rock2], [beds]: the bond and contact laws of each material, the block densities and
// where rock2 lies.
void declare_materials(Keys& k) {
  add_material(k, "rock", [](Scene& s) -> MaterialParams& { return s.rock; });
  k.add(positive("rock.density", "kg/m^3", 1e5, "block density",
                 [](Scene& s) -> double& { return s.rock.density; }));
  add_material(k, "joint", [](Scene& s) -> MaterialParams& { return s.joint; });
  add_material(k, "joint2", [](Scene& s) -> MaterialParams& { return s.joint2; });
  k.add(text("joint2.groups",
             "interfaces (physical curve names of the mesh, comma separated) whose joints get this material besides "
             "the second generated joint set; empty = the second set only",
             [](Scene& s) -> std::string& { return s.joint2.groups; }));
  add_material(k, "rock2", [](Scene& s) -> MaterialParams& { return s.rock2; });
  k.add(positive("rock2.density", "kg/m^3", 1e5, "block density of the layers of this rock",
                 [](Scene& s) -> double& { return s.rock2.density; }));
  k.add(text("rock2.groups",
             "layers (physical surface names or layer numbers, comma separated) made of this rock; empty = none. "
             "Layer numbers change with the dip: for beds that stay put across a sweep use beds.pattern",
             [](Scene& s) -> std::string& { return s.rock2.groups; }));
  // [beds]: rock2 by position along the joint normal (dem/materials.cpp), the same physical beds at every dip.
  k.add(text("beds.pattern",
             "the rock (rock or rock2) of consecutive beds along the normal of joint_set, repeated through the "
             "specimen, e.g. [\"rock\", \"rock2\"]: every layer between two joints takes the bed that holds its "
             "centroid, so the same physical beds result at every dip; empty = no beds (rock2.groups, if any)",
             [](Scene& s) -> std::string& { return s.beds.pattern; }));
  k.add(text("beds.thickness",
             "thickness in m of each bed of beds.pattern (a list as long as it); empty = joint_set.spacing each, "
             "one layer per bed",
             [](Scene& s) -> std::string& { return s.beds.thickness; }));
  k.add(real("beds.origin", "m", -10.0, 10.0,
             "where bed 0 of beds.pattern starts along the joint normal (-sin dip, cos dip), measured from the "
             "joint at joint_set.offset from the specimen centre: 0 puts bed 0 just above that joint",
             [](Scene& s) -> double& { return s.beds.origin; }));
}

// --- [loading]: read by the tests between platens (dem/driver/platen_test.cpp) and rbdem shear --------------------
namespace {
// The keys of rbdem cyclic (dem/driver/protocols/cyclic.cpp) and rbdem hold (dem/driver/protocols/hold.cpp).
void declare_cycles_and_hold(Keys& k) {
  k.add(integer("loading.cycles", "-", 1, 1000,
                "rbdem cyclic: loading-unloading cycles, to levels k / cycles x cycle_max_stress (k = 1 .. cycles)",
                [](Scene& s) -> int& { return s.loading.cycles; }));
  k.add(positive("loading.cycle_max_stress", "Pa", 1e10,
                 "rbdem cyclic: the highest cycle level, of the deviator sigma_1 - sigma_3 (sigma_1 when uniaxial)",
                 [](Scene& s) -> double& { return s.loading.cycle_max_stress; }));
  k.add(real("loading.cycle_unload_stress", "Pa", 0.0, 1e10,
             "rbdem cyclic: each cycle unloads to this deviator stress, below the first level",
             [](Scene& s) -> double& { return s.loading.cycle_unload_stress; }));
  k.add(boolean("loading.cycle_to_failure",
                "rbdem cyclic: after the last cycle load to failure (true) or stop when it closes (false)",
                [](Scene& s) -> bool& { return s.loading.cycle_to_failure; }));
  k.add(positive("loading.hold_stress", "Pa", 1e10,
                 "rbdem hold: the axial stress sigma_1 the platen servo holds (above loading.confining_pressure)",
                 [](Scene& s) -> double& { return s.loading.hold_stress; }));
  k.add(integer("loading.hold_steps", "-", 1, 100000000, "rbdem hold: explicit steps the stress is held for",
                [](Scene& s) -> int& { return s.loading.hold_steps; }));
}
}  // namespace
// [loading]: the platens and the stop criteria of the compression tests; the boxes and the load of the shear test.
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
  k.add(real("loading.confining_pressure", "Pa", 0.0, 1e10,
             "lateral (confining) pressure of rbdem triaxial, on the specimen's sides as a jacket would apply it; "
             "ucs and brazilian refuse a value above 0",
             [](Scene& s) -> double& { return s.loading.confining_pressure; }));
  k.add(real("loading.fast_factor", "-", 1.0, 10.0,
             "while no bond breaks, the top platen speeds up to this multiple of platen_velocity, back to it at the "
             "next break (docs/model.md, Platens); 1 = constant speed",
             [](Scene& s) -> double& { return s.loading.fast_factor; }));
  k.add(real("loading.transit_strain_fraction", "-", 0.0, 1.0,
             "> 0: the platen speed follows the rock: the platen closes this fraction of the static elastic start's "
             "strain per wave transit of the specimen, v = f eps_s sqrt(E_s / rho) (docs/model.md, Loading rate; "
             "0.0075 gives the paper scene's 0.01 m/s at 90 deg; with weibull_modulus > 0 the start at the bonds' "
             "mean strength, at most where 3 % of them would break); 0 = loading.platen_velocity as given",
             [](Scene& s) -> double& { return s.loading.transit_strain_fraction; }));
  k.add(positive("loading.quiet_transits", "-", 100.0,
                 "with fast_factor > 1: wave transits of the specimen without a break before the platen speeds up",
                 [](Scene& s) -> double& { return s.loading.quiet_transits; }));
  k.add(integer("loading.quiet_breaks", "-", 0, 1000000,
                "with fast_factor > 1: the platen counts as quiet while at most this many bonds broke in the last "
                "quiet_transits wave transits (docs/model.md, Platens); 0 = only while none broke",
                [](Scene& s) -> int& { return s.loading.quiet_breaks; }));
  k.add(real("loading.ramp_force_fraction", "-", 0.0, 1.0,
             "> 0: the top platen changes its speed (fast_factor's spells, mismatch_stop's slowing) no faster than "
             "makes the specimen's inertial force, rho H A dv/dt, this fraction of the platen force (docs/model.md, "
             "Platens); 0 = fast_factor's spells rise in one wave transit and fall in a quarter of one",
             [](Scene& s) -> double& { return s.loading.ramp_force_fraction; }));
  k.add(real("loading.mismatch_stop", "-", 0.0, 1.0,
             "> 0 (with ramp_force_fraction > 0): the top platen slows in proportion as its force exceeds the bottom "
             "one's, to a halt at this fraction of their mean (docs/model.md, Platens); 0 = off",
             [](Scene& s) -> double& { return s.loading.mismatch_stop; }));
  // rbdem shear (dem/driver/protocols/shear.cpp)
  k.add(real("loading.normal_stress", "Pa", 0.0, 1e10,
             "rbdem shear: the normal stress on the joint, brought on before the shear and kept constant (CNL), or "
             "the start of sigma_n = normal_stress + normal_stiffness x dilation (CNS)",
             [](Scene& s) -> double& { return s.loading.normal_stress; }));
  k.add(real("loading.normal_stiffness", "Pa/m", 0.0, 1e16,
             "rbdem shear: the stiffness k of the spring between the normal load and the upper box (constant normal "
             "stiffness test): the normal stress rises by k x the joint's dilation; 0 = constant normal load",
             [](Scene& s) -> double& { return s.loading.normal_stiffness; }));
  k.add(positive("loading.shear_velocity", "m/s", 100.0, "rbdem shear: the upper box's speed along the joint",
                 [](Scene& s) -> double& { return s.loading.shear_velocity; }));
  k.add(positive("loading.max_shear_displacement", "m", 1.0,
                 "rbdem shear: the test ends when the upper box has moved this far along the joint",
                 [](Scene& s) -> double& { return s.loading.max_shear_displacement; }));
  declare_cycles_and_hold(k);
}

// --- [numerics]: read by the engine (dem/engine.cpp) and the driver ------------------------------------------------
// [numerics]: time stepping, damping, threads, the contact-search savings, the elastic start, checkpoints.
void declare_numerics(Keys& k) {
  k.add(real("numerics.damping", "-", 0.0, 0.99, "Cundall local damping coefficient alpha",
             [](Scene& s) -> double& { return s.numerics.damping; }));
  k.add(positive("numerics.dt_safety", "-", 0.7,
                 "fraction of the critical time step used (above 0.7 the failure phase was found unstable: "
                 "docs/performance.md)",
                 [](Scene& s) -> double& { return s.numerics.dt_safety; }));
  k.add(real("numerics.dt", "s", 0.0, 1.0,
             "requested time step; 0 = automatic; a step above the critical one is refused",
             [](Scene& s) -> double& { return s.numerics.dt; }));
  k.add(real("numerics.mass_scaling", "-", 1.0, 1e8,
             "density multiplier for quasi-static runs (dt grows as its square root); reported",
             [](Scene& s) -> double& { return s.numerics.mass_scaling; }));
  k.add(integer("numerics.threads", "-", 0, 1024, "OpenMP threads for one run; 0 = all cores",
                [](Scene& s) -> int& { return s.numerics.threads; }));
  k.add(boolean("numerics.elastic_start",
                "start failure runs from the static elastic state just below the first bond failure",
                [](Scene& s) -> bool& { return s.numerics.elastic_start; }));
  k.add(real("numerics.elastic_start_fraction", "-", 0.0, 0.99,
             "fraction of the first-break load at which the explicit run takes over from the static state",
             [](Scene& s) -> double& { return s.numerics.elastic_start_fraction; }, true));
  k.add(boolean("numerics.skip_bonded_pairs",
                "no narrow phase for pairs joined by an intact bond (false: clip them too and discard the "
                "result, the same answer at a higher cost; docs/performance.md)",
                [](Scene& s) -> bool& { return s.numerics.skip_bonded_pairs; }));
  k.add(boolean("numerics.search_free_faces_only",
                "contact search only among blocks with a broken bond or a boundary edge (false: all blocks, "
                "which adds corner contacts inside intact rock; docs/performance.md)",
                [](Scene& s) -> bool& { return s.numerics.search_free_faces_only; }));
  k.add(boolean("numerics.update_after_breaks",
                "after bond breaks, add the broken pairs and the blocks that gained a free face to the contact "
                "lists instead of rebuilding them (false: rebuild, the same answer at a higher cost; "
                "docs/performance.md)",
                [](Scene& s) -> bool& { return s.numerics.update_after_breaks; }));
  k.add(integer("numerics.checkpoint_every_steps", "-", 0, 2000000000,
                "rbdem ucs, triaxial and brazilian write checkpoint.h5 every this many explicit steps (0 = off); "
                "--resume continues",
                [](Scene& s) -> int& { return s.numerics.checkpoint_every_steps; }));
  k.add(real("numerics.checkpoint_every_seconds", "s", 0.0, 1e7,
             "rbdem ucs, triaxial and brazilian write checkpoint.h5 every this much wall-clock time (0 = off)",
             [](Scene& s) -> double& { return s.numerics.checkpoint_every_seconds; }));
}

// --- [output]: read by the recorders (dem/driver/monitors.cpp) -----------------------------------------------------
// [output]: what the recorders keep.
void declare_output(Keys& k) {
  k.add(positive("output.frame_strain_interval", "-", 1.0,
                 "save block positions every this much axial strain (plus the peak and the last state)",
                 [](Scene& s) -> double& { return s.output.frame_strain_interval; }));
}

}  // namespace rbdem::scene_keys
