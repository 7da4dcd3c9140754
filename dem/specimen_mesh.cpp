// The specimen geometry, its joint segments and the checks before meshing; gmsh itself runs in the module
// librbdem_gmsh.so (gmsh_mesher.cpp, gmsh_module.hpp). See specimen_mesh.hpp; user meshes are read in msh_import.cpp.
#include "dem/specimen_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "dem/gmsh_module.hpp"
#include "dem/scene_keys.hpp"

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

TriMesh mesh_specimen(const SpecimenGeometry& g, double h, const std::filesystem::path& msh_out) {
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
  if (!scene.mesh.file.empty()) return read_msh(scene.mesh.file);
  return mesh_specimen(SpecimenGeometry::from_scene(scene), scene.mesh.size, msh_out);
}


namespace scene_keys {

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
  k.add(choice("specimen.shape", {"rectangle", "disc"},
               "rectangle: width x height (uniaxial and confined compression); disc: diameter (the Brazilian test)",
               [](Scene& s) -> std::string& { return s.specimen.shape; }));
  k.add(positive("specimen.width", "m", 100.0, "specimen width (horizontal) of a rectangle",
                 [](Scene& s) -> double& { return s.specimen.width; }));
  k.add(positive("specimen.height", "m", 100.0, "specimen height (load axis, vertical) of a rectangle",
                 [](Scene& s) -> double& { return s.specimen.height; }));
  k.add(positive("specimen.diameter", "m", 100.0, "diameter of a disc (the Brazilian test; loaded along the vertical)",
                 [](Scene& s) -> double& { return s.specimen.diameter; }));
  k.add(real("specimen.contact_arc_deg", "deg", 0.0, 60.0,
             "a disc's top and bottom are flattened over this angle 2 alpha (the contact arc of loading jaws, "
             "ISRM: about 10 deg), so that the flat platens load an arc rather than a point; 0 = a full disc",
             [](Scene& s) -> double& { return s.specimen.contact_arc_deg; }));
  k.add(positive("specimen.thickness", "m", 100.0, "out-of-plane thickness t (bond area A = L t)",
                 [](Scene& s) -> double& { return s.specimen.thickness; }));
  k.add(choice("specimen.model", {"plane_strain", "plane_stress"},
               "2D interpretation of the continuum constants (FE model and Amadei's formula)",
               [](Scene& s) -> std::string& { return s.specimen.model; }));
  // [joint_set], [joint_set2]
  declare_joint_set(k, "joint_set", [](Scene& s) -> JointSetParams& { return s.joint_set; });
  declare_joint_set(k, "joint_set2", [](Scene& s) -> JointSetParams& { return s.joint_set2; });
  // [mesh]
  k.add(positive("mesh.size", "m", 1.0, "target triangle edge length h (one rigid block per triangle)",
                 [](Scene& s) -> double& { return s.mesh.size; }));
  k.add(integer("mesh.seed", "-", 0, 1000000,
                 "mesh realization: 0 = the reference mesh; another seed grades the nodes along every side and joint "
                 "(+-2.5 %, same segment count) so gmsh lays a different mesh of the same size and quality; the same "
                 "seed gives the same mesh (docs/studies.md, \"Realizations\")",
                 [](Scene& s) -> int& { return s.mesh.seed; }));
  k.add(integer("mesh.strength_seed", "-", 0, 1000000,
                 "realization of the bond strength factors of the materials with a weibull_modulus (the same seed "
                 "gives the same strengths on the same mesh); a study's realizations = N runs seeds 0 .. N-1 of "
                 "both this and mesh.seed",
                 [](Scene& s) -> int& { return s.mesh.strength_seed; }));
  k.add(text("mesh.file", "user mesh (.msh; physical surfaces = layers); empty = mesh the specimen",
             [](Scene& s) -> std::string& { return s.mesh.file; }));
}

}  // namespace scene_keys

}  // namespace rbdem
