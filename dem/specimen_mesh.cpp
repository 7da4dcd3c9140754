// Specimen meshing with gmsh (OpenCASCADE kernel). See specimen_mesh.hpp; user meshes are read in msh_import.cpp.
#include "dem/specimen_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <set>

#include <fmt/format.h>
#include <gmsh.h>

#include "dem/gmsh_session.hpp"
#include "dem/scene_keys.hpp"

namespace rbdem {

using gmsh_io::collect_triangles;
using gmsh_io::gmsh_error;
using gmsh_io::GmshSession;
using gmsh_io::tidy;

namespace {
constexpr double deg = std::numbers::pi / 180.0;

// Largest log-ratio of the last to the first segment of a graded curve: spacings within exp(+-0.05 / 2) of the
// mean, about +-2.5 %. Any grading moves the curve's nodes; 0.02 already gave meshes that share no interior node.
constexpr double grading_amplitude = 0.05;

// Grades the 1D mesh of every curve of the current model by a seeded progression (see mesh_specimen in
// specimen_mesh.hpp). The segment count of each curve is gmsh's own for the size options already set, read
// from a 1D mesh made first, so the grading moves nodes without adding or removing any.
void grade_curves(int seed) {
  gmsh::model::mesh::generate(1);
  gmsh::vectorpair curves;
  gmsh::model::getEntities(curves, 1);
  std::vector<std::pair<int, int>> nodes;  // curve tag, node count with both ends
  for (const auto& [dim, tag] : curves) {
    std::vector<std::size_t> tags;
    std::vector<double> coord, param;
    gmsh::model::mesh::getNodes(tags, coord, param, 1, tag, true, false);
    nodes.push_back({tag, int(tags.size())});
  }
  gmsh::model::mesh::clear();
  // mt19937_64 is the same sequence on every platform; the uniform variate is built by hand because
  // std::uniform_real_distribution is not.
  std::mt19937_64 random(static_cast<std::uint64_t>(seed));
  for (const auto& [tag, count] : nodes) {
    const double u = double(random() >> 11) * 0x1.0p-53;  // [0, 1)
    if (count < 3) continue;                                // one segment: nothing to move
    const double ratio = std::exp(grading_amplitude * (2.0 * u - 1.0) / double(count - 2));
    gmsh::model::mesh::setTransfiniteCurve(tag, count, "Progression", ratio);
  }
}
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

