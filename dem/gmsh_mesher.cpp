// The module librbdem_gmsh.so: meshing a specimen and reading a .msh file through the gmsh C++ API (OpenCASCADE
// kernel). See gmsh_module.hpp for why this is a module and specimen_mesh.hpp for what the functions do; the
// checks that need no gmsh are done before the module is called (specimen_mesh.cpp, msh_import.cpp).
#include <algorithm>
#include <cmath>
#include <exception>
#include <numbers>
#include <set>

#include <fmt/format.h>
#include <gmsh.h>

#include "dem/gmsh_module.hpp"
#include "dem/gmsh_session.hpp"

namespace rbdem::gmsh_io {

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
  grade_by_progression(nodes, seed, grading_amplitude);
}

// The specimen's outline as one plane surface of the current model: a rectangle, a disc, or a disc flattened over
// its contact arc. Returns the surface's tag.
int add_specimen_surface(const SpecimenGeometry& g) {
  if (g.disc && g.contact_arc_deg > 0.0) {
    // Flattened at the top and bottom over the contact arc 2 alpha: two arcs and two flat ends.
    const double R = 0.5 * g.width, a = 0.5 * g.contact_arc_deg * deg, pi = std::numbers::pi;
    auto at = [&](double q) { return gmsh::model::occ::addPoint(R + R * std::cos(q), R + R * std::sin(q), 0); };
    const int c = gmsh::model::occ::addPoint(R, R, 0);
    const int tr = at(0.5 * pi - a), tl = at(0.5 * pi + a), bl = at(1.5 * pi - a), br = at(1.5 * pi + a);
    const int right = gmsh::model::occ::addCircleArc(br, c, tr), top = gmsh::model::occ::addLine(tr, tl);
    const int left = gmsh::model::occ::addCircleArc(tl, c, bl), bottom = gmsh::model::occ::addLine(bl, br);
    const int surface =
        gmsh::model::occ::addPlaneSurface({gmsh::model::occ::addCurveLoop({right, top, left, bottom})});
    gmsh::model::occ::remove({{0, c}});
    return surface;
  }
  if (g.disc) {
    // Two half circles, so that the top and bottom points are geometry vertices and hence mesh nodes.
    const double R = 0.5 * g.width;
    const int right = gmsh::model::occ::addCircle(R, R, 0, R, -1, -0.5 * std::numbers::pi, 0.5 * std::numbers::pi);
    const int left = gmsh::model::occ::addCircle(R, R, 0, R, -1, 0.5 * std::numbers::pi, 1.5 * std::numbers::pi);
    return gmsh::model::occ::addPlaneSurface({gmsh::model::occ::addCurveLoop({right, left})});
  }
  return gmsh::model::occ::addRectangle(0, 0, 0, g.width, g.height);
}

// Cuts the specimen's `surface` along the job's joint segments, each extended past the sides it ends on, and
// synchronizes the model. Returns gmsh's fragment map: entry 1 + t holds the pieces of segment t.
std::vector<gmsh::vectorpair> cut_joints(const MeshJob& job, int surface) {
  const SpecimenGeometry& g = job.geometry;
  gmsh::vectorpair tools;
  const double reach = 0.05 * std::hypot(g.width, g.height);  // lines overshoot the sides; trimmed below
  for (const auto& s : job.segments) {
    const auto d = job.direction[std::size_t(s.set)];
    const double ra = s.a_on_boundary ? reach : 0.0, rb = s.b_on_boundary ? reach : 0.0;
    const int p0 = gmsh::model::occ::addPoint(s.a[0] - ra * d[0], s.a[1] - ra * d[1], 0);
    const int p1 = gmsh::model::occ::addPoint(s.b[0] + rb * d[0], s.b[1] + rb * d[1], 0);
    tools.push_back({1, gmsh::model::occ::addLine(p0, p1)});
  }
  std::vector<gmsh::vectorpair> map;
  if (!tools.empty()) {
    gmsh::vectorpair out;
    gmsh::model::occ::fragment({{2, surface}}, tools, out, map);
  }
  gmsh::model::occ::synchronize();
  return map;
}

// Removes the overshooting line pieces: curves outside the specimen (their middle is outside it). Returns the tags
// of the curves kept.
std::set<int> remove_dangling_curves(const SpecimenGeometry& g) {
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
  return kept;
}

