// TriMesh helpers. See trimesh.hpp.
#include "mesh/trimesh.hpp"

namespace rbdem {

double signed_area(const TriMesh& mesh, std::size_t t) {
  const auto& tri = mesh.triangles[t];
  const auto& a = mesh.nodes[tri[0]];
  const auto& b = mesh.nodes[tri[1]];
  const auto& c = mesh.nodes[tri[2]];
  return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
}

std::vector<double> triangle_areas(const TriMesh& mesh) {
  std::vector<double> areas(mesh.num_triangles());
  for (std::size_t t = 0; t < areas.size(); ++t) areas[t] = signed_area(mesh, t);
  return areas;
}

}  // namespace rbdem
