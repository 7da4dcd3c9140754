// The gmsh session and the model readers shared by meshing and import. See gmsh_session.hpp.
#include "dem/gmsh_session.hpp"

#include <cmath>
#include <map>
#include <random>

#include <fmt/format.h>
#include <gmsh.h>
#include <omp.h>

#include "dem/scene.hpp"

namespace rbdem::gmsh_io {

namespace {
std::mutex gmsh_mutex;
}  // namespace

void grade_by_progression(const std::vector<std::pair<int, int>>& points, int seed, double amplitude) {
  // The uniform variate is built by hand because std::uniform_real_distribution is not the same everywhere.
  std::mt19937_64 random(static_cast<std::uint64_t>(seed));
  for (const auto& [tag, count] : points) {
    const double u = double(random() >> 11) * 0x1.0p-53;  // [0, 1)
    if (count < 3) continue;                                // one segment: nothing to move
    const double ratio = std::exp(amplitude * (2.0 * u - 1.0) / double(count - 2));
    gmsh::model::mesh::setTransfiniteCurve(tag, count, "Progression", ratio);
  }
}

GmshSession::GmshSession() : lock_(gmsh_mutex), omp_threads_(omp_get_max_threads()) {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::option::setNumber("General.Verbosity", 1);
  gmsh::option::setNumber("General.NumThreads", 1);
}

GmshSession::~GmshSession() {
  gmsh::finalize();
  omp_set_num_threads(omp_threads_);
}

std::string gmsh_error(const std::string& fallback) {
  std::string err;
  try {
    gmsh::logger::getLastError(err);
  } catch (...) {
  }
  return err.empty() ? fallback : err;
}

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
  // Physical curve groups: the interfaces (joint chains) of the mesh.
  gmsh::vectorpair curve_groups;
  gmsh::model::getPhysicalGroups(curve_groups, 1);
  for (const auto& [dim, group] : curve_groups) {
    MeshInterface itf;
    gmsh::model::getPhysicalName(1, group, itf.name);
    if (itf.name.empty()) itf.name = fmt::format("curve_{}", group);
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(1, group, entities);
    for (int entity : entities) {
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> etags, enodes;
      gmsh::model::mesh::getElements(types, etags, enodes, 1, entity);
      for (std::size_t k = 0; k < types.size(); ++k) {
        if (types[k] != 1)
          throw SceneError(fmt::format("{}: physical curve '{}' holds elements of type {}: rbdem needs first-order "
                                       "lines on curves (in gmsh: Mesh.ElementOrder = 1)",
                                       source, itf.name, types[k]));
        for (std::size_t e = 0; e < etags[k].size(); ++e)
          itf.edges.push_back({index.at(enodes[k][2 * e]), index.at(enodes[k][2 * e + 1])});
      }
    }
    mesh.interfaces.push_back(std::move(itf));
  }
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
  for (auto& itf : mesh.interfaces) {
    std::vector<std::array<int, 2>> kept_edges;
    for (const auto& [u, v] : itf.edges)
      if (used[u] >= 0 && used[v] >= 0) kept_edges.push_back({used[u], used[v]});
    itf.edges = std::move(kept_edges);
  }
  return mesh;
}

}  // namespace rbdem::gmsh_io