// The joints of each set as a physical curve group (what collect_triangles reads as TriMesh::interfaces), from
// the kept pieces of its segments.
void group_joints(const MeshJob& job, const std::vector<gmsh::vectorpair>& map, const std::set<int>& kept) {
  for (int k = 0; k < 2; ++k) {
    std::set<int> group;
    for (std::size_t t = 0; t < job.segments.size(); ++t)
      if (job.segments[t].set == k && 1 + t < map.size())
        for (const auto& [dim, tag] : map[1 + t])
          if (dim == 1 && kept.count(tag)) group.insert(tag);
    if (group.empty()) continue;
    const int pg = gmsh::model::addPhysicalGroup(1, std::vector<int>(group.begin(), group.end()));
    gmsh::model::setPhysicalName(1, pg, joint_set_group[std::size_t(k)]);
  }
}

// The layers as collect_triangles takes them: the surfaces and the name of each layer.
struct Layers {
  std::vector<std::vector<int>> entities;
  std::vector<std::string> names;
};

// Each surface a layer, a physical surface group layer_0, layer_1, ... in order along the joint normal, so layer
// ids are reproducible.
Layers group_layers(const MeshJob& job, const gmsh::vectorpair& surfaces) {
  const auto n = job.normal;
  std::vector<std::pair<double, int>> order;
  for (const auto& [dim, tag] : surfaces) {
    double cx = 0, cy = 0, cz = 0;
    gmsh::model::occ::getCenterOfMass(2, tag, cx, cy, cz);
    order.push_back({n[0] * cx + n[1] * cy, tag});
  }
  std::sort(order.begin(), order.end());
  Layers layers;
  for (std::size_t l = 0; l < order.size(); ++l) {
    const std::string name = fmt::format("layer_{}", l);
    const int pg = gmsh::model::addPhysicalGroup(2, {order[l].second});
    gmsh::model::setPhysicalName(2, pg, name);
    layers.entities.push_back({order[l].second});
    layers.names.push_back(name);
  }
  return layers;
}

// Boundary sides as named physical curves (for the FE model and for inspection in gmsh): bottom, right, top, left
// of a rectangle, the rim of a disc.
void group_sides(const SpecimenGeometry& g, const gmsh::vectorpair& surfaces) {
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
}

// Makes every surface of the current model a transfinite grid (mesh_specimen's `structured`): each piece of the
// rectangle has four sides, two horizontal ones (the specimen's top or bottom, or a joint) and two vertical ones;
// the horizontal curves get round(W / h) segments, the vertical ones round(their height / h), so that opposite
// sides match and every cell is the same rectangle, split into two right triangles.
void structure_surfaces(const SpecimenGeometry& g, double h) {
  const double eps = 1e-9 * std::max(g.width, g.height);
  const int columns = std::max(1, int(std::lround(g.width / h)));
  gmsh::vectorpair curves, surfaces;
  gmsh::model::getEntities(curves, 1);
  for (const auto& [dim, tag] : curves) {
    std::vector<double> lo, hi, a, b;  // the curve's end points (OCC's bounding boxes are padded)
    gmsh::model::getParametrizationBounds(1, tag, lo, hi);
    gmsh::model::getValue(1, tag, lo, a);
    gmsh::model::getValue(1, tag, hi, b);
    const double rise = std::abs(b.at(1) - a.at(1));
    const bool horizontal = rise < eps;
    const int segments = horizontal ? columns : std::max(1, int(std::lround(rise / h)));
    gmsh::model::mesh::setTransfiniteCurve(tag, segments + 1);
  }
  gmsh::model::getEntities(surfaces, 2);
  for (const auto& [dim, tag] : surfaces) gmsh::model::mesh::setTransfiniteSurface(tag, "Left");
}