  GmshSession session;
  TriMesh mesh;
  try {
    gmsh::model::add("specimen");
    int rect = 0;
    if (g.disc && g.contact_arc_deg > 0.0) {
      // Flattened at the top and bottom over the contact arc 2 alpha: two arcs and two flat ends.
      const double R = 0.5 * g.width, a = 0.5 * g.contact_arc_deg * deg, pi = std::numbers::pi;
      auto at = [&](double q) { return gmsh::model::occ::addPoint(R + R * std::cos(q), R + R * std::sin(q), 0); };
      const int c = gmsh::model::occ::addPoint(R, R, 0);
      const int tr = at(0.5 * pi - a), tl = at(0.5 * pi + a), bl = at(1.5 * pi - a), br = at(1.5 * pi + a);
      const int right = gmsh::model::occ::addCircleArc(br, c, tr), top = gmsh::model::occ::addLine(tr, tl);
      const int left = gmsh::model::occ::addCircleArc(tl, c, bl), bottom = gmsh::model::occ::addLine(bl, br);
      rect = gmsh::model::occ::addPlaneSurface({gmsh::model::occ::addCurveLoop({right, top, left, bottom})});
      gmsh::model::occ::remove({{0, c}});
    } else if (g.disc) {
      // Two half circles, so that the top and bottom points are geometry vertices and hence mesh nodes.
      const double R = 0.5 * g.width;
      const int right = gmsh::model::occ::addCircle(R, R, 0, R, -1, -0.5 * std::numbers::pi, 0.5 * std::numbers::pi);
      const int left = gmsh::model::occ::addCircle(R, R, 0, R, -1, 0.5 * std::numbers::pi, 1.5 * std::numbers::pi);
      rect = gmsh::model::occ::addPlaneSurface({gmsh::model::occ::addCurveLoop({right, left})});
    } else {
      rect = gmsh::model::occ::addRectangle(0, 0, 0, g.width, g.height);
    }
    gmsh::vectorpair tools;
    const double reach = 0.05 * std::hypot(g.width, g.height);  // lines overshoot the sides; trimmed below
    for (const auto& s : segments) {
      const auto d = g.set(s.set).direction();
      const double ra = s.a_on_boundary ? reach : 0.0, rb = s.b_on_boundary ? reach : 0.0;
      const int p0 = gmsh::model::occ::addPoint(s.a[0] - ra * d[0], s.a[1] - ra * d[1], 0);
      const int p1 = gmsh::model::occ::addPoint(s.b[0] + rb * d[0], s.b[1] + rb * d[1], 0);
      tools.push_back({1, gmsh::model::occ::addLine(p0, p1)});
    }
    std::vector<gmsh::vectorpair> map;
    if (!tools.empty()) {
      gmsh::vectorpair out;
      gmsh::model::occ::fragment({{2, rect}}, tools, out, map);
    }
    gmsh::model::occ::synchronize();

    gmsh::vectorpair surfaces;
    gmsh::model::getEntities(surfaces, 2);
    // Remove the overshooting line pieces: curves outside the specimen (their middle is outside it).
    const double eps_in = 1e-7 * std::max(g.width, g.height);
    auto inside = [&](double x, double y) {
      if (g.disc) return std::hypot(x - 0.5 * g.width, y - 0.5 * g.height) <= 0.5 * g.width + eps_in;
      return x >= -eps_in && x <= g.width + eps_in && y >= -eps_in && y <= g.height + eps_in;
    };
    gmsh::vectorpair curves, dangling;
    gmsh::model::getEntities(curves, 1);
    std::set<int> kept;
    for (const auto& dt : curves) {
      std::vector<double> lo, hi, xyz;
      gmsh::model::getParametrizationBounds(1, dt.second, lo, hi);
      gmsh::model::getValue(1, dt.second, {0.5 * (lo.at(0) + hi.at(0))}, xyz);
      if (inside(xyz.at(0), xyz.at(1))) kept.insert(dt.second);
      else dangling.push_back(dt);
    }
    if (!dangling.empty()) {
      gmsh::model::occ::remove(dangling, true);
      gmsh::model::occ::synchronize();
    }
    // The joints of each set as a physical curve group (what collect_triangles reads as TriMesh::interfaces).
    for (int k = 0; k < 2; ++k) {
      std::set<int> group;
      for (std::size_t t = 0; t < segments.size(); ++t)
        if (segments[t].set == k && 1 + t < map.size())
          for (const auto& [dim, tag] : map[1 + t])
            if (dim == 1 && kept.count(tag)) group.insert(tag);
      if (group.empty()) continue;
      const int pg = gmsh::model::addPhysicalGroup(1, std::vector<int>(group.begin(), group.end()));
      gmsh::model::setPhysicalName(1, pg, joint_set_group[std::size_t(k)]);
    }

    // Layers ordered along the joint normal, so layer ids are reproducible.
    const auto n = g.normal();
    std::vector<std::pair<double, int>> order;
    for (const auto& [dim, tag] : surfaces) {
      double cx = 0, cy = 0, cz = 0;
      gmsh::model::occ::getCenterOfMass(2, tag, cx, cy, cz);
      order.push_back({n[0] * cx + n[1] * cy, tag});
    }
    std::sort(order.begin(), order.end());
    std::vector<std::vector<int>> layer_entities;
    std::vector<std::string> names;
    for (std::size_t l = 0; l < order.size(); ++l) {
      const std::string name = fmt::format("layer_{}", l);
      const int pg = gmsh::model::addPhysicalGroup(2, {order[l].second});
      gmsh::model::setPhysicalName(2, pg, name);
      layer_entities.push_back({order[l].second});
      names.push_back(name);
    }
    // Boundary sides as named physical curves (for the FE model and for inspection in gmsh).
    const double eps = 1e-7 * std::max(g.width, g.height);
    const std::array<std::array<double, 4>, 4> boxes{{{-eps, -eps, g.width + eps, eps},
                                                      {g.width - eps, -eps, g.width + eps, g.height + eps},
                                                      {-eps, g.height - eps, g.width + eps, g.height + eps},
                                                      {-eps, -eps, eps, g.height + eps}}};
    const std::array<const char*, 4> sides{"bottom", "right", "top", "left"};
    if (g.disc) {
      gmsh::vectorpair rim;
      gmsh::model::getBoundary(surfaces, rim, true, false, false);
      std::vector<int> tags;
      for (const auto& dt : rim) tags.push_back(std::abs(dt.second));
      gmsh::model::setPhysicalName(1, gmsh::model::addPhysicalGroup(1, tags), "rim");
    }
    for (int s = 0; s < 4 && !g.disc; ++s) {
      gmsh::vectorpair in_box;
      gmsh::model::getEntitiesInBoundingBox(boxes[s][0], boxes[s][1], -eps, boxes[s][2], boxes[s][3], eps, in_box, 1);
      std::vector<int> tags;
      for (const auto& dt : in_box) tags.push_back(dt.second);
      if (!tags.empty()) gmsh::model::setPhysicalName(1, gmsh::model::addPhysicalGroup(1, tags), sides[s]);
    }

    gmsh::option::setNumber("Mesh.MeshSizeMin", h);
    gmsh::option::setNumber("Mesh.MeshSizeMax", h);
    gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
    gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
    // Delaunay (5), not Frontal-Delaunay (6): the frontal mesher lays near-regular rows of triangles along the
    // joints, so the block lattice turns with the dip and its stiffness with it (up to 9 % at 30 deg, measured by
    // the elastic gate); Delaunay triangles are oriented at random and the lattice is isotropic to about 1 %.
    gmsh::option::setNumber("Mesh.Algorithm", 5);
    if (g.mesh_seed != 0) grade_curves(g.mesh_seed);
    gmsh::model::mesh::generate(2);

    mesh = collect_triangles(layer_entities, names, "specimen mesh");
    if (!msh_out.empty()) {
      gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
      gmsh::write(msh_out.string());
    }
  } catch (const SceneError&) {
    throw;
  } catch (...) {
    throw SceneError("gmsh failed to mesh the specimen: " + gmsh_error("unknown error") +
                     " (check specimen.*, joint_set.* and mesh.size)");
  }
  tidy(mesh, g.width, g.height, 1e-9 * std::max(g.width, g.height));
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
