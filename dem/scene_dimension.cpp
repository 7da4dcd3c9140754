// The scene's rules that depend on specimen.dimension: which shapes each dimension builds, and the keys that have
// no meaning in the other one. A key of the other dimension left at its default is fine; set away from it, it is
// refused with the key, the value and the fix, never ignored (a scene must mean what it says).
#include <algorithm>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "dem/scene_keys.hpp"

namespace rbdem::scene_keys {

namespace {

std::string real_text(double v) { return fmt::format("{}", v); }

// A key that the dimension does not read, set away from its default.
[[noreturn]] void unused(const std::string& key, const std::string& value, int dimension, const std::string& fix) {
  throw SceneError(fmt::format("{} = {} has no meaning in a {}D scene (specimen.dimension = {}): {}", key, value,
                               dimension, dimension, fix));
}

void validate_2d(const Scene& s) {
  const SpecimenParams d{};
  if (s.specimen.shape == "cylinder" || s.specimen.shape == "prism")
    throw SceneError(fmt::format("specimen.shape = \"{}\" is a 3D shape and specimen.dimension = 2: set "
                                 "specimen.dimension = 3, or use specimen.shape = \"rectangle\" or \"disc\" in 2D",
                                 s.specimen.shape));
  if (s.specimen.depth != d.depth)
    unused("specimen.depth", real_text(s.specimen.depth), 2,
           "a 2D specimen's out-of-plane size is specimen.thickness; set specimen.dimension = 3 for a prism");
  for (const auto& [name, set] : {std::pair<const char*, const JointSetParams*>{"joint_set", &s.joint_set},
                                  std::pair<const char*, const JointSetParams*>{"joint_set2", &s.joint_set2}})
    if (set->dip_direction_deg != 0.0)
      unused(std::string(name) + ".dip_direction_deg", real_text(set->dip_direction_deg), 2,
             "the 2D specimen is the slice through the dip (dip direction 0); set specimen.dimension = 3 to turn "
             "the strike, or remove the key");
}

// The disc's own rules: its thickness holds one tetrahedron at least, and the quarter-of-the-extent rule applies to
// its diameter (the section that carries the Brazilian stress field; across the thickness it is nearly uniform).
void validate_3d_disc(const Scene& s) {
  if (s.mesh.file.empty() && s.mesh.size > s.specimen.thickness)
    throw SceneError(fmt::format("specimen.thickness = {} m is thinner than one tetrahedron of mesh.size = {} m: use "
                                 "mesh.size <= {} m or a thicker disc",
                                 real_text(s.specimen.thickness), real_text(s.mesh.size),
                                 real_text(s.specimen.thickness)));
  if (s.mesh.file.empty() && s.mesh.size > 0.25 * s.specimen.diameter)
    throw SceneError(fmt::format("mesh.size = {} m is too coarse for the 3D disc (diameter {} m): use at most a "
                                 "quarter of it ({} m)",
                                 real_text(s.mesh.size), real_text(s.specimen.diameter),
                                 real_text(0.25 * s.specimen.diameter)));
}

void validate_3d_specimen(const Scene& s) {
  const SpecimenParams d{};
  const std::string& shape = s.specimen.shape;
  if (shape != "cylinder" && shape != "prism" && shape != "disc")
    throw SceneError(fmt::format(
        "specimen.shape = \"{}\" is not built in 3D (specimen.dimension = 3): use \"cylinder\" (specimen.diameter x "
        "specimen.height, the default), \"prism\" (specimen.width x specimen.depth x specimen.height) or \"disc\" "
        "(specimen.diameter x specimen.thickness, the Brazilian test)",
        shape));
  if (s.specimen.model != d.model)
    unused("specimen.model", "\"" + s.specimen.model + "\"", 3,
           "plane strain or stress is the 2D slice's reading; the solid needs none: remove the key");
  if (shape == "disc") return validate_3d_disc(s);
  // Either default is fine (a scene built in code may set the dimension without Scene::given's defaults).
  if (s.specimen.thickness != disc3_default_thickness && s.specimen.thickness != d.thickness)
    unused("specimen.thickness", real_text(s.specimen.thickness), 3,
           "the solid's size is specimen.diameter (cylinder) or specimen.width and specimen.depth (prism); the "
           "thickness is the 3D disc's (specimen.shape = \"disc\")");
  if (s.specimen.contact_arc_deg != d.contact_arc_deg)
    unused("specimen.contact_arc_deg", real_text(s.specimen.contact_arc_deg), 3,
           "it flattens the Brazilian disc (specimen.shape = \"disc\"): remove the key");
  const bool prism = shape == "prism";
  const double least = prism ? std::min({s.specimen.width, s.specimen.depth, s.specimen.height})
                             : std::min(s.specimen.diameter, s.specimen.height);
  if (s.mesh.file.empty() && s.mesh.size > 0.25 * least)
    throw SceneError(fmt::format("mesh.size = {} m is too coarse for the 3D {} (smallest extent {} m): use at most a "
                                 "quarter of it ({} m)",
                                 real_text(s.mesh.size), shape, real_text(least), real_text(0.25 * least)));
}

// One tetrahedron across a layer at least (mesh_specimen3 checks the same; failing here reports it before any
// solve starts).
void validate_3d_layers(const Scene& s) {
  if (!s.mesh.file.empty()) return;
  for (const auto& [name, set] : {std::pair<const char*, const JointSetParams*>{"joint_set", &s.joint_set},
                                  std::pair<const char*, const JointSetParams*>{"joint_set2", &s.joint_set2}})
    if (set->enabled && set->spacing < s.mesh.size)
      throw SceneError(fmt::format("{}.spacing = {} m is thinner than one tetrahedron of mesh.size = {} m: use "
                                   "mesh.size <= {} m or a wider spacing",
                                   name, real_text(set->spacing), real_text(s.mesh.size), real_text(set->spacing)));
}

void validate_3d_others(const Scene& s) {
  const MeshParams m{};
  if (s.mesh.structured != m.structured)
    unused("mesh.structured", "true", 3,
           "the structured grid is of right triangles (rbdem shear sets it: the direct shear test is 2D only, "
           "its boxes are block groups); remove the key or run shear on a 2D scene");
  for (const auto& [name, set] : {std::pair<const char*, const JointSetParams*>{"joint_set", &s.joint_set},
                                  std::pair<const char*, const JointSetParams*>{"joint_set2", &s.joint_set2}})
    if (set->enabled && set->persistence < 1.0)
      unused(std::string(name) + ".persistence", real_text(set->persistence), 3,
             "3D joint planes are through-going: use persistence = 1");
  if (!s.beds.pattern.empty() || !s.beds.thickness.empty())
    unused(!s.beds.pattern.empty() ? "beds.pattern" : "beds.thickness",
           "\"" + (!s.beds.pattern.empty() ? s.beds.pattern : s.beds.thickness) + "\"", 3,
           "a 3D specimen is of one rock ([rock]) with joints of [joint] and [joint2]: remove [beds]");
  if (!s.rock2.groups.empty())
    unused("rock2.groups", "\"" + s.rock2.groups + "\"", 3,
           "a 3D specimen is of one rock ([rock]): remove rock2.groups");
  for (const auto& [name, mat] : {std::pair<const char*, const MaterialParams*>{"rock", &s.rock}, {"rock2", &s.rock2}})
    if (mat->stiffness_weibull_modulus != 0.0)
      unused(std::string(name) + ".stiffness_weibull_modulus", real_text(mat->stiffness_weibull_modulus), 3,
             "the 3D face bonds keep every bond at its material's E*: remove the key (weibull_modulus scatters the "
             "strengths in 3D as in 2D)");
  if (!s.joint2.groups.empty())
    unused("joint2.groups", "\"" + s.joint2.groups + "\"", 3,
           "names interfaces of a user mesh, which 3D does not read; the second joint set (joint_set2) takes [joint2]");
}

}  // namespace

void validate_dimension(const Scene& s) {
  if (s.specimen.dimension == 2) return validate_2d(s);
  if (s.specimen.dimension != 3)
    throw SceneError(fmt::format("specimen.dimension = {} is not a dimension rbdem builds: use 2 (the plane slice) or "
                                 "3 (the solid)",
                                 s.specimen.dimension));
  validate_3d_specimen(s);
  validate_3d_layers(s);
  validate_3d_others(s);
}

}  // namespace rbdem::scene_keys
