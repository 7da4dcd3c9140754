// The records a run produces, each declared once with its field table: Crack (one broken bond), CurvePoint (one
// sample of the loading curve) and Frame (the block poses at one instant). Every writer walks the table: the
// checkpoint (io/checkpoint.cpp), result.h5 (io/result_h5.cpp), the CSV files (io/results.cpp) and the Python
// records (python/bindings.cpp). A field added to a table appears in all of them; its name is the column name of
// the CSV files, the dataset name of result.h5 and the key of the Python record.
//
// The records are dimension-free: positions and normals have three components of which the first `dim` are used,
// a frame's poses are flat arrays of Dim<dim>::pose components per block (dem/dim.hpp).
//
// A table is a static function fields(dim, f) that calls f(Field, get) for each field in order, with `get` a
// callable that returns the field of a record: a reference for stored fields (read and written back), a value for
// derived ones (written only; readers skip them).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <type_traits>
#include <vector>

#include "dem/dim.hpp"
#include "dem/laws/parallel_bond.hpp"

namespace rbdem {

enum class BondKind : std::uint8_t { rock = 0, joint = 1 };

// The names of the enumerations as the files write them.
inline const char* name_of(BondKind k) { return k == BondKind::rock ? "rock" : "joint"; }
inline const char* name_of(BreakMode m) { return m == BreakMode::shear ? "shear" : (m == BreakMode::tensile ? "tensile" : "none"); }

// One field of a record: the name in every file, its unit and meaning (docs/outputs.md), and the significant
// digits the CSV files give it.
struct Field {
  const char* name;
  const char* unit;
  const char* doc;
  int digits = 9;
};

// Orientation of a 2D bond's edge (the crack's trace), in degrees counter-clockwise from the horizontal, in
// [0, 180): the direction perpendicular to the bond normal (nx, ny). A crack along a horizontal edge is 0, a vertical
// one 90.
inline double edge_orientation_deg(double nx, double ny) {
  // The edge runs along t = (-ny, nx); its angle folded into [0, 180).
  double a = std::atan2(nx, -ny) * 180.0 / std::numbers::pi;
  if (a < 0) a += 180.0;
  if (a >= 180.0) a -= 180.0;
  return a;
}

// The orientation of a plane in 3D as the joint sets have it (theory/elasticity3.hpp, plane_axes): the dip from
// the horizontal in [0, 90] and the dip direction in [0, 360), 0 when the plane's strike runs along y and its upward
// normal (-sin dip cos dd, -sin dip sin dd, cos dip) leans towards -x. A crack's or a band's normal has no sign, so
// the upward one is taken; a vertical plane (|n_z| below 1e-9 of |n|) has two dip directions 180 deg apart and gets
// the one in [0, 180); a horizontal plane's dip direction is 0.
struct PlaneOrientation {
  double dip_deg = 0, dip_direction_deg = 0;
};
inline constexpr double vertical_plane_tolerance = 1e-9;

// The normal n with the sign the joint sets' normals have (above): upward, or for a vertical plane the one whose
// dip direction lies in [0, 180).
inline std::array<double, 3> upward_normal(std::array<double, 3> n) {
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const bool vertical = std::abs(n[2]) <= vertical_plane_tolerance * len;
  const bool flip = vertical ? (n[1] > 0 || (n[1] == 0 && n[0] > 0)) : n[2] < 0;
  if (flip) n = {-n[0], -n[1], -n[2]};
  return n;
}

inline PlaneOrientation plane_orientation_deg(const std::array<double, 3>& normal) {
  const std::array<double, 3> n = upward_normal(normal);
  const double h = std::hypot(n[0], n[1]), to_deg = 180.0 / std::numbers::pi;
  PlaneOrientation o;
  if (!(h > 0)) return o;  // horizontal (or no normal)
  const bool vertical = std::abs(n[2]) <= vertical_plane_tolerance * std::hypot(h, n[2]);
  o.dip_deg = vertical ? 90.0 : std::atan2(h, n[2]) * to_deg;
  // A round-off component of the normal (a mesh face on a plane of dip direction 0 has |n_y| ~ 1e-16) must not
  // send 0 to 359.99999999999994 or 6e-14: the directions within 1e-9 deg of 0 (or the period) are 0.
  const double period = vertical ? 180.0 : 360.0;
  o.dip_direction_deg = std::fmod(std::atan2(-n[1], -n[0]) * to_deg + 360.0, period);
  if (o.dip_direction_deg < 1e-9 || o.dip_direction_deg >= period - 1e-9) o.dip_direction_deg = 0.0;
  return o;
}

// Whether a table accessor returns a stored field (a reference) rather than a derived value.
template <class Get, class Record>
inline constexpr bool stored_field = std::is_lvalue_reference_v<std::invoke_result_t<Get, Record&>>;

struct Crack {
  double time = 0, strain = 0;       // s, axial strain when the bond broke
  std::array<double, 3> position{};  // m, the bond point when it broke
  std::array<double, 3> normal{};    // -, the bond's reference normal (from block i to block j)
  double size = 0;                   // m (2D: the edge length) or m^2 (3D: the face area)
  int bond = -1;
  BondKind kind = BondKind::rock;
  BreakMode mode = BreakMode::tensile;
  double sigma = 0, tau = 0;         // Pa, the bond stresses that broke it

