// The module's 3D mesher: a cylinder, a prism or a flattened disc cut by joint planes and meshed in tetrahedra
// through the gmsh C++ API (OpenCASCADE kernel). See specimen_mesh3.hpp for what it makes and gmsh_module.hpp for
// why it is a module.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <map>
#include <numbers>
#include <set>

#include <fmt/format.h>
#include <gmsh.h>

#include "dem/gmsh_module.hpp"
#include "dem/gmsh_session.hpp"

namespace rbdem::gmsh_io {

namespace {

using Vec = std::array<double, 3>;

// The z of the disc's bottom and top flats (its rim's lowest and highest points for a full disc).
std::array<double, 2> disc_flats(const SpecimenGeometry3& g) {
  const double R = 0.5 * g.diameter, c = std::cos(0.5 * g.contact_arc_deg * std::numbers::pi / 180.0);
  return {R - R * c, R + R * c};
}

// The Brazilian disc: a cylinder along y, flattened by keeping only the slab between its flats (a box wider than
// the disc), so the flats are plane faces that the mesh conforms to.
int add_disc(const SpecimenGeometry3& g) {
  const double R = 0.5 * g.diameter, t = g.thickness;
  const int disc = gmsh::model::occ::addCylinder(R, 0.0, R, 0.0, t, 0.0, R);
  if (!(g.contact_arc_deg > 0.0)) return disc;
  const auto [zb, zt] = disc_flats(g);
  const int slab = gmsh::model::occ::addBox(-R, -t, zb, 2.0 * g.diameter, 3.0 * t, zt - zb);
  gmsh::vectorpair out;
  std::vector<gmsh::vectorpair> map;
  gmsh::model::occ::intersect({{3, disc}}, {{3, slab}}, out, map);
  if (out.size() != 1 || out[0].first != 3)
    throw SceneError("gmsh could not flatten the disc (specimen.contact_arc_deg): check its value");
  return out[0].second;
}

int add_solid(const SpecimenGeometry3& g) {
  if (g.shape == Shape3::disc) return add_disc(g);
  if (g.shape == Shape3::cylinder) {
    const double R = 0.5 * g.diameter;
    return gmsh::model::occ::addCylinder(R, R, 0.0, 0.0, 0.0, g.height, R);
  }
  return gmsh::model::occ::addBox(0.0, 0.0, 0.0, g.width, g.depth, g.height);
}

// A square of the plane, centred on the foot of the specimen's centre and larger than the specimen, to cut it by.
int add_plane(const SpecimenGeometry3& g, const Vec& c, const JointPlane& p) {
  const Vec n = p.normal;
  // Two unit vectors in the plane: the horizontal strike (any horizontal vector when the plane is horizontal) and
  // the dip line n x u.
  const double horizontal = std::hypot(n[0], n[1]);
  const Vec u = horizontal > 1e-12 ? Vec{-n[1] / horizontal, n[0] / horizontal, 0.0} : Vec{1.0, 0.0, 0.0};
  const Vec v{n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]};
  const double L = 2.0 * std::max({g.diameter, g.width, g.depth, g.height, g.thickness});
  std::vector<int> points;
  for (const auto& [a, b] : {std::pair{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}}) {
    Vec x{};
    for (int i = 0; i < 3; ++i) x[i] = c[i] + p.r * n[i] + L * (a * u[i] + b * v[i]);
    points.push_back(gmsh::model::occ::addPoint(x[0], x[1], x[2]));
  }
  std::vector<int> lines;
  for (int k = 0; k < 4; ++k) lines.push_back(gmsh::model::occ::addLine(points[k], points[(k + 1) % 4]));
  return gmsh::model::occ::addPlaneSurface({gmsh::model::occ::addCurveLoop(lines)});
}

// Cuts the solid by the planes and removes the parts of the planes outside it: afterwards every surface of the
// model bounds a volume, and the volumes are the layers.
void cut_by_planes(const MeshJob3& job) {
  const int solid = add_solid(job.geometry);
  gmsh::vectorpair tools;
  for (const auto& p : job.planes) tools.push_back({2, add_plane(job.geometry, job.centre, p)});
  if (!tools.empty()) {
    gmsh::vectorpair out;
    std::vector<gmsh::vectorpair> map;
    gmsh::model::occ::fragment({{3, solid}}, tools, out, map);
  }
  gmsh::model::occ::synchronize();
  gmsh::vectorpair volumes, bounding, surfaces, dangling;
  gmsh::model::getEntities(volumes, 3);
  gmsh::model::getBoundary(volumes, bounding, false, false, false);
  std::set<int> kept;
  for (const auto& [dim, tag] : bounding) kept.insert(std::abs(tag));
  gmsh::model::getEntities(surfaces, 2);
  for (const auto& dt : surfaces)
    if (!kept.count(dt.second)) dangling.push_back(dt);
  if (!dangling.empty()) {
    gmsh::model::occ::remove(dangling, true);
    gmsh::model::occ::synchronize();
  }
}

// The volumes in layer order, each a physical volume "layer_<l>": by the number of planes of the first set below
// the volume's centre of mass, then of the second set (so the layers of one set run along its normal).
std::vector<int> group_layers(const MeshJob3& job, std::vector<std::string>& names,
                              std::vector<std::array<int, 2>>& rows) {
  gmsh::vectorpair volumes;
  gmsh::model::getEntities(volumes, 3);
  const Vec c = job.centre;
  std::vector<std::pair<std::array<int, 2>, int>> order;
  for (const auto& [dim, tag] : volumes) {
    Vec m{};
    gmsh::model::occ::getCenterOfMass(3, tag, m[0], m[1], m[2]);
    std::array<int, 2> below{0, 0};
    for (const auto& p : job.planes) {
      const double r = p.normal[0] * (m[0] - c[0]) + p.normal[1] * (m[1] - c[1]) + p.normal[2] * (m[2] - c[2]);
      if (r > p.r) ++below[std::size_t(p.set)];
    }
    order.push_back({below, tag});
  }
  std::sort(order.begin(), order.end());
  std::vector<int> tags;
  for (std::size_t l = 0; l < order.size(); ++l) {
    names.push_back(fmt::format("layer_{}", l));
    rows.push_back(order[l].first);
    const int pg = gmsh::model::addPhysicalGroup(3, {order[l].second});
    gmsh::model::setPhysicalName(3, pg, names.back());
    tags.push_back(order[l].second);
  }
  return tags;
}

// Largest log-ratio of the last to the first segment of a graded curve, as in 2D (gmsh_mesher.cpp): spacings
// within exp(+-0.05 / 2) of the mean, about +-2.5 %.
constexpr double grading_amplitude3 = 0.05;

// A mesh realization (see mesh_specimen3 in specimen_mesh3.hpp): grades the 1D mesh of every curve of the model
// (the rims of the ends, the seam, the traces of the joint planes on the surface and on each other) by a seeded
// geometric progression. Each curve keeps the segment count gmsh gives it at the size options already set, read
// from a 1D mesh made first (as line elements, so that a closed curve, whose one vertex is both ends, counts
// right). The surfaces are then meshed from moved curve nodes, and the volumes from moved surface nodes, so the
// whole tetrahedral mesh differs while its size and quality stay those of the reference mesh.
void grade_curves3(int seed) {
  gmsh::model::mesh::generate(1);
  gmsh::vectorpair curves;
  gmsh::model::getEntities(curves, 1);
  std::vector<std::pair<int, int>> points;  // curve tag, segments + 1
  for (const auto& [dim, tag] : curves) {
    std::vector<std::size_t> etags, enodes;
    gmsh::model::mesh::getElementsByType(1, etags, enodes, tag);
    points.push_back({tag, int(etags.size()) + 1});
  }
  gmsh::model::mesh::clear();
  grade_by_progression(points, seed, grading_amplitude3);
}

// The first-order tetrahedra of the layers (each a list of volume entities), with the nodes they use (in order of
// first use).
TetMesh collect_tets(const std::vector<std::vector<int>>& layer_volumes, std::vector<std::string> names) {
  std::vector<std::size_t> node_tags;
  std::vector<double> coord, param;
  gmsh::model::mesh::getNodes(node_tags, coord, param, -1, -1, false, false);
  std::map<std::size_t, std::size_t> where;
  for (std::size_t k = 0; k < node_tags.size(); ++k) where[node_tags[k]] = k;
  TetMesh mesh;
  std::map<std::size_t, int> index;  // gmsh node tag -> mesh node
  for (std::size_t l = 0; l < layer_volumes.size(); ++l) {
    for (const int volume : layer_volumes[l]) {
      std::vector<std::size_t> etags, enodes;
      gmsh::model::mesh::getElementsByType(4, etags, enodes, volume);
      for (std::size_t e = 0; e < etags.size(); ++e) {
        std::array<int, 4> tet{};
        for (int v = 0; v < 4; ++v) {
          const std::size_t tag = enodes[4 * e + std::size_t(v)];
          auto [it, added] = index.try_emplace(tag, int(mesh.nodes.size()));
          if (added) {
            const std::size_t k = where.at(tag);
            mesh.nodes.push_back({coord[3 * k], coord[3 * k + 1], coord[3 * k + 2]});
          }
          tet[std::size_t(v)] = it->second;
        }
        mesh.tets.push_back(tet);
        mesh.layer.push_back(int(l));
      }
    }
  }
  mesh.layer_names = std::move(names);
  return mesh;
}

// Snaps the nodes within `tol` of the flat faces onto them (OpenCASCADE returns 0.09999999999999999 for 0.1) and
// turns every tetrahedron to a positive volume.
void tidy3(TetMesh& mesh, const SpecimenGeometry3& g, double tol) {
  auto snap = [&](double& x, double to) {
    if (std::abs(x - to) < tol) x = to;
  };
  for (auto& p : mesh.nodes) {
    if (g.shape == Shape3::disc) {
      const auto [zb, zt] = disc_flats(g);
      snap(p[2], zb), snap(p[2], zt);
      snap(p[1], 0.0), snap(p[1], g.thickness);
      continue;
    }
    snap(p[2], 0.0);
    snap(p[2], g.height);
    if (g.shape == Shape3::prism) {
      snap(p[0], 0.0), snap(p[0], g.width);
      snap(p[1], 0.0), snap(p[1], g.depth);
    }
  }
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (tet_volume(mesh, t) < 0) std::swap(mesh.tets[t][2], mesh.tets[t][3]);
}

TetMesh mesh_specimen3_now(const MeshJob3& job) {
  const auto start = std::chrono::steady_clock::now();
  const SpecimenGeometry3& g = job.geometry;
  GmshSession session;
  TetMesh mesh;
  try {
    gmsh::model::add("specimen3");
    cut_by_planes(job);
    std::vector<std::string> names;
    std::vector<std::array<int, 2>> rows;
    const std::vector<int> layers = group_layers(job, names, rows);
    gmsh::option::setNumber("Mesh.MeshSizeMin", job.h);
    gmsh::option::setNumber("Mesh.MeshSizeMax", job.h);
    gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
    gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
    if (job.seed != 0) grade_curves3(job.seed);
    gmsh::model::mesh::generate(3);
    std::vector<std::vector<int>> layer_volumes;
    for (const int v : layers) layer_volumes.push_back({v});
    mesh = collect_tets(layer_volumes, std::move(names));
    mesh.layer_rows = std::move(rows);
  } catch (const std::exception& e) {
    throw SceneError(fmt::format("gmsh failed to mesh the 3D specimen: {} (check the specimen's sizes, the joint "
                                 "planes and the mesh size)",
                                 gmsh_error(e.what())));
  }
  const double tol = 1e-9 * std::max({g.diameter, g.width, g.depth, g.height, g.thickness});
  tidy3(mesh, g, tol);
  mesh.boundary = boundary_faces(mesh, tol);
  mesh.mesh_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return mesh;
}

// The layers of a user mesh: its physical volumes, in tag order, each with its entities. Refuses a mesh without
// physical volumes, a volume entity in two of them and 3D elements other than first-order tetrahedra.
std::vector<std::vector<int>> user_layers(const std::string& path, std::vector<std::string>& names) {
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups, 3);
  if (groups.empty())
    throw SceneError(fmt::format("mesh file '{}' has no physical volume: give each layer of the 3D specimen a "
                                 "physical volume (Physical Volume(\"name\") = {{...}} in gmsh)",
                                 path));
  std::vector<std::vector<int>> layers;
  std::set<int> seen;
  for (const auto& [dim, tag] : groups) {
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(3, tag, entities);
    for (const int e : entities)
      if (!seen.insert(e).second)
        throw SceneError(fmt::format("mesh file '{}': volume {} is in two physical volumes; give each volume one "
                                     "layer",
                                     path, e));
    std::string name;
    gmsh::model::getPhysicalName(3, tag, name);
    names.push_back(name.empty() ? fmt::format("volume_{}", tag) : name);
    layers.push_back(entities);
  }
  std::vector<int> types;
  gmsh::model::mesh::getElementTypes(types, 3);
  for (const int t : types)
    if (t != 4) {
      std::string type_name;
      int order = 0, nodes = 0, primary = 0;
      int edim = 0;
      std::vector<double> local;
      gmsh::model::mesh::getElementProperties(t, type_name, edim, order, nodes, local, primary);
      throw SceneError(fmt::format("mesh file '{}' holds 3D elements of type {} ({}): the 3D DEM takes first-order "
                                   "tetrahedra only (Mesh.ElementOrder = 1, no recombination)",
                                   path, t, type_name));
    }
  return layers;
}