// Meshes the surfaces with triangles of size h (Delaunay), the curves graded first when g.mesh_seed != 0; or as
// structured grids when g.structured.
void generate_mesh(const SpecimenGeometry& g, double h) {
  if (g.structured) {
    structure_surfaces(g, h);
    gmsh::model::mesh::generate(2);
    return;
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
}

// The specimen meshed in a gmsh session of its own: outline, joints cut in, physical groups (joints, layers,
// sides), mesh; the triangles collected and tidied.
TriMesh mesh_specimen_now(const MeshJob& job) {
  const SpecimenGeometry& g = job.geometry;
  GmshSession session;
  TriMesh mesh;
  try {
    gmsh::model::add("specimen");
    const std::vector<gmsh::vectorpair> map = cut_joints(job, add_specimen_surface(g));
    gmsh::vectorpair surfaces;  // the pieces of the cut specimen: one layer each
    gmsh::model::getEntities(surfaces, 2);
    const std::set<int> kept = remove_dangling_curves(g);
    group_joints(job, map, kept);
    const Layers layers = group_layers(job, surfaces);
    group_sides(g, surfaces);
    generate_mesh(g, job.h);

    mesh = collect_triangles(layers.entities, layers.names, "specimen mesh");
    if (!job.msh_out.empty()) {
      gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
      gmsh::write(job.msh_out);
    }
  } catch (const SceneError&) {
    throw;
  } catch (...) {
    throw SceneError("gmsh failed to mesh the specimen: " + gmsh_error("unknown error") +
                     " (check specimen.*, joint_set.* and mesh.size)");
  }
  tidy(mesh, g.width, g.height, 1e-9 * std::max(g.width, g.height));
  return mesh;
}

TriMesh read_msh_now(const std::string& path) {
  GmshSession session;
  TriMesh mesh;
  try {
    gmsh::open(path);
  } catch (...) {
    throw SceneError(fmt::format("cannot read mesh file '{}': {} (expected a gmsh .msh file)", path,
                                 gmsh_error("not a readable mesh")));
  }
  gmsh::vectorpair groups;
  std::vector<int> volume_types;
  std::vector<std::vector<std::size_t>> volume_tags, volume_nodes;
  try {
    gmsh::model::getPhysicalGroups(groups, 2);
    gmsh::model::mesh::getElements(volume_types, volume_tags, volume_nodes, 3, -1);
  } catch (...) {
    throw SceneError(fmt::format("cannot read the groups of '{}': {}", path, gmsh_error("gmsh error")));
  }
  std::size_t volume_elements = 0;
  for (const auto& t : volume_tags) volume_elements += t.size();
  if (volume_elements > 0)
    throw SceneError(fmt::format("mesh file '{}' is a 3D mesh ({} volume elements): rbdem needs a planar triangle "
                                 "mesh in the x-y plane; mesh the 2D cross-section (gmsh: Mesh > 2D) and save again",
                                 path, volume_elements));
  if (groups.empty())
    throw SceneError(fmt::format("mesh file '{}' has no physical surface groups: define one physical surface per "
                                 "rock layer (Physical Surface(\"layer_0\") = {{...}}) and save again",
                                 path));
  std::vector<std::vector<int>> layer_entities;
  std::vector<std::string> names;
  std::set<int> seen;
  for (const auto& [dim, tag] : groups) {
    std::vector<int> entities;
    std::string name;
    try {
      gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
      gmsh::model::getPhysicalName(dim, tag, name);
    } catch (...) {
      throw SceneError(fmt::format("cannot read physical group {} of '{}': {}", tag, path,
                                   gmsh_error("gmsh error")));
    }
    for (int e : entities)
      if (!seen.insert(e).second)
        throw SceneError(fmt::format("mesh file '{}': surface {} belongs to two physical groups; each triangle must "
                                     "be in exactly one layer",
                                     path, e));
    names.push_back(name.empty() ? fmt::format("group_{}", tag) : name);
    layer_entities.push_back(entities);
  }
  try {
    mesh = collect_triangles(layer_entities, names, path);
  } catch (const SceneError&) {
    throw;
  } catch (...) {
    throw SceneError(fmt::format("cannot read the elements of '{}': {}", path, gmsh_error("gmsh error")));
  }
  return mesh;
}

// Runs `make` and turns anything it throws into the outcome's message.
template <class Make>
MeshOutcome outcome_of(Make make) {
  MeshOutcome out;
  try {
    out.mesh = make();
  } catch (const std::exception& e) {
    out.error = e.what();
  } catch (...) {
    out.error = "gmsh failed: " + gmsh_error("unknown error");
  }
  return out;
}

MeshOutcome mesh_specimen(const MeshJob& job) {
  return outcome_of([&] { return mesh_specimen_now(job); });
}

MeshOutcome read_msh(const std::string& path) {
  return outcome_of([&] { return read_msh_now(path); });
}

}  // namespace

}  // namespace rbdem::gmsh_io

extern "C" [[gnu::visibility("default")]] const rbdem::gmsh_io::GmshModule* rbdem_gmsh_module() {
  static rbdem::gmsh_io::GmshModule table = [] {
    rbdem::gmsh_io::GmshModule t;
    t.mesh_specimen = &rbdem::gmsh_io::mesh_specimen;
    t.read_msh = &rbdem::gmsh_io::read_msh;
    t.mesh_specimen3 = &rbdem::gmsh_io::mesh_specimen3;
    t.read_msh3 = &rbdem::gmsh_io::read_msh3;
    return t;
  }();
  return &table;
}