  template <class F>
  static void fields(int dim, F&& f) {
    f(Field{"time_s", "s", "time when the bond broke"}, [](auto& c) -> auto& { return c.time; });
    f(Field{"strain", "-", "axial strain when the bond broke"}, [](auto& c) -> auto& { return c.strain; });
    static constexpr const char* position_names[3] = {"x_m", "y_m", "z_m"};
    for (int k = 0; k < dim; ++k)
      f(Field{position_names[k], "m", "position of the bond point when it broke"},
        [k](auto& c) -> auto& { return c.position[std::size_t(k)]; });
    static constexpr const char* normal_names[3] = {"normal_x", "normal_y", "normal_z"};
    for (int k = 0; k < dim; ++k)
      f(Field{normal_names[k], "-", "the bond's reference normal, from its first block to its second"},
        [k](auto& c) -> auto& { return c.normal[std::size_t(k)]; });
    f(Field{dim == 2 ? "length_m" : "area_m2", dim == 2 ? "m" : "m^2", "size of the broken face"},
      [](auto& c) -> auto& { return c.size; });
    f(Field{"kind", "-", "rock or joint"}, [](auto& c) -> auto& { return c.kind; });
    f(Field{"mode", "-", "tensile or shear"}, [](auto& c) -> auto& { return c.mode; });
    f(Field{"bond", "-", "index of the broken bond"}, [](auto& c) -> auto& { return c.bond; });
    f(Field{"sigma_pa", "Pa", "peripheral tensile stress of the bond when it broke", 6},
      [](auto& c) -> auto& { return c.sigma; });
    f(Field{"tau_pa", "Pa", "shear stress of the bond when it broke", 6}, [](auto& c) -> auto& { return c.tau; });
    if (dim == 2)
      f(Field{"orientation_deg", "deg", "the broken edge's angle from the horizontal, counter-clockwise, [0, 180)", 6},
        [](const auto& c) { return edge_orientation_deg(c.normal[0], c.normal[1]); });
    if (dim == 3) {
      f(Field{"dip_deg", "deg", "the broken face's dip from the horizontal, [0, 90]", 6},
        [](const auto& c) { return plane_orientation_deg(c.normal).dip_deg; });
      f(Field{"dip_direction_deg", "deg", "the broken face's dip direction as the joint sets': 0 strikes along y, "
                                          "[0, 360) ([0, 180) when vertical)", 6},
        [](const auto& c) { return plane_orientation_deg(c.normal).dip_direction_deg; });
    }
  }
};

struct CurvePoint {
  long step = 0;                             // explicit step; -1 for the points of the static elastic start
  double time = 0, strain = 0;               // s, axial strain = platen displacement / height
  double stress_top = 0, stress_bottom = 0;  // Pa, compression positive, platen force / loaded area
  double kinetic = 0, strain_energy = 0;     // J
  double lateral_strain = 0;                 // -, width change / width (compression positive: < 0 when it widens)
  std::array<int, 4> broken{};               // rock tensile, rock shear, joint tensile, joint shear
  // The direct shear test's (rbdem shear): the upper box's displacement along the joint, the normal stress on the
  // joint and its dilation since the shear began (opening positive); 0 for the other tests.
  double shear_displacement = 0, normal_stress = 0, dilation = 0;  // m, Pa, m
  double stress() const { return 0.5 * (stress_top + stress_bottom); }
  // Compression positive. 2D: eps_v = eps_a + eps_l (plane strain); 3D: eps_v = eps_a + 2 eps_l, the lateral
  // strain being the cylinder's radial strain (the same in every horizontal direction).
  double volumetric_strain(int dim = 2) const { return strain + (dim - 1) * lateral_strain; }