TetMesh read_msh3_now(const std::string& path) {
  const auto start = std::chrono::steady_clock::now();
  GmshSession session;
  TetMesh mesh;
  try {
    gmsh::open(path);
    std::vector<std::string> names;
    const auto layers = user_layers(path, names);
    mesh = collect_tets(layers, std::move(names));
  } catch (const SceneError&) {
    throw;
  } catch (const std::exception& e) {
    throw SceneError(fmt::format("gmsh could not read the mesh file '{}': {}", path, gmsh_error(e.what())));
  }
  if (mesh.tets.empty())
    throw SceneError(fmt::format("mesh file '{}' has no tetrahedra in its physical volumes: mesh the volumes in 3D "
                                 "(gmsh -3) and save them",
                                 path));
  Vec lo = mesh.nodes.front(), hi = lo;
  for (const auto& p : mesh.nodes)
    for (int i = 0; i < 3; ++i) lo[i] = std::min(lo[i], p[i]), hi[i] = std::max(hi[i], p[i]);
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  std::size_t turned = 0;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const double v = tet_volume(mesh, t);
    if (!(std::abs(v) > 1e-12 * extent * extent * extent))
      throw SceneError(fmt::format("mesh file '{}': tetrahedron {} is degenerate (volume {:.3g} m^3); remesh", path,
                                   t, v));
    if (v < 0) std::swap(mesh.tets[t][2], mesh.tets[t][3]), ++turned;
  }
  if (turned > 0) mesh.notes.push_back(fmt::format("{} negative tetrahedra of {} turned", turned, path));
  mesh.boundary = boundary_faces(mesh, 1e-9 * extent);
  mesh.mesh_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return mesh;
}

}  // namespace

MeshOutcome3 read_msh3(const std::string& path) {
  MeshOutcome3 out;
  try {
    out.mesh = read_msh3_now(path);
  } catch (const std::exception& e) {
    out.error = e.what();
  } catch (...) {
    out.error = "gmsh could not read the mesh file '" + path + "': " + gmsh_error("unknown error");
  }
  return out;
}

MeshOutcome3 mesh_specimen3(const MeshJob3& job) {
  MeshOutcome3 out;
  try {
    out.mesh = mesh_specimen3_now(job);
  } catch (const std::exception& e) {
    out.error = e.what();
  } catch (...) {
    out.error = "gmsh failed to mesh the 3D specimen: " + gmsh_error("unknown error");
  }
  return out;
}

}  // namespace rbdem::gmsh_io
