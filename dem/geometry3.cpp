// Closed forms of dem/geometry3.hpp.
#include "dem/geometry3.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace rbdem {

double signed_volume(const Tet& t) { return dot(t[1] - t[0], cross(t[2] - t[0], t[3] - t[0])) / 6.0; }

Vec3 centroid(const Tet& t) { return 0.25 * (((t[0] + t[1]) + t[2]) + t[3]); }

Sym3 inertia_tensor(const Tet& t, double rho) {
  const Vec3 c = centroid(t);
  const double V = std::abs(signed_volume(t));
  // C = V / 20 sum_k p_k p_k^T with p_k from the centroid (the header's quadrature), then rho (tr C 1 - C).
  Sym3 C;
  for (const Vec3& v : t) {
    const Vec3 p = v - c;
    C.xx += p.x * p.x, C.yy += p.y * p.y, C.zz += p.z * p.z;
    C.yz += p.y * p.z, C.xz += p.x * p.z, C.xy += p.x * p.y;
  }
  const double f = rho * V / 20.0;
  return {f * (C.yy + C.zz), f * (C.xx + C.zz), f * (C.xx + C.yy), -f * C.yz, -f * C.xz, -f * C.xy};
}

Principal principal(const Sym3& T) {
  Eigen::Matrix3d m;
  m << T.xx, T.xy, T.xz, T.xy, T.yy, T.yz, T.xz, T.yz, T.zz;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
  Eigen::Matrix3d axes = eig.eigenvectors();  // columns, ascending eigenvalues
  if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
  Principal p;
  for (int k = 0; k < 3; ++k) {
    p.moments[k] = eig.eigenvalues()(k);
    p.axes.r[k] = {axes(0, k), axes(1, k), axes(2, k)};
  }
  const Eigen::Quaterniond q(axes);
  p.rotation = normalized({q.w(), q.x(), q.y(), q.z()});
  return p;
}

TetBody tet_body(const Tet& t, double rho) {
  TetBody b;
  b.volume = std::abs(signed_volume(t));
  b.mass = rho * b.volume;
  b.centroid = centroid(t);
  b.inertia = principal(inertia_tensor(t, rho));
  return b;
}

Face face_of(const Tri& t) {
  Face f;
  const Vec3 a = t[1] - t[0], n = cross(a, t[2] - t[0]);
  f.area = 0.5 * norm(n);
  f.normal = (1.0 / norm(n)) * n;
  f.centroid = (1.0 / 3.0) * ((t[0] + t[1]) + t[2]);
  // The face's second moments in a first in-plane basis (u, v), then turned to the principal axes: the in-plane
  // tensor A / 12 sum_k p_k p_k^T of the header, its larger eigenvector along angle phi from u.
  const Vec3 u = (1.0 / norm(a)) * a, v = cross(f.normal, u);
  double cuu = 0, cvv = 0, cuv = 0;
  for (const Vec3& p : t) {
    const Vec3 d = p - f.centroid;
    const double pu = dot(d, u), pv = dot(d, v);
    cuu += pu * pu, cvv += pv * pv, cuv += pu * pv;
  }
  const double phi = 0.5 * std::atan2(2.0 * cuv, cuu - cvv);
  f.e1 = std::cos(phi) * u + std::sin(phi) * v;
  f.e2 = cross(f.normal, f.e1);
  double s11 = 0, s22 = 0;
  for (std::size_t k = 0; k < 3; ++k) {
    const Vec3 d = t[k] - f.centroid;
    f.y1[k] = dot(d, f.e1), f.y2[k] = dot(d, f.e2);
    f.r_max = std::max(f.r_max, norm(d));
    s11 += f.y1[k] * f.y1[k], s22 += f.y2[k] * f.y2[k];
  }
  f.I2 = f.area / 12.0 * s11, f.I1 = f.area / 12.0 * s22;
  f.J = f.I1 + f.I2;
  return f;
}

}  // namespace rbdem
