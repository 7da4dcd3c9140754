// The 3D specimen's joint planes and the front of its meshing (the gmsh calls are in gmsh_mesher3.cpp, in the gmsh
// module). See specimen_mesh3.hpp.
#include "dem/specimen_mesh3.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "dem/gmsh_module.hpp"
#include "mesh/block_order.hpp"
#include "theory/elasticity3.hpp"

namespace rbdem {

std::array<double, 3> JointPlaneSet::normal() const {
  return theory::plane_axes(dip_deg, dip_direction_deg).normal;
}

std::array<double, 3> SpecimenGeometry3::centre() const {
  if (shape == Shape3::disc) return {0.5 * diameter, 0.5 * thickness, 0.5 * diameter};
  if (shape == Shape3::cylinder) return {0.5 * diameter, 0.5 * diameter, 0.5 * height};
  return {0.5 * width, 0.5 * depth, 0.5 * height};
}

double SpecimenGeometry3::half_extent(const std::array<double, 3>& n) const {
  if (shape == Shape3::disc) {
    // In the x-z section: the round rim's R for directions farther than alpha from the vertical, else the corner of
    // the flat, (R sin alpha, R cos alpha).
    const double R = 0.5 * diameter, a = contact_arc_deg * std::numbers::pi / 360.0, s = std::hypot(n[0], n[2]);
    const double in_plane = std::abs(n[2]) >= s * std::cos(a)
                                ? R * (std::cos(a) * std::abs(n[2]) + std::sin(a) * std::abs(n[0]))
                                : R * s;
    return in_plane + 0.5 * thickness * std::abs(n[1]);
  }
  const double vertical = 0.5 * height * std::abs(n[2]);
  if (shape == Shape3::cylinder) return 0.5 * diameter * std::hypot(n[0], n[1]) + vertical;
  return 0.5 * width * std::abs(n[0]) + 0.5 * depth * std::abs(n[1]) + vertical;
}

double SpecimenGeometry3::volume() const {
  if (shape == Shape3::disc) {
    // The disc less its two circular segments of half-angle alpha, R^2 (2 alpha - sin 2 alpha) / 2 each.
    const double R = 0.5 * diameter, a = contact_arc_deg * std::numbers::pi / 360.0;
    return thickness * R * R * (std::numbers::pi - (2.0 * a - std::sin(2.0 * a)));
  }
  if (shape == Shape3::cylinder) return 0.25 * std::numbers::pi * diameter * diameter * height;
  return width * depth * height;
}

namespace {

void add_set(const SpecimenGeometry3& g, int k, double min_piece, std::vector<std::string>* notes,
             std::vector<JointPlane>& out) {
  const JointPlaneSet& js = k == 0 ? g.set1 : g.set2;
  const auto n = js.normal();
  const double extent = g.half_extent(n);
  const double tol = 1e-9 * std::max({g.diameter, g.width, g.depth, g.height});
  const long kmin = long(std::ceil((-extent - js.offset) / js.spacing - 1e-9));
  const long kmax = long(std::floor((extent - js.offset) / js.spacing + 1e-9));
  for (long row = kmin; row <= kmax; ++row) {
    const double r = js.offset + double(row) * js.spacing;
    const double cap = extent - std::abs(r);  // thickness of the piece it cuts off on its near side
    if (cap <= tol) continue;                 // touches the solid at an edge or a point only
    if (cap < min_piece) {
      if (notes)
        notes->push_back(fmt::format("joint plane {} at {:.4g} m from the centre left out: it would cut off a cap "
                                     "{:.3g} m thick (under {:.3g} m); shift the set's offset to keep it",
                                     k + 1, r, cap, min_piece));
      continue;
    }
    out.push_back({n, r, k});
  }
}

void check_geometry(const SpecimenGeometry3& g, double h) {
  auto positive = [](double v, const char* name) {
    if (!(std::isfinite(v) && v > 0))
      throw SceneError(fmt::format("{} = {} m: it must be a positive length", name, v));
  };
  positive(h, "mesh.size");
  if (g.shape == Shape3::disc) {
    positive(g.diameter, "specimen.diameter");
    positive(g.thickness, "specimen.thickness");
    if (!(g.contact_arc_deg >= 0 && g.contact_arc_deg <= 60))
      throw SceneError(fmt::format("specimen.contact_arc_deg = {}: it must lie in [0, 60] deg", g.contact_arc_deg));
  } else if (g.shape == Shape3::cylinder) {
    positive(g.height, "specimen.height");
    positive(g.diameter, "specimen.diameter");
  } else {
    positive(g.height, "specimen.height");
    positive(g.width, "specimen.width");
    positive(g.depth, "specimen.depth");
  }
  for (int k = 0; k < 2; ++k) {
    const bool on = k == 0 ? g.joints : g.second_set;
    const JointPlaneSet& js = k == 0 ? g.set1 : g.set2;
    const char* name = k == 0 ? "joint_set" : "joint_set2";
    if (!on) continue;
    if (!(std::isfinite(js.dip_deg) && js.dip_deg >= 0 && js.dip_deg <= 90))
      throw SceneError(fmt::format("{}.dip_deg = {}: it must lie in [0, 90] deg", name, js.dip_deg));
    if (!std::isfinite(js.dip_direction_deg) || !std::isfinite(js.offset))
      throw SceneError(fmt::format("{}.dip_direction_deg and {}.offset must be finite", name, name));
    // One tetrahedron across a layer at least (gmsh conforms to both planes of a thinner one only with slivers).
    if (!(js.spacing >= h))
      throw SceneError(fmt::format("{}.spacing = {:.4g} m is thinner than one element of mesh.size = {:.4g} m: "
                                   "use mesh.size <= {:.4g} m or a wider spacing",
                                   name, js.spacing, h, js.spacing));
  }
}

}  // namespace

std::vector<JointPlane> joint_planes(const SpecimenGeometry3& g, double min_piece, std::vector<std::string>* notes) {
  std::vector<JointPlane> out;
  if (g.joints) add_set(g, 0, min_piece, notes, out);
  if (g.second_set) add_set(g, 1, min_piece, notes, out);
  return out;
}

TetMesh mesh_specimen3(const SpecimenGeometry3& g, double h, int seed) {
  check_geometry(g, h);
  std::vector<std::string> notes;
  gmsh_io::MeshJob3 job;
  job.geometry = g;
  // Caps thinner than half an element would be a layer of flat tetrahedra (blocks with a tiny time step).
  job.planes = joint_planes(g, 0.5 * h, &notes);
  job.centre = g.centre();
  job.h = h;
  job.seed = seed;
  TetMesh mesh = gmsh_io::mesh3_with_gmsh(job);
  notes.insert(notes.end(), mesh.notes.begin(), mesh.notes.end());
  mesh.notes = std::move(notes);
  return mesh;
}

namespace {
double azimuth(double deg) {
  const double a = std::fmod(deg, 360.0);
  return a < 0 ? a + 360.0 : a;
}
}  // namespace

SpecimenGeometry3 specimen_geometry3(const Scene& scene) {
  if (scene.specimen.dimension != 3)
    throw SceneError(fmt::format("the scene is {}D (specimen.dimension = {}): set specimen.dimension = 3 for the "
                                 "solid specimen",
                                 scene.specimen.dimension, scene.specimen.dimension));
  SpecimenGeometry3 g;
  const std::string& shape = scene.specimen.shape;
  g.shape = shape == "prism" ? Shape3::prism : shape == "disc" ? Shape3::disc : Shape3::cylinder;
  g.diameter = scene.specimen.diameter;
  g.thickness = scene.specimen.thickness, g.contact_arc_deg = scene.specimen.contact_arc_deg;
  g.width = scene.specimen.width, g.depth = scene.specimen.depth, g.height = scene.specimen.height;
  const JointSetParams& s1 = scene.joint_set;
  g.joints = s1.enabled;
  g.set1 = {s1.dip_deg, azimuth(s1.dip_direction_deg), s1.spacing, s1.offset};
  const JointSetParams& s2 = scene.joint_set2;
  g.second_set = s2.enabled;
  double dip2 = second_set_dip_deg(scene, s1.dip_deg), dd2 = s2.dip_direction_deg;
  if (dip2 > 90.0) dip2 = 180.0 - dip2, dd2 += 180.0;  // the normal reversed: the same planes
  g.set2 = {dip2, azimuth(dd2), s2.spacing, s2.offset};
  return g;
}

TetMesh read_msh3(const std::filesystem::path& path) {
  if (!std::filesystem::is_regular_file(path))
    throw SceneError(fmt::format("mesh file '{}' does not exist: check --mesh / mesh.file", path.string()));
  TetMesh mesh = gmsh_io::read3_with_gmsh(path);
  std::size_t bottom = 0, top = 0;
  for (const auto& f : mesh.boundary) bottom += f.tag == FaceTag::bottom, top += f.tag == FaceTag::top;
  if (bottom == 0 || top == 0)
    throw SceneError(fmt::format("mesh file '{}' has no flat {} face: the platens load the faces at the mesh's lowest "
                                 "and highest z; give the specimen flat horizontal ends",
                                 path.string(), bottom == 0 ? "bottom" : "top"));
  return mesh;
}

TetMesh mesh_scene3(const Scene& scene) {
  TetMesh mesh = scene.mesh.file.empty() ? mesh_specimen3(specimen_geometry3(scene), scene.mesh.size, scene.mesh.seed)
                                         : read_msh3(scene.mesh.file);
  apply_block_order(mesh, scene.mesh.block_order);
  return mesh;
}

}  // namespace rbdem
