// Polygon overlap geometry against closed forms (docs/theory.md, section 7). The laws are tested in test_laws.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "dem/contact_geometry.hpp"

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

}  // namespace
}  // namespace rbdem
