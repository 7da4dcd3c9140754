// Specimen meshing with gmsh (OpenCASCADE kernel) and .msh import. See specimen_mesh.hpp.
#include "dem/specimen_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <numbers>
#include <set>

#include <fmt/format.h>
#include <gmsh.h>

namespace rbdem {

namespace {

constexpr double deg = std::numbers::pi / 180.0;

// gmsh keeps global state: one session at a time, always finalized, never left open on an exception.
std::mutex gmsh_mutex;

class GmshSession {
 public:
  GmshSession() : lock_(gmsh_mutex) {
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.Verbosity", 1);
  }
  ~GmshSession() { gmsh::finalize(); }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

 private:
  std::lock_guard<std::mutex> lock_;
};

std::string gmsh_error(const std::string& fallback) {
  std::string err;
  try {
    gmsh::logger::getLastError(err);
  } catch (...) {
  }
  return err.empty() ? fallback : err;
}

// Orients every triangle counter-clockwise and snaps nodes lying within `tol` of the rectangle's sides
// onto them exactly (OpenCASCADE returns 0.09999999999999999 for 0.1).
void tidy(TriMesh& mesh, double width, double height, double tol) {
  for (auto& p : mesh.nodes) {
    if (std::abs(p[0]) < tol) p[0] = 0.0;
    if (std::abs(p[0] - width) < tol) p[0] = width;
    if (std::abs(p[1]) < tol) p[1] = 0.0;
    if (std::abs(p[1] - height) < tol) p[1] = height;
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    if (signed_area(mesh, t) < 0) std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
}

// Collects the first-order triangles of the current gmsh model, one layer per entry of `layer_entities`.
TriMesh collect_triangles(const std::vector<std::vector<int>>& layer_entities, std::vector<std::string> names,
                          const std::string& source) {
  TriMesh mesh;
  std::vector<std::size_t> tags;
  std::vector<double> coord, param;
  gmsh::model::mesh::getNodes(tags, coord, param, -1, -1, false, false);
  std::map<std::size_t, int> index;
  mesh.nodes.reserve(tags.size());
  for (std::size_t k = 0; k < tags.size(); ++k) {
    index[tags[k]] = int(mesh.nodes.size());
    mesh.nodes.push_back({coord[3 * k], coord[3 * k + 1]});
    if (std::abs(coord[3 * k + 2]) > 1e-12)
      throw SceneError(fmt::format("{}: node {} has z = {}: rbdem needs a planar mesh in the x-y plane", source,
                                   tags[k], coord[3 * k + 2]));
  }
  for (std::size_t l = 0; l < layer_entities.size(); ++l) {
    for (int entity : layer_entities[l]) {
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> etags, enodes;
      gmsh::model::mesh::getElements(types, etags, enodes, 2, entity);
      for (std::size_t k = 0; k < types.size(); ++k) {
        if (types[k] != 2) {
          std::string name;
          int d = 0, order = 0, nn = 0, np = 0;
          std::vector<double> lc;
          gmsh::model::mesh::getElementProperties(types[k], name, d, order, nn, lc, np);
          throw SceneError(fmt::format(
              "{}: surface {} holds {} {} elements: rbdem needs first-order triangles only "
              "(in gmsh: Mesh.RecombineAll = 0, Mesh.ElementOrder = 1)",
              source, entity, etags[k].size(), name));
        }
        for (std::size_t e = 0; e < etags[k].size(); ++e) {
          std::array<int, 3> tri{};
          for (int v = 0; v < 3; ++v) tri[v] = index.at(enodes[k][3 * e + v]);
          mesh.triangles.push_back(tri);
          mesh.layer.push_back(int(l));
        }
      }
    }
  }
  mesh.layer_names = std::move(names);
  // Drop nodes that no triangle uses (boundary-only or unused nodes of the file).
  std::vector<int> used(mesh.nodes.size(), -1);
  std::vector<std::array<double, 2>> kept;
  for (auto& tri : mesh.triangles)
    for (int& v : tri) {
      if (used[v] < 0) {
        used[v] = int(kept.size());
        kept.push_back(mesh.nodes[v]);
      }
      v = used[v];
    }
  mesh.nodes = std::move(kept);
  return mesh;
}

}  // namespace

double signed_area(const TriMesh& mesh, std::size_t t) {
  const auto& tri = mesh.triangles[t];
  const auto& a = mesh.nodes[tri[0]];
  const auto& b = mesh.nodes[tri[1]];
  const auto& c = mesh.nodes[tri[2]];
  return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
}

SpecimenGeometry SpecimenGeometry::from_scene(const Scene& scene) {
  SpecimenGeometry g;
  g.width = scene.specimen.width;
  g.height = scene.specimen.height;
  g.dip_deg = scene.joint_set.dip_deg;
  g.spacing = scene.joint_set.spacing;
  g.offset = scene.joint_set.offset;
  g.joints = scene.joint_set.enabled;
  return g;
}

std::array<double, 2> SpecimenGeometry::direction() const {
  if (dip_deg == 0.0) return {1.0, 0.0};
  if (dip_deg == 90.0) return {0.0, 1.0};
  return {std::cos(dip_deg * deg), std::sin(dip_deg * deg)};
}

std::array<double, 2> SpecimenGeometry::normal() const {
  const auto d = direction();
  return {-d[1], d[0]};
}

double JointSegment::length() const { return std::hypot(b[0] - a[0], b[1] - a[1]); }

std::vector<JointSegment> joint_segments(const SpecimenGeometry& g, double min_piece,
                                         std::vector<std::string>* notes) {
  std::vector<JointSegment> out;
  if (!g.joints) return out;
  const std::array<double, 2> c{0.5 * g.width, 0.5 * g.height};
  const auto d = g.direction();
  const auto n = g.normal();
  // Extent of the rectangle along the normal, measured from the centre.
  double rmin = 1e300, rmax = -1e300;
  for (double x : {0.0, g.width})
    for (double y : {0.0, g.height}) {
      const double r = n[0] * (x - c[0]) + n[1] * (y - c[1]);
      rmin = std::min(rmin, r);
      rmax = std::max(rmax, r);
    }
  const double tol = 1e-9 * std::max(g.width, g.height);
  const long kmin = long(std::ceil((rmin - g.offset) / g.spacing - 1e-9));
  const long kmax = long(std::floor((rmax - g.offset) / g.spacing + 1e-9));
  for (long k = kmin; k <= kmax; ++k) {
    const double r = g.offset + double(k) * g.spacing;
    if (r - rmin <= tol || rmax - r <= tol) continue;  // on a side or through a corner only
    if (r - rmin < min_piece || rmax - r < min_piece) {
      if (notes)
        notes->push_back(fmt::format("joint at {:.4g} m from the centre left out: it would cut off a corner piece "
                                     "{:.3g} m thick (under {:.3g} m); shift joint_set.offset to keep it",
                                     r, std::min(r - rmin, rmax - r), min_piece));
      continue;
    }
    // Clip the infinite line p(t) = c + r n + t d to the rectangle (Liang-Barsky).
    const std::array<double, 2> p{c[0] + r * n[0], c[1] + r * n[1]};
    double t0 = -1e300, t1 = 1e300;
    for (int axis = 0; axis < 2; ++axis) {
      const double lo = 0.0, hi = axis == 0 ? g.width : g.height;
      if (d[axis] == 0.0) continue;  // parallel to this pair of sides; inside since |r| < extent
      double ta = (lo - p[axis]) / d[axis], tb = (hi - p[axis]) / d[axis];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (t1 - t0 <= tol) continue;
    JointSegment s{{p[0] + t0 * d[0], p[1] + t0 * d[1]}, {p[0] + t1 * d[0], p[1] + t1 * d[1]}, r};
    out.push_back(s);
  }
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
    const int rect = gmsh::model::occ::addRectangle(0, 0, 0, g.width, g.height);
    gmsh::vectorpair tools;
    const auto d = g.direction();
    const double reach = 0.05 * std::hypot(g.width, g.height);  // lines overshoot the sides; trimmed below
    for (const auto& s : segments) {
      const int p0 = gmsh::model::occ::addPoint(s.a[0] - reach * d[0], s.a[1] - reach * d[1], 0);
      const int p1 = gmsh::model::occ::addPoint(s.b[0] + reach * d[0], s.b[1] + reach * d[1], 0);
      tools.push_back({1, gmsh::model::occ::addLine(p0, p1)});
    }
    if (!tools.empty()) {
      gmsh::vectorpair out;
      std::vector<gmsh::vectorpair> map;
      gmsh::model::occ::fragment({{2, rect}}, tools, out, map);
    }
    gmsh::model::occ::synchronize();

    gmsh::vectorpair surfaces;
    gmsh::model::getEntities(surfaces, 2);
    // Remove the overshooting line pieces: curves that bound no surface.
    gmsh::vectorpair boundary;
    gmsh::model::getBoundary(surfaces, boundary, false, false, false);
    std::set<int> bounding;
    for (const auto& [dim, tag] : boundary) bounding.insert(std::abs(tag));
    gmsh::vectorpair curves, dangling;
    gmsh::model::getEntities(curves, 1);
    for (const auto& dt : curves)
      if (!bounding.count(dt.second)) dangling.push_back(dt);
    if (!dangling.empty()) {
      gmsh::model::occ::remove(dangling, true);
      gmsh::model::occ::synchronize();
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
    for (int s = 0; s < 4; ++s) {
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

TriMesh read_msh(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path))
    throw SceneError(fmt::format("mesh file '{}' does not exist: check --mesh / mesh.file", path.string()));
  GmshSession session;
  TriMesh mesh;
  try {
    gmsh::open(path.string());
  } catch (...) {
    throw SceneError(fmt::format("cannot read mesh file '{}': {} (expected a gmsh .msh file)", path.string(),
                                 gmsh_error("not a readable mesh")));
  }
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups, 2);
  if (groups.empty())
    throw SceneError(fmt::format("mesh file '{}' has no physical surface groups: define one physical surface per "
                                 "rock layer (Physical Surface(\"layer_0\") = {{...}}) and save again",
                                 path.string()));
  std::vector<std::vector<int>> layer_entities;
  std::vector<std::string> names;
  std::set<int> seen;
  for (const auto& [dim, tag] : groups) {
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    for (int e : entities)
      if (!seen.insert(e).second)
        throw SceneError(fmt::format("mesh file '{}': surface {} belongs to two physical groups; each triangle must "
                                     "be in exactly one layer",
                                     path.string(), e));
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    names.push_back(name.empty() ? fmt::format("group_{}", tag) : name);
    layer_entities.push_back(entities);
  }
  try {
    mesh = collect_triangles(layer_entities, names, path.string());
  } catch (const SceneError&) {
    throw;
  } catch (...) {
    throw SceneError(fmt::format("cannot read the elements of '{}': {}", path.string(), gmsh_error("gmsh error")));
  }
  if (mesh.triangles.empty())
    throw SceneError(fmt::format("mesh file '{}' has no triangles in its physical surfaces", path.string()));
  double xmin = 1e300, ymin = 1e300, xmax = -1e300, ymax = -1e300;
  for (const auto& p : mesh.nodes) {
    xmin = std::min(xmin, p[0]), xmax = std::max(xmax, p[0]);
    ymin = std::min(ymin, p[1]), ymax = std::max(ymax, p[1]);
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const double a = signed_area(mesh, t);
    if (std::abs(a) <= 1e-14 * (xmax - xmin) * (ymax - ymin))
      throw SceneError(fmt::format("mesh file '{}': triangle {} is degenerate (zero area); remesh", path.string(), t));
    if (a < 0) std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
  }
  return mesh;
}

TriMesh make_mesh(const Scene& scene, const std::filesystem::path& msh_out) {
  if (!scene.mesh.file.empty()) return read_msh(scene.mesh.file);
  return mesh_specimen(SpecimenGeometry::from_scene(scene), scene.mesh.size, msh_out);
}

}  // namespace rbdem