  template <class F>
  static void fields(int dim, F&& f) {
    f(Field{"step", "-", "explicit step (-1: a point of the static start)"}, [](auto& p) -> auto& { return p.step; });
    f(Field{"time_s", "s", "time"}, [](auto& p) -> auto& { return p.time; });
    f(Field{"strain", "-", "axial strain, platen closure over height"}, [](auto& p) -> auto& { return p.strain; });
    f(Field{"stress_top_pa", "Pa", "top platen force over the loaded area"},
      [](auto& p) -> auto& { return p.stress_top; });
    f(Field{"stress_bottom_pa", "Pa", "bottom platen force over the loaded area"},
      [](auto& p) -> auto& { return p.stress_bottom; });
    f(Field{"kinetic_j", "J", "kinetic energy", 6}, [](auto& p) -> auto& { return p.kinetic; });
    f(Field{"strain_energy_j", "J", "elastic energy in bonds, contacts and boundaries", 6},
      [](auto& p) -> auto& { return p.strain_energy; });
    static constexpr const char* broken_names[4] = {"broken_rock_tensile", "broken_rock_shear",
                                                    "broken_joint_tensile", "broken_joint_shear"};
    for (std::size_t k = 0; k < 4; ++k)
      f(Field{broken_names[k], "-", "bonds broken so far, by kind and mode"},
        [k](auto& p) -> auto& { return p.broken[k]; });
    f(Field{"lateral_strain", "-",
            dim == 2 ? "width change over width, compression positive"
                     : "radial strain of the lateral surface (mean radial displacement over radius), compression "
                       "positive"},
      [](auto& p) -> auto& { return p.lateral_strain; });
    f(Field{"volumetric_strain", "-",
            dim == 2 ? "axial plus lateral strain (plane strain), compression positive"
                     : "axial plus twice the radial strain, compression positive"},
      [dim](const auto& p) { return p.volumetric_strain(dim); });
    f(Field{"shear_displacement_m", "m", "rbdem shear: the upper box's displacement along the joint (0 otherwise)"},
      [](auto& p) -> auto& { return p.shear_displacement; });
    f(Field{"normal_stress_pa", "Pa", "rbdem shear: the normal load on the upper box over the joint area, compression "
                                      "positive (0 otherwise)"},
      [](auto& p) -> auto& { return p.normal_stress; });
    f(Field{"dilation_m", "m", "rbdem shear: the upper box's displacement across the joint since the shear began, "
                               "opening positive (0 otherwise)"},
      [](auto& p) -> auto& { return p.dilation; });
  }
};

// One loading-unloading cycle of rbdem cyclic (dem/driver/protocols/cyclic.cpp, docs/cyclic.md): from the end of
// the previous cycle to the moment the reloading branch reaches this cycle's level again. The loop is the path from
// the reversal at the level down to the unload stress and back up to the level. Moduli are secants over 10 % to
// 90 % of each branch's stress range; the dissipated energy is the loop's area in the plane of the top platen's
// stress and the axial strain times the specimen's volume (the net work of the platen over the loop).
struct Cycle {
  int cycle = 0;                           // 1, 2, ...
  double level = 0, unload_stress = 0;     // Pa, of the deviator (sigma_1 - sigma_3; sigma_1 when uniaxial)
  double strain_at_level = 0;              // -, axial strain at the reversal
  double strain_at_unload = 0;             // -, axial strain at the unloaded end (the permanent strain part)
  double unloading_modulus = 0;            // Pa
  double reloading_modulus = 0;            // Pa
  double modulus_loss = 0;                 // -, 1 - unloading modulus / the intact specimen's static modulus
  double dissipated = 0;                   // J, the loop's area x volume
  double damped = 0;                       // J, local damping and contact friction over the loop (the engine's)
  int cracks = 0, cracks_total = 0;        // bonds broken in the cycle, and since the start
  long reversal_step = 0, closure_step = 0;  // explicit steps of the reversal and of the loop's closure

