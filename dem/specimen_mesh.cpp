// The specimen geometry, its joint segments and the checks before meshing; gmsh itself runs in the module
// librbdem_gmsh.so (gmsh_mesher.cpp, gmsh_module.hpp). See specimen_mesh.hpp; user meshes are read in msh_import.cpp.
#include "dem/specimen_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "dem/gmsh_module.hpp"
#include "mesh/block_order.hpp"

namespace rbdem {

namespace {
constexpr double deg = std::numbers::pi / 180.0;
}  // namespace

SpecimenGeometry SpecimenGeometry::from_scene(const Scene& scene) {
  SpecimenGeometry g;
  g.disc = scene.specimen.shape == "disc";
  g.contact_arc_deg = g.disc ? scene.specimen.contact_arc_deg : 0.0;
  g.width = g.disc ? scene.specimen.diameter : scene.specimen.width;
  g.height = g.disc ? scene.specimen.diameter : scene.specimen.height;
  const JointSetParams& j = scene.joint_set;
  g.dip_deg = j.dip_deg, g.spacing = j.spacing, g.offset = j.offset, g.joints = j.enabled;
  g.persistence = j.persistence, g.joint_length = j.joint_length, g.stagger = j.stagger;
  const JointSetParams& j2 = scene.joint_set2;
  g.second_set = j2.enabled;
  g.set2 = {second_set_dip_deg(scene, j.dip_deg), j2.spacing, j2.offset, j2.persistence, j2.joint_length,
            j2.stagger};
  g.mesh_seed = scene.mesh.seed;
  g.structured = scene.mesh.structured;
  return g;
}

std::array<double, 2> JointSetGeometry::direction() const {
  if (dip_deg == 0.0) return {1.0, 0.0};
  if (dip_deg == 90.0) return {0.0, 1.0};
  return {std::cos(dip_deg * deg), std::sin(dip_deg * deg)};
}

std::array<double, 2> JointSetGeometry::normal() const {
  const auto d = direction();
  return {-d[1], d[0]};
}

JointSetGeometry SpecimenGeometry::set(int k) const {
  if (k == 1) return set2;
  return {dip_deg, spacing, offset, persistence, joint_length, stagger};
}

std::array<double, 2> SpecimenGeometry::direction() const { return set(0).direction(); }
std::array<double, 2> SpecimenGeometry::normal() const { return set(0).normal(); }

double JointSegment::length() const { return std::hypot(b[0] - a[0], b[1] - a[1]); }

namespace {
// The segments of one set (see joint_segments).
void set_segments(const SpecimenGeometry& g, int k, double min_piece, std::vector<std::string>* notes,
                  std::vector<JointSegment>& out) {
  const JointSetGeometry js = g.set(k);
  const std::string name = joint_set_group[std::size_t(k)];
  const std::array<double, 2> c{0.5 * g.width, 0.5 * g.height};
  const auto d = js.direction();
  const auto n = js.normal();
  // Extent of the specimen along the normal, measured from the centre.
  double rmin = 1e300, rmax = -1e300;
  for (double x : {0.0, g.width})
    for (double y : {0.0, g.height}) {
      const double r = n[0] * (x - c[0]) + n[1] * (y - c[1]);
      rmin = std::min(rmin, r);
      rmax = std::max(rmax, r);
    }
  const double radius = 0.5 * g.width;
  if (g.disc) rmin = -radius, rmax = radius;
  const double tol = 1e-9 * std::max(g.width, g.height);
  const long kmin = long(std::ceil((rmin - js.offset) / js.spacing - 1e-9));
  const long kmax = long(std::floor((rmax - js.offset) / js.spacing + 1e-9));
  for (long row = kmin; row <= kmax; ++row) {
    const double r = js.offset + double(row) * js.spacing;
    if (r - rmin <= tol || rmax - r <= tol) continue;  // on a side or through a corner only
    if (r - rmin < min_piece || rmax - r < min_piece) {
      if (notes)
        notes->push_back(fmt::format("joint at {:.4g} m from the centre left out: it would cut off a corner piece "
                                     "{:.3g} m thick (under {:.3g} m); shift {}.offset to keep it",
                                     r, std::min(r - rmin, rmax - r), min_piece, name));
      continue;
    }
    // Clip the infinite line p(t) = c + r n + t d to the rectangle (Liang-Barsky) or to the disc (the chord).
    const std::array<double, 2> p{c[0] + r * n[0], c[1] + r * n[1]};
    double t0 = -1e300, t1 = 1e300;
    if (g.disc) t1 = std::sqrt(radius * radius - r * r), t0 = -t1;
    for (int axis = 0; axis < 2 && !g.disc; ++axis) {
      const double lo = 0.0, hi = axis == 0 ? g.width : g.height;
      if (d[axis] == 0.0) continue;  // parallel to this pair of sides; inside since |r| < extent
      double ta = (lo - p[axis]) / d[axis], tb = (hi - p[axis]) / d[axis];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (t1 - t0 <= tol) continue;
    auto at = [&](double t) { return std::array<double, 2>{p[0] + t * d[0], p[1] + t * d[1]}; };
    if (js.persistence >= 1.0) {
      out.push_back({at(t0), at(t1), r, k, true, true});
      continue;
    }
    // Pieces [m P + shift, m P + shift + L_j] along the joint, the piece m = 0 of the joint through the centre
    // centred on the centre's foot, each next joint shifted by `stagger` periods.
    const double P = js.joint_length / js.persistence;
    const double shift = -0.5 * js.joint_length + js.stagger * P * double(row);
    const long mmin = long(std::floor((t0 - shift - js.joint_length) / P)), mmax = long(std::ceil((t1 - shift) / P));
    for (long m = mmin; m <= mmax; ++m) {
      const double a = std::max(t0, double(m) * P + shift), b = std::min(t1, double(m) * P + shift + js.joint_length);
      if (b - a <= tol) continue;
      if (b - a < std::max(min_piece, tol)) {
        if (notes)
          notes->push_back(fmt::format("a piece of a {} joint {:.3g} m long left out where the boundary cuts it "
                                       "(under {:.3g} m)",
                                       name, b - a, min_piece));
        continue;
      }
      out.push_back({at(a), at(b), r, k, a <= t0, b >= t1});
    }
  }
}
}  // namespace

std::vector<JointSegment> joint_segments(const SpecimenGeometry& g, double min_piece,
                                         std::vector<std::string>* notes) {
  std::vector<JointSegment> out;
  if (g.joints) set_segments(g, 0, min_piece, notes, out);
  if (g.second_set) set_segments(g, 1, min_piece, notes, out);
  return out;
}

namespace {
// A structured grid needs four-sided pieces: a rectangle cut by horizontal through-going joints only.
void check_structured(const SpecimenGeometry& g) {
  if (!g.structured) return;
  const auto refuse = [](const std::string& what, const std::string& fix) {
    throw SceneError(fmt::format("mesh.structured = true meshes a rectangle cut by horizontal through-going joints, "
                                 "and {}: {} (or set mesh.structured = false)",
                                 what, fix));
  };
  if (g.disc) refuse("the specimen is a disc", "set specimen.shape = \"rectangle\"");
  if (g.joints && g.dip_deg != 0.0) refuse(fmt::format("joint_set.dip_deg = {}", g.dip_deg), "set it to 0");
  if (g.joints && g.persistence < 1.0)
    refuse(fmt::format("joint_set.persistence = {}", g.persistence), "set it to 1");
  if (g.second_set) refuse("the scene has a second joint set", "set joint_set2.enabled = false");
  if (g.mesh_seed != 0)
    refuse(fmt::format("mesh.seed = {} asks for a graded realization", g.mesh_seed), "set mesh.seed = 0");
}
}  // namespace

TriMesh mesh_specimen(const SpecimenGeometry& g, double h, const std::filesystem::path& msh_out) {
  check_structured(g);
  if (g.joints && g.spacing < 2.0 * h)
    throw SceneError(fmt::format("joint_set.spacing = {:.4g} m holds fewer than two elements of mesh.size = {:.4g} m:"
                                 " use mesh.size <= {:.4g} m or a wider spacing",
                                 g.spacing, h, 0.5 * g.spacing));
  std::vector<std::string> notes;
  // Corner pieces thinner than a fifth of an element would become needle blocks with a tiny time step.
  const auto segments = joint_segments(g, 0.2 * h, &notes);

  gmsh_io::MeshJob job;
  job.geometry = g;
  job.segments = segments;
  job.direction = {g.set(0).direction(), g.set(1).direction()};
  job.normal = g.normal();
  job.h = h;
  job.msh_out = msh_out.string();
  TriMesh mesh = gmsh_io::mesh_with_gmsh(job);
  mesh.notes = std::move(notes);
  return mesh;
}

TriMesh make_mesh(const Scene& scene, const std::filesystem::path& msh_out) {
  if (scene.specimen.dimension != 2)
    throw SceneError(fmt::format("a triangle mesh was asked of a {}D scene (specimen.dimension = {}): the 3D "
                                 "specimen is tetrahedral (mesh_scene3, dem/specimen_mesh3.hpp)",
                                 scene.specimen.dimension, scene.specimen.dimension));
  TriMesh mesh = scene.mesh.file.empty() ? mesh_specimen(SpecimenGeometry::from_scene(scene), scene.mesh.size, msh_out)
                                          : read_msh(scene.mesh.file);
  apply_block_order(mesh, scene.mesh.block_order);
  return mesh;
}

}  // namespace rbdem
