// TetMesh helpers. See tetmesh.hpp.
#include "mesh/tetmesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace rbdem {

namespace {

using Vec = std::array<double, 3>;

Vec sub(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec& a) { return std::sqrt(dot(a, a)); }

// The face opposite local vertex f, ordered so that its normal (b - a) x (c - a) points out of a positive
// tetrahedron (on the reference tetrahedron 0, e1, e2, e3 the face opposite 0 has the normal (1, 1, 1)).
constexpr std::array<std::array<int, 3>, 4> local_face{{{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};

std::array<int, 3> face_nodes(const TetMesh& mesh, std::size_t t, int f) {
  const auto& tet = mesh.tets[t];
  return {tet[local_face[f][0]], tet[local_face[f][1]], tet[local_face[f][2]]};
}

// The outward area vectors (normal x area x 2) of the four faces of tetrahedron t.
std::array<Vec, 4> face_normals(const TetMesh& mesh, std::size_t t) {
  std::array<Vec, 4> n;
  for (int f = 0; f < 4; ++f) {
    const auto v = face_nodes(mesh, t, f);
    n[f] = cross(sub(mesh.nodes[v[1]], mesh.nodes[v[0]]), sub(mesh.nodes[v[2]], mesh.nodes[v[0]]));
  }
  return n;
}

// Each face as its sorted node triple, with the tetrahedron and local face it came from; equal triples are the
// two sides of one shared face. Sorting (rather than hashing) keeps the order, and so the bond order, deterministic.
struct FaceEntry {
  std::array<int, 3> key;
  int tet, local;
};

std::vector<FaceEntry> sorted_faces(const TetMesh& mesh) {
  std::vector<FaceEntry> faces;
  faces.reserve(4 * mesh.tets.size());
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    for (int f = 0; f < 4; ++f) {
      auto key = face_nodes(mesh, t, f);
      std::sort(key.begin(), key.end());
      faces.push_back({key, int(t), f});
    }
  std::sort(faces.begin(), faces.end(), [](const FaceEntry& a, const FaceEntry& b) {
    return a.key != b.key ? a.key < b.key : a.tet < b.tet;
  });
  return faces;
}

// Calls on_shared(first, second) for each face of two tetrahedra and on_single(entry) for each face of one.
template <class Shared, class Single>
void walk_faces(const TetMesh& mesh, Shared on_shared, Single on_single) {
  const auto faces = sorted_faces(mesh);
  for (std::size_t k = 0; k < faces.size();) {
    std::size_t end = k + 1;
    while (end < faces.size() && faces[end].key == faces[k].key) ++end;
    if (end - k > 2)
      throw std::invalid_argument("tetrahedral mesh: the face of nodes " + std::to_string(faces[k].key[0]) + ", " +
                                  std::to_string(faces[k].key[1]) + ", " + std::to_string(faces[k].key[2]) +
                                  " belongs to " + std::to_string(end - k) + " tetrahedra (at most two may share one)");
    if (end - k == 2)
      on_shared(faces[k], faces[k + 1]);
    else
      on_single(faces[k]);
    k = end;
  }
}

}  // namespace

double tet_volume(const TetMesh& mesh, std::size_t t) {
  const auto& v = mesh.tets[t];
  const Vec& a = mesh.nodes[v[0]];
  return dot(sub(mesh.nodes[v[1]], a), cross(sub(mesh.nodes[v[2]], a), sub(mesh.nodes[v[3]], a))) / 6.0;
}

std::vector<SharedFace> shared_faces(const TetMesh& mesh) {
  std::vector<SharedFace> out;
  walk_faces(
      mesh,
      [&](const FaceEntry& a, const FaceEntry& b) {
        const bool joint = !mesh.layer.empty() && mesh.layer[a.tet] != mesh.layer[b.tet];
        int set = joint ? 0 : -1;
        if (joint && !mesh.layer_rows.empty()) {
          const auto& ra = mesh.layer_rows[std::size_t(mesh.layer[a.tet])];
          const auto& rb = mesh.layer_rows[std::size_t(mesh.layer[b.tet])];
          set = ra[0] != rb[0] ? 0 : 1;
        }
        out.push_back({face_nodes(mesh, a.tet, a.local), {a.tet, b.tet}, joint, set});
      },
      [](const FaceEntry&) {});
  std::sort(out.begin(), out.end(), [](const SharedFace& a, const SharedFace& b) { return a.tets < b.tets; });
  return out;
}

std::vector<BoundaryFace> boundary_faces(const TetMesh& mesh, double tol) {
  double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
  for (const auto& p : mesh.nodes) zmin = std::min(zmin, p[2]), zmax = std::max(zmax, p[2]);
  std::vector<BoundaryFace> out;
  walk_faces(
      mesh, [](const FaceEntry&, const FaceEntry&) {},
      [&](const FaceEntry& e) {
        const auto v = face_nodes(mesh, e.tet, e.local);
        auto all_at = [&](double z) {
          return std::all_of(v.begin(), v.end(), [&](int n) { return std::abs(mesh.nodes[n][2] - z) <= tol; });
        };
        const FaceTag tag = all_at(zmin) ? FaceTag::bottom : all_at(zmax) ? FaceTag::top : FaceTag::lateral;
        out.push_back({v, e.tet, tag});
      });
  std::sort(out.begin(), out.end(), [](const BoundaryFace& a, const BoundaryFace& b) {
    return a.tet != b.tet ? a.tet < b.tet : a.nodes < b.nodes;
  });
  return out;
}

double min_dihedral_deg(const TetMesh& mesh, std::size_t t) {
  const auto n = face_normals(mesh, t);
  double smallest = std::numbers::pi;
  // Every pair of faces meets along one edge; the interior dihedral angle there is pi minus the angle between
  // their outward normals.
  for (int f = 0; f < 4; ++f)
    for (int g = f + 1; g < 4; ++g) {
      const double c = std::clamp(dot(n[f], n[g]) / (norm(n[f]) * norm(n[g])), -1.0, 1.0);
      smallest = std::min(smallest, std::numbers::pi - std::acos(c));
    }
  return smallest * 180.0 / std::numbers::pi;
}

double radius_ratio(const TetMesh& mesh, std::size_t t) {
  const auto& v = mesh.tets[t];
  const Vec& a = mesh.nodes[v[0]];
  const Vec b = sub(mesh.nodes[v[1]], a), c = sub(mesh.nodes[v[2]], a), d = sub(mesh.nodes[v[3]], a);
  const double six_v = dot(b, cross(c, d));
  double area = 0;  // sum of the four face areas
  for (const auto& n : face_normals(mesh, t)) area += 0.5 * norm(n);
  const double r_in = 0.5 * std::abs(six_v) / area;  // 3 V / A
  // Circumcentre x (relative to a): 2 x . e = |e|^2 for e = b, c, d; by Cramer's rule with the triple product.
  const Vec bc = cross(c, d), cd = cross(d, b), db = cross(b, c);
  Vec x{};
  for (int i = 0; i < 3; ++i) x[i] = (dot(b, b) * bc[i] + dot(c, c) * cd[i] + dot(d, d) * db[i]) / (2.0 * six_v);
  const double r_circ = norm(x);
  return r_circ > 0 ? 3.0 * r_in / r_circ : 0.0;
}

TetMeshReport report(const TetMesh& mesh) {
  TetMeshReport r;
  r.nodes = mesh.num_nodes();
  r.tets = mesh.num_tets();
  r.layers = mesh.num_layers();
  r.mesh_seconds = mesh.mesh_seconds;
  for (const auto& f : shared_faces(mesh)) (f.joint ? r.joint_faces : r.rock_faces) += 1;
  for (const auto& f : mesh.boundary)
    (f.tag == FaceTag::bottom ? r.bottom_faces : f.tag == FaceTag::top ? r.top_faces : r.lateral_faces) += 1;
  r.min_dihedral_deg = 180.0;
  r.min_radius_ratio = 1.0;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    r.volume += tet_volume(mesh, t);
    const double angle = min_dihedral_deg(mesh, t);
    r.min_dihedral_deg = std::min(r.min_dihedral_deg, angle);
    r.min_radius_ratio = std::min(r.min_radius_ratio, radius_ratio(mesh, t));
    if (angle < sliver_deg) ++r.slivers;
  }
  return r;
}

}  // namespace rbdem