  template <class F>
  static void fields(int /*dim*/, F&& f) {
    f(Field{"cycle", "-", "cycle number, from 1"}, [](auto& c) -> auto& { return c.cycle; });
    f(Field{"level_pa", "Pa", "the cycle's level, deviator stress at the reversal"},
      [](auto& c) -> auto& { return c.level; });
    f(Field{"unload_stress_pa", "Pa", "deviator stress the cycle unloads to"},
      [](auto& c) -> auto& { return c.unload_stress; });
    f(Field{"strain_at_level", "-", "axial strain at the reversal"},
      [](auto& c) -> auto& { return c.strain_at_level; });
    f(Field{"strain_at_unload", "-", "axial strain at the unloaded end of the loop"},
      [](auto& c) -> auto& { return c.strain_at_unload; });
    f(Field{"unloading_modulus_pa", "Pa", "secant modulus of the unloading branch, 90 % to 10 % of its range"},
      [](auto& c) -> auto& { return c.unloading_modulus; });
    f(Field{"reloading_modulus_pa", "Pa", "secant modulus of the reloading branch, 10 % to 90 % of its range"},
      [](auto& c) -> auto& { return c.reloading_modulus; });
    f(Field{"modulus_loss", "-", "1 - unloading modulus / the intact static modulus"},
      [](auto& c) -> auto& { return c.modulus_loss; });
    f(Field{"dissipated_j", "J", "hysteresis loop area (top platen stress) x volume: the platen's net work", 6},
      [](auto& c) -> auto& { return c.dissipated; });
    f(Field{"damped_j", "J", "local damping and contact friction over the loop (the engine's accounts)", 6},
      [](auto& c) -> auto& { return c.damped; });
    f(Field{"cracks", "-", "bonds broken in the cycle"}, [](auto& c) -> auto& { return c.cracks; });
    f(Field{"cracks_total", "-", "bonds broken since the start, at the loop's closure"},
      [](auto& c) -> auto& { return c.cracks_total; });
    f(Field{"reversal_step", "-", "explicit step of the reversal at the level"},
      [](auto& c) -> auto& { return c.reversal_step; });
    f(Field{"closure_step", "-", "explicit step at which the reloading branch reached the level again"},
      [](auto& c) -> auto& { return c.closure_step; });
  }
};

// The force network at one instant: one link per intact bond (in bond order), then one per contact, between the
// centroids of its two blocks (force chains in ParaView, the fabric of the forces). Single precision: it is for
// display and statistics; the exact state is the pose.
struct ForceNetwork {
  std::vector<std::int32_t> i, j;   // the two blocks; the force acts on j, its opposite on i
  std::vector<std::uint8_t> kind;   // 0 bond, 1 contact
  std::vector<float> force;         // N, dim per link: the force on block j
  std::vector<float> normal_force;  // N, along the normal from i to j, tension positive (contacts: <= 0)
  std::size_t size() const { return i.size(); }
};

// The block poses at one instant (crack maps on the deformed specimen, ParaView animations) and the force network.
struct Frame {
  long step = 0;
  double time = 0, strain = 0, stress = 0;
  std::string label;        // "", "elastic_start", "peak" or "final"
  std::size_t cracks = 0;   // cracks logged by then (a prefix of the crack log)
  int dim = 2;
  std::vector<double> pose;  // component-major: component c of block b at pose[c * blocks + b] (Dim<dim>::pose)
  ForceNetwork network;      // the bonds' and contacts' forces
  std::size_t blocks() const { return pose.empty() ? 0 : pose.size() / std::size_t(pose_size(dim)); }
  // Component c of every block (c < pose_size(dim)).
  const double* component(int c) const { return pose.data() + std::size_t(c) * blocks(); }

  // The scalars; the pose is written per component, under the names pose_names(dim).
  template <class F>
  static void fields(int /*dim*/, F&& f) {
    f(Field{"step", "-", "explicit step"}, [](auto& r) -> auto& { return r.step; });
    f(Field{"time_s", "s", "time"}, [](auto& r) -> auto& { return r.time; });
    f(Field{"strain", "-", "axial strain"}, [](auto& r) -> auto& { return r.strain; });
    f(Field{"stress_pa", "Pa", "the curve's stress"}, [](auto& r) -> auto& { return r.stress; });
    f(Field{"label", "-", "\"\", elastic_start, peak or final"}, [](auto& r) -> auto& { return r.label; });
    f(Field{"cracks", "-", "cracks logged by then"}, [](auto& r) -> auto& { return r.cracks; });
  }
};

}  // namespace rbdem
