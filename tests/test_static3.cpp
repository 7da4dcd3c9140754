// The static elastic solve of the 3D face-bond network (dem/static3.hpp) against finite differences of the face
// bond's kernel, Clapeyron's theorem, Amadei's closed forms and the 3D FE twin (continuum/fe_3d.hpp) with the
// network's own elastic constants, measured on prisms as docs/continuum.md, "The 3D DEM's static moduli" describes.
//
// Static3.DISABLED_Table prints that section's tables (mesh size in mm from RBDEM_STATIC3_H, default 4):
//   RBDEM_STATIC3_H=4 build/tests/test_static3 --gtest_also_run_disabled_tests --gtest_filter=Static3.DISABLED_Table
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>

#include "continuum/fe_3d.hpp"
#include "dem/specimen_mesh3.hpp"
#include "dem/static3.hpp"
#include "theory/elasticity.hpp"
#include "theory/elasticity3.hpp"

namespace rbdem {
namespace {

using stages::BlockKin3;
using stages::FaceBondFrame;

// Two irregular tetrahedra on one shared face (mm scale), a rock bond of the paper scene's rock.
struct Pair {
  Vec3 ci, cj;
  FaceBondFrame frame;
};
Pair pair() {
  const double L = 1e-3;
  const Tri face{Vec3{0, 0, 0}, Vec3{1.1 * L, 0.1 * L, 0.05 * L}, Vec3{0.3 * L, 0.9 * L, -0.1 * L}};
  const Vec3 ai{0.4 * L, 0.2 * L, -1.0 * L}, aj{0.3 * L, 0.5 * L, 1.2 * L};
  Pair p;
  p.ci = 0.25 * (face[0] + face[1] + face[2] + ai);
  p.cj = 0.25 * (face[0] + face[1] + face[2] + aj);
  p.frame = stages::face_bond_frame(p.ci, p.cj, face, FaceBond{1.0 / 1.5, {}, 0.0}, 160e9,
                                    std::numeric_limits<double>::infinity());
  return p;
}

// The generalized forces (F_i, M_i, F_j, M_j) of eval_face_bond at the dofs q (u_i, phi_i, u_j, phi_j) added to a
// base state, with velocities q / dt (dt = 1 s) so that the linear part's incremental shear is its total shear.
std::array<double, 12> forces_at(const Pair& p, const std::array<double, 12>& q, Vec3 base_j) {
  auto kin = [&](Vec3 c, int o, Vec3 base) {
    const Vec3 u{q[o], q[o + 1], q[o + 2]}, phi{q[o + 3], q[o + 4], q[o + 5]};
    return BlockKin3{c + base + u, from_rotation_vector(phi), u, phi};
  };
  const auto e = stages::eval_face_bond(p.frame, kin(p.ci, 0, {}), kin(p.cj, 6, base_j), 1.0, 0.0, 0.0, 1.0);
  const Vec3 fi = -e.f;
  return {fi.x, fi.y, fi.z, e.mi.x, e.mi.y, e.mi.z, e.f.x, e.f.y, e.f.z, e.mj.x, e.mj.y, e.mj.z};
}

// The 12 x 12 matrix is minus the Jacobian of the kernel's forces: central differences about a state pressed
// together by delta0 along n, so that the linear part stays closed over the whole face under the small motions
// (its force there adds geometric terms of relative size delta0 / L = 1e-6). Rotation dofs are scaled by L so
// that every entry is in N/m.
TEST(Static3, FaceBondMatrixIsTheKernelsJacobian) {
  const Pair p = pair();
  const double L = 1e-3, delta0 = 1e-9, h = 1e-12;
  const Vec3 base_j = -delta0 * p.frame.axes.r[2];
  const FaceBondMatrix K = face_bond_stiffness(p.frame, true);
  double kmax = 0, err = 0;
  for (int c = 0; c < 12; ++c) {
    const double step = (c % 6 < 3) ? h : h / L;
    std::array<double, 12> qp{}, qm{};
    qp[std::size_t(c)] = step, qm[std::size_t(c)] = -step;
    const auto fp = forces_at(p, qp, base_j), fm = forces_at(p, qm, base_j);
    for (int r = 0; r < 12; ++r) {
      const double scale = ((r % 6 < 3) ? 1.0 : 1.0 / L) * ((c % 6 < 3) ? 1.0 : 1.0 / L);
      const double fd = -(fp[std::size_t(r)] - fm[std::size_t(r)]) / (2 * step) * scale;
      const double k = K[std::size_t(12 * r + c)] * scale;
      kmax = std::max(kmax, std::abs(k)), err = std::max(err, std::abs(fd - k));
    }
  }
  EXPECT_LT(err / kmax, 1e-5) << "max |K| " << kmax << " N/m";
  // The parallel bond alone is half the normal and shear stiffness: the closed linear part doubles them.
  const FaceBondMatrix Kpb = face_bond_stiffness(p.frame, false);
  EXPECT_NEAR(K[12 * 6 + 6] - Kpb[12 * 6 + 6], K[0] - Kpb[0], 1e-9 * K[0]);
}

// Symmetric and zero on the six rigid motions of the pair: u = t + w x c, phi = w.
TEST(Static3, FaceBondMatrixIsSymmetricAndIgnoresRigidMotion) {
  const Pair p = pair();
  const FaceBondMatrix K = face_bond_stiffness(p.frame, true);
  double kmax = 0;
  for (double k : K) kmax = std::max(kmax, std::abs(k));
  for (int r = 0; r < 12; ++r)
    for (int c = 0; c < 12; ++c) EXPECT_EQ(K[std::size_t(12 * r + c)], K[std::size_t(12 * c + r)]);
  const Vec3 t{1e-6, -2e-6, 3e-6}, w{0.7e-3, -0.4e-3, 0.9e-3};
  const Vec3 ui = t + cross(w, p.ci), uj = t + cross(w, p.cj);
  const double q[12] = {ui.x, ui.y, ui.z, w.x, w.y, w.z, uj.x, uj.y, uj.z, w.x, w.y, w.z};
  for (int r = 0; r < 12; ++r) {
    double f = 0;
    for (int c = 0; c < 12; ++c) f += K[std::size_t(12 * r + c)] * q[c];
    EXPECT_LT(std::abs(f), 1e-12 * kmax * 1e-5) << "row " << r;
  }
}

}  // namespace
}  // namespace rbdem
