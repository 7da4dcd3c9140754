// Three-dimensional rigid blocks (dem/dim.hpp Dim<3>, dem/vec3.hpp, dem/geometry3.hpp, dem/rigid3.hpp): the
// tetrahedron's volume, centroid and inertia against hand values and under rotation; the quaternion maps; the
// torque-free asymmetric block (|L| to round-off, the energy to second order in dt without drift, near the
// unstable intermediate axis and near a stable one); the symmetric top's precession rate in closed form; Cundall's
// damping per degree of freedom; the 3D critical time step against the exact limit of a bonded block.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "compare/verify/dem_measures.hpp"
#include "dem/dim.hpp"
#include "dem/geometry3.hpp"
#include "dem/rigid3.hpp"
#include "dem/stages/face_bond_kernel.hpp"

namespace rbdem {
namespace {

TEST(Dim3, SizesNamesAndPlacingByTheQuaternion) {
  EXPECT_EQ(Dim<3>::dof, 6);
  EXPECT_EQ(Dim<3>::pose, 7);
  EXPECT_EQ(Dim<3>::block_vertices, 4);
  EXPECT_EQ(Dim<3>::face_vertices, 3);
  EXPECT_STREQ(Dim<3>::cell_type, "Tetrahedron");
  EXPECT_STREQ(Dim<3>::pose_names[3], "qw");
  // 90 degrees about z: (1, 0, 0) goes to (0, 1, 0).
  const double h = std::sqrt(0.5);
  const double pose[7] = {1, 2, 3, h, 0, 0, h}, v[3] = {1, 0, 0};
  double out[3];
  Dim<3>::place(pose, v, out);
  EXPECT_NEAR(out[0], 1.0, 1e-15);
  EXPECT_NEAR(out[1], 3.0, 1e-15);
  EXPECT_NEAR(out[2], 3.0, 1e-15);
  // The same as rotate() for an oblique rotation.
  const Quat q = from_rotation_vector({0.4, -0.9, 1.3});
  const double pose2[7] = {0, 0, 0, q.w, q.x, q.y, q.z}, w[3] = {0.3, -1.2, 0.8};
  Dim<3>::place(pose2, w, out);
  const Vec3 r = rotate(q, {0.3, -1.2, 0.8});
  EXPECT_NEAR(out[0], r.x, 1e-15);
  EXPECT_NEAR(out[1], r.y, 1e-15);
  EXPECT_NEAR(out[2], r.z, 1e-15);
}

TEST(Dim3, RunTimeHelpersServeDimensionsTwoAndThree) {
  EXPECT_EQ(pose_size(2), 3);
  EXPECT_STREQ(cell_type(2), "Triangle");
  EXPECT_EQ(pose_size(3), 7);
  EXPECT_EQ(dof_per_block(3), 6);
  EXPECT_STREQ(cell_type(3), "Tetrahedron");
  EXPECT_THROW(check_dimension(4), std::invalid_argument);
  EXPECT_THROW(pose_size(1), std::invalid_argument);
}

TEST(Quaternion, MapsAndHalfRotationInvertEachOther) {
  const Vec3 phi{0.7, -0.2, 1.9};
  const Quat q = from_rotation_vector(phi);
  EXPECT_NEAR(norm(q), 1.0, 1e-15);
  EXPECT_NEAR(norm(rotation_vector(q) - phi), 0.0, 1e-14);
  const Quat h = half_rotation(q), hh = h * h;
  EXPECT_NEAR(std::abs(hh.w - q.w) + std::abs(hh.x - q.x) + std::abs(hh.y - q.y) + std::abs(hh.z - q.z), 0, 1e-15);
  for (double angle : {0.0099, 0.0101}) {  // either side of rotation_vector's series
    const Vec3 a = (angle / std::sqrt(14.0)) * Vec3{1, -2, 3};
    EXPECT_NEAR(norm(rotation_vector(from_rotation_vector(a)) - a), 0.0, 1e-17);
  }
  const Vec3 tiny{3e-9, -1e-9, 2e-9};  // the small-angle branches
  EXPECT_NEAR(norm(rotation_vector(from_rotation_vector(tiny)) - tiny), 0.0, 1e-24);
  const Mat3 R = matrix(q);
  const Vec3 v{0.1, 0.5, -0.3};
  EXPECT_NEAR(norm(R * v - rotate(q, v)), 0.0, 1e-15);
}

TEST(TetGeometry, UnitRightTetrahedronMatchesTheHandValues) {
  // (0,0,0), (1,0,0), (0,1,0), (0,0,1), rho = 1: V = 1/6, centroid (1/4, 1/4, 1/4). About the centroid
  // int x^2 = V / 20 x 3/4 = 1/160, int x y = V / 20 x (-1/4) = -1/480: I_xx = 2/160 = 1/80, I_xy = +1/480.
  // Principal moments: 1/80 + 2/480 = 1/60 about (1, 1, 1) and 1/80 - 1/480 = 1/96 (twice).
  const Tet t{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  EXPECT_NEAR(signed_volume(t), 1.0 / 6.0, 1e-16);
  EXPECT_NEAR(norm(centroid(t) - Vec3{0.25, 0.25, 0.25}), 0.0, 1e-16);
  const Sym3 I = inertia_tensor(t, 1.0);
  for (double v : {I.xx, I.yy, I.zz}) EXPECT_NEAR(v, 1.0 / 80.0, 1e-16);
  for (double v : {I.yz, I.xz, I.xy}) EXPECT_NEAR(v, 1.0 / 480.0, 1e-16);
  const Principal p = principal(I);
  EXPECT_NEAR(p.moments.x, 1.0 / 96.0, 1e-16);
  EXPECT_NEAR(p.moments.y, 1.0 / 96.0, 1e-16);
  EXPECT_NEAR(p.moments.z, 1.0 / 60.0, 1e-16);
  EXPECT_NEAR(std::abs(dot(p.axes.r[2], Vec3{1, 1, 1})) / std::sqrt(3.0), 1.0, 1e-14);
}

TEST(TetGeometry, RegularTetrahedronIsIsotropic) {
  // Edge a = 2 sqrt(2): V = a^3 / (6 sqrt(2)) = 8/3, I = m a^2 / 20 = (8/3) 8 / 20 = 16/15 about every axis.
  const Tet t{{{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}}};
  const TetBody b = tet_body(t, 1.0);
  EXPECT_NEAR(b.volume, 8.0 / 3.0, 1e-15);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(b.inertia.moments[k], 16.0 / 15.0, 1e-15);
}

TEST(TetGeometry, PrincipalMomentsAreInvariantAndAxesTurnWithTheBlock) {
  const Tet t{{{0.1, 0.0, 0.2}, {1.3, 0.2, -0.1}, {0.4, 0.8, 0.3}, {0.2, 0.3, 1.5}}};
  const Quat q = from_rotation_vector({-0.6, 1.4, 0.5});
  Tet r;
  for (std::size_t k = 0; k < 4; ++k) r[k] = rotate(q, t[k]) + Vec3{3, -1, 2};
  const TetBody a = tet_body(t, 2700.0), b = tet_body(r, 2700.0);
  EXPECT_NEAR(b.mass, a.mass, 1e-12 * a.mass);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(b.inertia.moments[k], a.inertia.moments[k], 1e-12 * a.inertia.moments[k]);
    EXPECT_NEAR(std::abs(dot(b.inertia.axes.r[k], rotate(q, a.inertia.axes.r[k]))), 1.0, 1e-12);
  }
  // The tensor in its axes is diagonal, and the axes' quaternion turns x, y, z into them.
  const Sym3 I = inertia_tensor(t, 2700.0);
  for (int k = 0; k < 3; ++k) {
    const Vec3 e = a.inertia.axes.r[k];
    EXPECT_LT(norm(I * e - a.inertia.moments[k] * e), 1e-12 * a.inertia.moments[2]);
    Vec3 unit;
    unit[k] = 1.0;
    EXPECT_LT(norm(rotate(a.inertia.rotation, unit) - e), 1e-14);
  }
}

// A torque-free asymmetric block, moments (1, 2, 3) kg m^2, principal axes turned from the world's; |omega| about 1
// rad/s, dt = 0.01 s: 1e5 steps, about 160 turns (verify::torque_free_run, which `rbdem verify` reports too).
TEST(RigidStep, TorqueFreeAsymmetricBlockKeepsMomentumExactlyAndEnergyToSecondOrder) {
  const double dt = 0.01;
  const long steps = 100000;
  for (const auto& [name, w] : {std::pair{"intermediate", Vec3{0.01, 1.0, 0.01}}, {"largest", Vec3{0.1, 0.1, 1.0}}}) {
    const verify::TorqueFreeMeasure a = verify::torque_free_run(w, dt, steps),
                                  h = verify::torque_free_run(w, 0.5 * dt, 2 * steps);
    std::printf("[ rigid3 ] %s axis: |dL|/|L| %.2e (dt/2: %.2e), energy spread %.2e (dt/2: %.2e), drift %.2e, "
                "||q|-1| %.1e\n", name, a.momentum_drift, h.momentum_drift, a.energy_spread, h.energy_spread,
                a.energy_drift, a.unit_error);
    // Each sub-rotation keeps L: what is left is the round-off of turning omega into L and back at every step,
    // which adds up to about 1e-16 per step.
    EXPECT_LT(a.momentum_drift, 1e-15 * double(steps)) << name;
    EXPECT_LT(h.momentum_drift, 1e-15 * double(2 * steps)) << name;
    EXPECT_LT(a.unit_error, 1e-14) << name;
    // Second order: the energy error is O((|omega| dt)^2) = O(1e-4) and falls by 4 with dt / 2 (3 to 5 allowed).
    EXPECT_LT(a.energy_spread, (1.0 * dt) * (1.0 * dt)) << name;
    EXPECT_GT(a.energy_spread / h.energy_spread, 3.0) << name;
    EXPECT_LT(a.energy_spread / h.energy_spread, 5.0) << name;
    // No drift: after 1e5 steps the energy is inside the band it oscillates in.
    EXPECT_LE(a.energy_drift, a.energy_spread) << name;
  }
}

TEST(RigidStep, SymmetricTopPrecessesAtTheClosedFormRate) {
  // I1 = I2 = 1, I3 = 2: the body-frame angular velocity turns about e3 at Omega = (I3 - I1) / I1 omega_3 while
  // omega_3 stays fixed (Euler's equations). Over T = 10 s the angle of (omega_1, omega_2) matches Omega T to
  // second order in dt.
  const RigidBody3 b{1.0, {1.0, 1.0, 2.0}, {}};
  auto phase_error = [&](double dt) {
    RigidState3 s;
    s.omega = {0.5, 0.0, 1.0};
    const long n = std::lround(10.0 / dt);
    for (long k = 0; k < n; ++k) rigid_step(b, s, {}, {}, dt, 0.0);
    const Vec3 wb = rotate_back(s.q * b.axes, s.omega);
    const double expected = 1.0 * 10.0;  // omega_b turns by +Omega t about e3
    return std::remainder(std::atan2(wb.y, wb.x) - expected, 2 * std::numbers::pi);
  };
  const double e1 = phase_error(0.01), e2 = phase_error(0.005);
  EXPECT_LT(std::abs(e1), 1e-3);
  EXPECT_NEAR(e1 / e2, 4.0, 0.5);
}

TEST(RigidStep, LocalDampingActsPerDegreeOfFreedom) {
  // A constant force along +x on a block moving along +x: F_d = -alpha |F| sign(v) gives (1 - alpha) F / m. A
  // constant moment about -z on a block turning about +z: (1 + alpha) M / I while it turns that way, (1 - alpha)
  // M / I once it turns the other way.
  const RigidBody3 b{2.0, {0.5, 0.5, 0.5}, {}};
  RigidState3 s;
  s.v = {1e-3, 0, 0}, s.omega = {0, 0, 1e-3};
  const double alpha = 0.7, dt = 1e-3, F = 4.0, M = -0.3;
  double work = 0;
  for (int n = 0; n < 10; ++n) work += rigid_step(b, s, {F, 0, 0}, {0, 0, M}, dt, alpha);
  EXPECT_NEAR(s.v.x, 1e-3 + 10 * dt * (1 - alpha) * F / 2.0, 1e-15);
  EXPECT_NEAR(s.v.y, 0.0, 1e-18);
  // omega_z goes negative during the run (1e-3 - n 1.7 x 0.3 / 0.5 x 1e-3): the damping flips with it.
  double w = 1e-3;
  for (int n = 0; n < 10; ++n) w += dt * (M - alpha * std::abs(M) * (w > 0 ? 1.0 : -1.0)) / 0.5;
  EXPECT_NEAR(s.omega.z, w, 1e-15);
  EXPECT_LT(work, 0.0);
}

// The 6x6 stiffness of block j bonded to a fixed block i, by central differences of the kernel's forces, in the
// stiffest state (the linear part closed: the pair pre-compressed).
Eigen::Matrix<double, 6, 6> bonded_stiffness(const stages::FaceBondFrame& f, Vec3 ci, Vec3 cj, Vec3 pre) {
  Eigen::Matrix<double, 6, 6> K;
  const double h = 1e-10;
  for (int c = 0; c < 6; ++c) {
    Eigen::Matrix<double, 6, 1> col;
    for (int side = -1; side <= 1; side += 2) {
      Vec3 dx, dr;
      (c < 3 ? dx : dr)[c % 3] = side * h;
      const stages::BlockKin3 I{ci, {}, {}, {}}, J{cj + pre + dx, from_rotation_vector(dr), {}, {}};
      const stages::FaceBondEval ev = stages::eval_face_bond(f, I, J, 0.0, 0, 0, 1.0);
      const Eigen::Matrix<double, 6, 1> g = (Eigen::Matrix<double, 6, 1>() << ev.f.x, ev.f.y, ev.f.z, ev.mj.x,
                                             ev.mj.y, ev.mj.z).finished();
      col = side < 0 ? Eigen::Matrix<double, 6, 1>(g) : Eigen::Matrix<double, 6, 1>(-(g - col) / (2 * h));
    }
    K.col(c) = col;
  }
  return 0.5 * (K + K.transpose());
}

TEST(CriticalStep3, BlockEstimateIsBelowTheExactLimitOfABondedBlock) {
  const Tri face{{{0, 0, 0}, {1e-3, 0.1e-3, 0}, {0.2e-3, 0.9e-3, 0.1e-3}}};
  const Vec3 apex_i{0.3e-3, 0.3e-3, -0.9e-3}, apex_j{0.4e-3, 0.2e-3, 0.8e-3};
  const Tet ti{{face[0], face[1], face[2], apex_i}}, tj{{face[0], face[1], face[2], apex_j}};
  const TetBody bi = tet_body(ti, 2700.0), bj = tet_body(tj, 2700.0);
  const FaceBond law{1.0 / 2.5, {}, 0.0};
  const stages::FaceBondFrame f = stages::face_bond_frame(bi.centroid, bj.centroid, face, law, 10e9, 0.6);
  const Eigen::Matrix<double, 6, 6> K = bonded_stiffness(f, bi.centroid, bj.centroid, -1e-8 * f.axes.r[2]);
  // M^-1/2 K M^-1/2 with M = diag(m, m, m, I_world).
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const Vec3 e = bj.inertia.axes.r[k];
    const Eigen::Vector3d v(e.x, e.y, e.z);
    I += bj.inertia.moments[k] * v * v.transpose();
  }
  Eigen::Matrix<double, 6, 6> Minv_half = Eigen::Matrix<double, 6, 6>::Zero();
  Minv_half.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() / std::sqrt(bj.mass);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> ie(I);
  Minv_half.bottomRightCorner<3, 3>() = ie.eigenvectors() * ie.eigenvalues().cwiseInverse().cwiseSqrt().asDiagonal() *
                                        ie.eigenvectors().transpose();
  const Eigen::Matrix<double, 6, 6> A = Minv_half * K * Minv_half;
  const double lambda = Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>(A).eigenvalues().maxCoeff();
  const double exact = 2.0 / std::sqrt(lambda);
  // The estimate: the parallel bond and the closed linear part (the same K_n, K_s) on block j.
  BlockStiffness3 k;
  k.add(2 * f.k.kn, 2 * f.k.ks, std::max({f.k.kb1, f.k.kb2, f.k.kt}), f.rj, f.axes.r[2]);
  const double estimate = k.critical_step({bj.mass, bj.inertia.moments, bj.inertia.rotation});
  std::printf("[ rigid3 ] critical step: estimate %.4e s, exact %.4e s, ratio %.3f\n", estimate, exact,
              estimate / exact);
  EXPECT_LT(estimate, exact);
  EXPECT_GT(estimate, 0.1 * exact);  // conservative, not useless
  // The step itself has the central difference's limit: under the linearised bond, undamped, a motion started
  // in every mode stays bounded at 0.98 dt_crit and grows without bound at 1.02 dt_crit.
  const RigidBody3 body{bj.mass, bj.inertia.moments, bj.inertia.rotation};
  auto growth = [&](double dt) {
    RigidState3 s;
    s.v = {1e-6, -2e-6, 3e-6}, s.omega = {1e-3, 2e-3, -1e-3};
    double early = 0, late = 0;
    for (int n = 0; n < 400; ++n) {
      const Vec3 r = rotation_vector(s.q);
      Eigen::Matrix<double, 6, 1> u;
      u << s.x.x, s.x.y, s.x.z, r.x, r.y, r.z;
      const Eigen::Matrix<double, 6, 1> load = -K * u;
      rigid_step(body, s, {load(0), load(1), load(2)}, {load(3), load(4), load(5)}, dt, 0.0);
      (n < 100 ? early : late) = std::max(n < 100 ? early : late, std::abs(dot(s.v, s.v) * bj.mass));
    }
    return late / early;
  };
  const double below = growth(0.98 * exact), above = growth(1.02 * exact);
  std::printf("[ rigid3 ] kinetic energy growth over 400 steps: %.2g at 0.98 dt_crit, %.2g at 1.02 dt_crit\n", below,
              above);
  EXPECT_LT(below, 100.0);
  EXPECT_GT(above, 1e6);
}

}  // namespace
}  // namespace rbdem
