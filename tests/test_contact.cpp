// Polygon overlap geometry and the contact laws against closed forms (THEORY.md 4, 4b).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "dem/contact_geometry.hpp"
#include "dem/contact_law.hpp"

namespace rbdem {
namespace {

// Counter-clockwise square of side a centred at (cx, cy), rotated by angle q.
std::array<double, 8> square(double cx, double cy, double a, double q = 0.0) {
  std::array<double, 8> v{};
  const double h = 0.5 * a, c = std::cos(q), s = std::sin(q);
  const double lx[4] = {-h, h, h, -h}, ly[4] = {-h, -h, h, h};
  for (int k = 0; k < 4; ++k) v[2 * k] = cx + c * lx[k] - s * ly[k], v[2 * k + 1] = cy + s * lx[k] + c * ly[k];
  return v;
}

TEST(Overlap, EdgeToEdgeGivesLTimesDeltaWithNormalAlongTheAxis) {
  const double a = 1e-3, delta = 2e-6;
  const auto A = square(0, 0, a), B = square(a - delta, 0, a);  // B pushed into A by delta along x
  Overlap o;
  ASSERT_TRUE(overlap_polygons(A.data(), 4, B.data(), 4, o));
  EXPECT_NEAR(o.area, a * delta, 1e-12 * a * delta);
  EXPECT_NEAR(o.chord, a, 1e-12 * a);
  EXPECT_NEAR(o.nx, -1.0, 1e-12);  // from B into A
  EXPECT_NEAR(o.ny, 0.0, 1e-12);
  EXPECT_NEAR(o.px, 0.5 * a - 0.5 * delta, 1e-12 * a);
  EXPECT_NEAR(o.py, 0.0, 1e-12 * a);
}

TEST(Overlap, VertexIntoEdgeGrowsWithDeltaSquared) {
  // A square corner (90 degrees) pushed into a flat face: A_o = delta^2 (a right isosceles triangle of height delta
  // has area delta^2), chord 2 delta.
  const double a = 1e-3;
  for (double delta : {1e-6, 2e-6, 4e-6}) {
    const auto A = square(0, 0, a);
    const auto B = square(0.5 * a + a / std::sqrt(2.0) - delta, 0, a, std::numbers::pi / 4);  // corner towards A
    Overlap o;
    ASSERT_TRUE(overlap_polygons(A.data(), 4, B.data(), 4, o));
    EXPECT_NEAR(o.area, delta * delta, 1e-6 * delta * delta);
    EXPECT_NEAR(o.chord, 2 * delta, 1e-6 * delta);
    EXPECT_NEAR(o.nx, -1.0, 1e-9);
  }
}

TEST(Overlap, VertexToVertexNeedsNoSpecialCase) {
  const double a = 1e-3, delta = 1e-6;
  const double r = a / std::sqrt(2.0);
  const auto A = square(0, 0, a, std::numbers::pi / 4);            // corner at (r, 0)
  const auto B = square(2 * r - delta, 0, a, std::numbers::pi / 4);  // corner at (r - delta, 0)
  Overlap o;
  ASSERT_TRUE(overlap_polygons(A.data(), 4, B.data(), 4, o));
  EXPECT_NEAR(o.area, 0.5 * delta * delta, 1e-6 * delta * delta);  // a small square of diagonal delta
  EXPECT_NEAR(o.nx, -1.0, 1e-9);
  EXPECT_NEAR(o.px, r - 0.5 * delta, 1e-9 * a);
}

TEST(Overlap, CollinearSidesAreCountedOnce) {
  // Two blocks side by side on the same platen line, pushed together: their bottom edges are collinear.
  const double a = 1e-3, delta = 1e-6;
  const double A[6] = {0, 0, a, 0, 0, a};               // right triangle, hypotenuse facing +x
  const double B[6] = {a - delta, 0, 2 * a, 0, 2 * a, a};  // its mirror, overlapping A's corner region
  Overlap o;
  ASSERT_TRUE(overlap_polygons(A, 3, B, 3, o));
  // Overlap: the triangle on y = 0 from x = a - delta to x = a, apex where A's hypotenuse x + y = a meets B's
  // side y = s (x - a + delta), s = a / (a + delta): height delta s / (1 + s). Counting the shared base twice
  // would add the base's Green term again.
  const double s = a / (a + delta), height = delta * s / (1 + s);
  EXPECT_NEAR(o.area, 0.5 * delta * height, 1e-9 * delta * delta);
}

TEST(Overlap, SeparatedAndTouchingPolygonsHaveNoOverlap) {
  const double a = 1e-3;
  Overlap o;
  const auto A = square(0, 0, a);
  const auto B = square(a + 1e-9, 0, a), C = square(a, 0, a);
  EXPECT_FALSE(overlap_polygons(A.data(), 4, B.data(), 4, o));
  EXPECT_FALSE(overlap_polygons(A.data(), 4, C.data(), 4, o));  // a shared edge at rest carries no force
}

TEST(Overlap, InvariantUnderRigidMotionOfBoth) {
  const double a = 1e-3, delta = 3e-6;
  const double tri_a[6] = {0, 0, a, 0, 0.3 * a, 0.8 * a};
  const double tri_b[6] = {0.9 * a, -0.2 * a, 1.4 * a, 0.6 * a, 0.45 * a, 0.5 * a - delta};
  Overlap o0;
  ASSERT_TRUE(overlap_polygons(tri_a, 3, tri_b, 3, o0));
  const double q = 1.0, c = std::cos(q), s = std::sin(q), tx = 0.37, ty = -1.2;
  double ra[6], rb[6];
  for (int k = 0; k < 3; ++k) {
    ra[2 * k] = tx + c * tri_a[2 * k] - s * tri_a[2 * k + 1], ra[2 * k + 1] = ty + s * tri_a[2 * k] + c * tri_a[2 * k + 1];
    rb[2 * k] = tx + c * tri_b[2 * k] - s * tri_b[2 * k + 1], rb[2 * k + 1] = ty + s * tri_b[2 * k] + c * tri_b[2 * k + 1];
  }
  Overlap o1;
  ASSERT_TRUE(overlap_polygons(ra, 3, rb, 3, o1));
  EXPECT_NEAR(o1.area, o0.area, 1e-6 * o0.area);
  EXPECT_NEAR(o1.chord, o0.chord, 1e-6 * o0.chord);
  EXPECT_NEAR(o1.nx, c * o0.nx - s * o0.ny, 1e-6);
  EXPECT_NEAR(o1.ny, s * o0.nx + c * o0.ny, 1e-6);
  EXPECT_NEAR(o1.px, tx + c * o0.px - s * o0.py, 1e-9 * a);
  EXPECT_NEAR(o1.py, ty + s * o0.px + c * o0.py, 1e-9 * a);
}

TEST(Overlap, HalfPlaneCutsTheEdgeBelowThePlaten) {
  const double a = 1e-3, delta = 5e-7;
  const auto A = square(0, 0, a);
  Overlap o;
  ASSERT_TRUE(overlap_halfplane(A.data(), 4, 0.0, 0.5 * a - delta, 0.0, 1.0, o));
  EXPECT_NEAR(o.area, a * delta, 1e-9 * a * delta);
  EXPECT_NEAR(o.chord, a, 1e-9 * a);
  EXPECT_NEAR(o.ny, 1.0, 1e-12);
  EXPECT_NEAR(o.px, 0.0, 1e-12);
  EXPECT_FALSE(overlap_halfplane(A.data(), 4, 0.0, 0.5 * a, 0.0, 1.0, o));
}

TEST(EdgeOverlap, FullyCompressedEdgeGivesLTimesDelta) {
  const EdgeOverlap e = edge_overlap(2e-3, -1e-6, 1e-4);  // rotation small enough to keep the edge closed
  EXPECT_NEAR(e.area, 2e-9, 1e-21);
  EXPECT_EQ(e.chord, 2e-3);
  EXPECT_EQ(e.s_c, 0.0);
}

TEST(EdgeOverlap, PartlyOpenEdgeIsATriangleOfTheCompressedPart) {
  // u(s) = -dn + s dth: with dn = 0 and dth > 0 the half s > 0 is compressed, area = dth L^2 / 8.
  const double L = 2e-3, dth = 1e-3;
  const EdgeOverlap e = edge_overlap(L, 0.0, dth);
  EXPECT_NEAR(e.area, dth * L * L / 8, 1e-18);
  EXPECT_NEAR(e.chord, L / 2, 1e-15);
  EXPECT_NEAR(e.s_c, L / 4, 1e-15);
  const EdgeOverlap f = edge_overlap(L, 0.0, -dth);
  EXPECT_NEAR(f.s_c, -L / 4, 1e-15);
  EXPECT_EQ(edge_overlap(L, 1e-6, 0.0).area, 0.0);  // open edge: no linear force (no tension)
}

TEST(ParallelBond, BreaksInTensionAtSigmaC) {
  const BondStrength st{10e6, 50e6, std::tan(0.5), 1.0};
  const double A = 1e-3, I = 1e-10, R = 5e-4;
  double sigma, tau;
  EXPECT_EQ(st.check(-10e6 * A * (1 - 1e-12), 0, 0, A, I, R, sigma, tau), BreakMode::none);
  EXPECT_EQ(st.check(-10e6 * A, 0, 0, A, I, R, sigma, tau), BreakMode::tensile);
  EXPECT_DOUBLE_EQ(sigma, 10e6);
}

TEST(ParallelBond, ShearStrengthRisesWithCompressionAsCMinusSigmaTanPhi) {
  const double c = 20e6, phi = 30.0 * std::numbers::pi / 180, A = 1e-3, I = 1e-10, R = 5e-4;
  const BondStrength st{5e6, c, std::tan(phi), 1.0};
  for (double sn : {-40e6, -10e6, 0.0, 2e6}) {  // sigma_n, tension positive
    const double strength = c - sn * std::tan(phi);
    double sigma, tau;
    EXPECT_EQ(st.check(-sn * A, strength * A * (1 - 1e-9), 0, A, I, R, sigma, tau), BreakMode::none) << sn;
    EXPECT_EQ(st.check(-sn * A, strength * A * (1 + 1e-9), 0, A, I, R, sigma, tau), BreakMode::shear) << sn;
  }
}

TEST(ParallelBond, MomentAddsBetaTimesMROverIToTheTensileStress) {
  const double A = 1e-3, L = 1e-3, t = 1.0, I = t * L * L * L / 12, R = L / 2;
  for (double beta_m : {1.0, 0.5}) {
    const BondStrength st{10e6, 1e12, 0.0, beta_m};
    const double M = 2.0;  // N m
    double sigma, tau;
    st.check(-1e3, 0.0, M, A, I, R, sigma, tau);
    EXPECT_NEAR(sigma, 1e3 / A + beta_m * M * R / I, 1e-6);
    st.check(-1e3, 0.0, -M, A, I, R, sigma, tau);  // either sign of the moment opens one side
    EXPECT_NEAR(sigma, 1e3 / A + beta_m * M * R / I, 1e-6);
  }
}

TEST(LinearContact, SlidesExactlyAtMuFn) {
  const LinearContact law{1e14, 1e14, 0.5, 1e-3};
  double fs = 0;
  EXPECT_FALSE(law.update_shear(100.0, 1e-3, 1.0, -4.9e-10, fs));  // ks t l ds = 49 N < mu F_n = 50 N
  EXPECT_NEAR(fs, 49.0, 1e-9);
  EXPECT_TRUE(law.update_shear(100.0, 1e-3, 1.0, -2e-11, fs));
  EXPECT_DOUBLE_EQ(fs, 50.0);
  EXPECT_FALSE(law.update_shear(0.0, 1e-3, 1.0, -1e-12, fs));  // no normal force, no shear force
  EXPECT_EQ(fs, 0.0);
}

}  // namespace
}  // namespace rbdem
