// The tetrahedron-tetrahedron narrow phase (dem/contact3.hpp; docs/theory.md, section 11.9): closed-form overlaps
// (a corner tetrahedron and its translate, a vertex into a face, a face pressed into a face, two edges crossing,
// two faces touching), the contact normal of a face-on contact under round-off, the linear contact law on it, and
// property tests over random poses: the overlap volume against an independent exact computation (vertex
// enumeration of the eight half-spaces, not clipping), the area vector against the volume's derivative in a
// translation, the point of action against its derivative in a rotation, the exchange of i and j, and no NaN over
// degenerate pairs.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "dem/contact3.hpp"
#include "dem/laws/face_bond.hpp"
#include "dem/laws/linear_contact.hpp"

namespace {

using rbdem::ContactAxis;
using rbdem::contact_tets;
using rbdem::Tet;
using rbdem::TetContact;
using rbdem::Vec3;

const Tet kCorner{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};  // the unit corner tetrahedron, volume 1/6

Tet moved(const Tet& t, Vec3 d) {
  Tet m = t;
  for (Vec3& p : m) p += d;
  return m;
}

void expect_near(Vec3 a, Vec3 b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// --- An independent overlap volume: the vertices of the eight half-spaces' intersection, face by face ----------

struct HalfSpace {
  Vec3 m;
  double h;
};

void add_half_spaces(const Tet& t, std::vector<HalfSpace>& out) {
  const Vec3 c = rbdem::centroid(t);
  for (int k = 0; k < 4; ++k) {
    const Vec3 a = t[(k + 1) % 4], b = t[(k + 2) % 4], d = t[(k + 3) % 4];
    Vec3 n = rbdem::cross(b - a, d - a);
    if (rbdem::dot(n, c - a) > 0) n = -n;  // outward
    n = (1.0 / rbdem::norm(n)) * n;
    out.push_back({n, rbdem::dot(n, a)});
  }
}

// Every feasible intersection point of three planes; each plane's points sorted by angle and fanned to the mean
// of all points. Exact for a non-degenerate intersection.
double volume_by_vertices(const Tet& i, const Tet& j) {
  std::vector<HalfSpace> H;
  add_half_spaces(i, H);
  add_half_spaces(j, H);
  std::vector<Vec3> verts;
  for (int a = 0; a < 8; ++a)
    for (int b = a + 1; b < 8; ++b)
      for (int c = b + 1; c < 8; ++c) {
        const Vec3 bc = rbdem::cross(H[b].m, H[c].m), ca = rbdem::cross(H[c].m, H[a].m),
                   ab = rbdem::cross(H[a].m, H[b].m);
        const double det = rbdem::dot(H[a].m, bc);
        if (std::abs(det) < 1e-9) continue;
        const Vec3 x = (1.0 / det) * ((H[a].h * bc + H[b].h * ca) + H[c].h * ab);
        bool in = true;
        for (const HalfSpace& s : H) in = in && rbdem::dot(s.m, x) <= s.h + 1e-10;
        if (in) verts.push_back(x);
      }
  if (verts.size() < 4) return 0.0;
  Vec3 o;
  for (const Vec3& v : verts) o += v;
  o = (1.0 / double(verts.size())) * o;
  double volume = 0;
  for (const HalfSpace& s : H) {
    std::vector<Vec3> f;
    for (const Vec3& v : verts)
      if (std::abs(rbdem::dot(s.m, v) - s.h) < 1e-9) f.push_back(v);
    if (f.size() < 3) continue;
    Vec3 fc;
    for (const Vec3& v : f) fc += v;
    fc = (1.0 / double(f.size())) * fc;
    const Vec3 u = rbdem::norm(rbdem::cross(s.m, {1, 0, 0})) > 0.5 ? rbdem::cross(s.m, {1, 0, 0})
                                                                    : rbdem::cross(s.m, {0, 1, 0});
    const Vec3 e1 = (1.0 / rbdem::norm(u)) * u, e2 = rbdem::cross(s.m, e1);
    std::sort(f.begin(), f.end(), [&](Vec3 p, Vec3 q) {
      return std::atan2(rbdem::dot(p - fc, e2), rbdem::dot(p - fc, e1)) <
             std::atan2(rbdem::dot(q - fc, e2), rbdem::dot(q - fc, e1));
    });
    for (std::size_t k = 0; k < f.size(); ++k) {
      const Vec3 p = f[k] - o, q = f[(k + 1) % f.size()] - o;
      volume += std::abs(rbdem::dot(fc - o, rbdem::cross(p, q))) / 6.0;
    }
  }
  return volume;
}

// A random tetrahedron of edges about `size` near `at`, positive, with a volume of at least 1 % of size^3.
Tet random_tet(std::mt19937_64& rng, Vec3 at, double size) {
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (;;) {
    Tet t;
    for (Vec3& p : t) p = at + size * Vec3{u(rng), u(rng), u(rng)};
    const double v = rbdem::signed_volume(t);
    if (std::abs(v) < 0.01 * size * size * size) continue;
    if (v < 0) std::swap(t[1], t[2]);
    return t;
  }
}

std::string sci(double x) {
  char s[32];
  std::snprintf(s, sizeof s, "%.3e", x);
  return s;
}

double overlap_volume(const Tet& i, const Tet& j) {
  TetContact c;
  return contact_tets(i, j, c) ? c.volume : 0.0;
}

// --- Closed forms -----------------------------------------------------------------------------------------------

// The corner tetrahedron and its translate by t along x overlap in the corner tetrahedron scaled by 1 - t; the
// least translation apart is along the slanted face's normal (1, 1, 1)/sqrt(3), by (1 - t)/sqrt(3).
TEST(ContactTets, CornerTetrahedronAndItsTranslateOverlapInAScaledCopy) {
  for (double t : {0.1, 0.35, 0.8}) {
    TetContact c;
    ASSERT_TRUE(contact_tets(kCorner, moved(kCorner, {t, 0, 0}), c));
    EXPECT_NEAR(c.volume, std::pow(1 - t, 3) / 6.0, 1e-14);
    EXPECT_NEAR(c.depth, (1 - t) / std::sqrt(3.0), 1e-14);
    expect_near(c.axis, (1 / std::sqrt(3.0)) * Vec3{1, 1, 1}, 1e-14);
    EXPECT_EQ(c.axis_kind, ContactAxis::face_i);
    EXPECT_EQ(c.axis_index, 0);
    // The overlap's centroid: the scaled copy's, (t + (1 - t)/4, (1 - t)/4, (1 - t)/4).
    const double q = (1 - t) / 4;
    expect_near(c.centroid, {t + q, q, q}, 1e-14);
  }
  TetContact c;
  EXPECT_FALSE(contact_tets(kCorner, moved(kCorner, {1.001, 0, 0}), c));
  EXPECT_TRUE(contact_tets(kCorner, moved(kCorner, {1.0, 0, 0}), c));  // a vertex on a vertex: touching
  EXPECT_EQ(c.volume, 0.0);
}

// A vertex of j a depth d into i's face z = 0: the overlap is j's tip, similar to j with the ratio d / h (h: j's
// height over that vertex), so V = V_j (d/h)^3 and the contact area, j's section in the face, A_b (d/h)^2.
TEST(ContactTets, VertexIntoAFaceCutsASimilarTip) {
  const Tet i{{{10, 0, 0}, {-5, 9, 0}, {-5, -9, 0}, {0, 0, -10}}};  // top face z = 0
  const double h = 1.0, a = 0.6;
  for (double d : {1e-6, 1e-3, 0.05, 0.3}) {
    const Tet j{{{0, 0, -d}, {a, 0, h - d}, {-0.5 * a, a, h - d}, {-0.5 * a, -a, h - d}}};
    const double base = 0.5 * 1.5 * a * 2 * a, vj = base * h / 3, r = d / h;
    TetContact c;
    ASSERT_TRUE(contact_tets(i, j, c));
    // Round-off: the vertices are rounded to eps of the pair's extent E = 20, the tip is d across.
    const double tol = 64 * std::numeric_limits<double>::epsilon() * 20 / d;
    EXPECT_NEAR(c.volume / (vj * r * r * r), 1.0, tol);
    EXPECT_NEAR(c.area / (base * r * r), 1.0, tol);
    EXPECT_NEAR(c.depth, d, 1e-14);
    expect_near(c.normal, {0, 0, 1}, 1e-12);
    expect_near(c.axis, {0, 0, 1}, 0.0);
    // The tip's centroid, 3/4 of the way from the vertex to the section, on the axis x = y = 0 of j's base.
    expect_near(c.centroid, {0, 0, -0.25 * d}, 1e-12 * (1 + d));
    // A planar crossing curve: the force acts on the vertical through the centroid.
    EXPECT_NEAR(c.point.x, 0, 1e-12);
    EXPECT_NEAR(c.point.y, 0, 1e-12);
  }
}

// Two edges crossing at right angles, j's edge a depth d below i's: the overlap {-d + |x| <= z <= -|y|} has the
// volume 2 d^3 / 3, and each body's boundary inside the other projects on the diamond |x| + |y| <= d: S = 2 d^2 z.
TEST(ContactTets, CrossedEdgesOverlapInAPyramidPair) {
  const Tet i{{{-1, 0, 0}, {1, 0, 0}, {0, 1, -1}, {0, -1, -1}}};
  for (double d : {1e-4, 0.01, 0.1}) {
    const Tet j{{{0, -1, -d}, {0, 1, -d}, {1, 0, 1 - d}, {-1, 0, 1 - d}}};
    TetContact c;
    ASSERT_TRUE(contact_tets(i, j, c));
    EXPECT_NEAR(c.volume / (2 * d * d * d / 3), 1.0, 1e-10);
    EXPECT_NEAR(c.area / (2 * d * d), 1.0, 1e-10);
    EXPECT_NEAR(c.depth, d, 1e-14);
    EXPECT_EQ(c.axis_kind, ContactAxis::edge_edge);
    expect_near(c.normal, {0, 0, 1}, 1e-12);
    expect_near(c.axis, {0, 0, 1}, 1e-15);
    expect_near(c.point, {0, 0, -0.5 * d}, 1e-12);
  }
  // Apart by a gap g only an edge-edge axis shows it: every face normal sees the projections overlap.
  const double g = 1e-3;
  const Tet j{{{0, -1, g}, {0, 1, g}, {1, 0, 1 + g}, {-1, 0, 1 + g}}};
  TetContact c;
  EXPECT_FALSE(contact_tets(i, j, c));
}

// The unit cube as six Kuhn tetrahedra (0, e_a, e_a + e_b, (1, 1, 1) for each order a, b, c of the axes). They tile
// the cube, so two of them overlap in no volume, and the overlaps of the tetrahedra of the cube and of its
// translate by t sum to the cubes' overlap (1 - t_x)(1 - t_y)(1 - t_z). A translate along an axis puts many faces
// of the two cubes in one plane, with the same or the opposite outward side.
TEST(ContactTets, KuhnTetrahedraOfTwoUnitCubesOverlapAsTheCubes) {
  std::vector<Tet> cube;
  const int order[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& o : order) {
    Vec3 a, b;
    a[o[0]] = 1;
    b = a;
    b[o[1]] = 1;
    cube.push_back({Vec3{0, 0, 0}, a, b, Vec3{1, 1, 1}});
  }
  for (std::size_t a = 0; a < 6; ++a)
    for (std::size_t b = a + 1; b < 6; ++b) EXPECT_NEAR(overlap_volume(cube[a], cube[b]), 0.0, 1e-16);
  for (const Vec3 t : {Vec3{0.3, 0.2, 0.1}, Vec3{0.3, 0, 0}, Vec3{0, 0.5, 0.25}, Vec3{0, 0, 0}}) {
    double sum = 0;
    for (const Tet& i : cube)
      for (const Tet& j : cube) sum += overlap_volume(i, moved(j, t));
    EXPECT_NEAR(sum, (1 - t.x) * (1 - t.y) * (1 - t.z), 1e-14) << t.x << " " << t.y << " " << t.z;
  }
}

// Two faces touching: no volume, the contact area is the face's, the normal the face's from i to j.
TEST(ContactTets, CoincidentFacesTouchOverTheWholeFace) {
  const Tet j{{{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0, -1}}};  // the corner tetrahedron mirrored in z = 0
  TetContact c;
  ASSERT_TRUE(contact_tets(kCorner, j, c));
  EXPECT_NEAR(c.volume, 0.0, 1e-16);
  EXPECT_NEAR(c.area, 0.5, 1e-15);
  EXPECT_EQ(c.depth, 0.0);
  expect_near(c.normal, {0, 0, -1}, 1e-15);
  expect_near(c.axis, {0, 0, -1}, 0.0);
  expect_near(c.point, {1.0 / 3, 1.0 / 3, 0}, 1e-15);
  // A face of j inside i's face: the area is j's face.
  const Tet small{{{0.2, 0.2, 0}, {0.2, 0.4, 0}, {0.4, 0.2, 0}, {0.3, 0.3, -1}}};
  ASSERT_TRUE(contact_tets(kCorner, small, c));
  EXPECT_NEAR(c.area, 0.02, 1e-15);
  expect_near(c.normal, {0, 0, -1}, 1e-15);
}

// j's face pressed a depth d into i's face z = 0, from below: the overlap is the top of j between its face and
// z = 0, a frustum, and the contact area j's section at z = 0. The linear contact law's force
// K V A_c / A^2 (K = k_n A) tends to the closed face's k_n A d as d -> 0.
TEST(ContactTets, FacePressedIntoAFaceGivesTheFrustumAndTheLinearLaw) {
  const double H = 1.0, A = 0.5 * 0.3 * 0.3;
  const double kn = 2e12;
  const rbdem::LinearContact law{kn * A, 0.5 * kn * A, 0.6, 1.0 / A};
  for (double d : {1e-8, 1e-5, 1e-3, 0.05}) {
    const Tet j{{{0.2, 0.2, d}, {0.2, 0.5, d}, {0.5, 0.2, d}, {0.3, 0.3, d - H}}};
    TetContact c;
    ASSERT_TRUE(contact_tets(kCorner, j, c));
    const double x = d / H, r = 1 - x, vj = A * H / 3;  // j below z = 0 is j scaled by r about its apex
    EXPECT_NEAR(c.volume / (vj * x * (3 - 3 * x + x * x)), 1.0, 1e-12);  // vj (1 - r^3)
    EXPECT_NEAR(c.area / (A * r * r), 1.0, 1e-12);
    EXPECT_NEAR(c.depth, d, 1e-15);
    EXPECT_EQ(c.axis_kind, ContactAxis::face_i);
    expect_near(c.normal, {0, 0, -1}, 1e-12);
    const double fn = law.normal_force(c.volume, c.area);
    EXPECT_NEAR(fn / (kn * A * d), r * r * (3 - 3 * x + x * x) / 3, 1e-12);
    // The face bond's linear part on a closed face of the same area, k_n A d, is the limit d -> 0: the ratio is
    // (1 - x)^2 (1 - x + x^2 / 3) >= 1 - 3 x.
    const rbdem::FaceOverlap closed{d * A, A, 0.0, 0.0};
    EXPECT_NEAR(fn / rbdem::face_linear_part(law, closed, 0, 0, 0, 0, 0).fn, 1.0, 3 * x + 1e-12);
  }
}

// --- Stability of a face-on contact -----------------------------------------------------------------------------

// j's face on i's face, exactly or off by round-off either way, or pressed in: the axis stays i's face normal,
// bit for bit, though edge pairs of the two faces give the same direction and the same depth. The normal S/|S|
// turns continuously: j's face pressed a depth d in overhangs i's slanted face, so strips of height d along the
// face's perimeter P add to S across it, by at most P d against the face's area A.

TEST(ContactTets, FaceOnContactKeepsTheFaceNormalUnderRoundOff) {
  const Tet base{{{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {0.2, 0.3, -1}}};
  for (double d : {0.0, 1e-16, -1e-16, 3e-15, -3e-15, 1e-13, 1e-10, 1e-7, 1e-4}) {
    const Tet j = moved(base, {0, 0, d});
    TetContact c;
    ASSERT_TRUE(contact_tets(kCorner, j, c)) << d;
    EXPECT_EQ(c.axis_kind, ContactAxis::face_i) << d;
    EXPECT_EQ(c.axis_index, 3) << d;
    EXPECT_EQ(c.axis.x, 0.0);
    EXPECT_EQ(c.axis.y, 0.0);
    EXPECT_EQ(c.axis.z, -1.0);
    const double perimeter = 2 + std::sqrt(2.0), area = 0.5;
    expect_near(c.normal, {0, 0, -1}, perimeter * std::abs(d) / area + 1e-15);
    EXPECT_NEAR(c.depth, std::max(d, 0.0), 1e-15);
  }
}

// --- Properties over random poses -------------------------------------------------------------------------------

// The overlap volume agrees with the eight half-spaces' vertex enumeration, a different algorithm (no clipping),
// to round-off; exchanging i and j keeps the volume, the area, the depth and the point and turns the normal.
TEST(ContactTets, RandomPosesMatchAnIndependentOverlapVolume) {
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  int overlapping = 0;
  double worst = 0;
  for (int n = 0; n < 3000; ++n) {
    const Tet i = random_tet(rng, {0, 0, 0}, 1.0), j = random_tet(rng, {u(rng), u(rng), u(rng)}, 1.0);
    TetContact a, b;
    const bool ab = contact_tets(i, j, a), ba = contact_tets(j, i, b);
    ASSERT_EQ(ab, ba);
    const double exact = volume_by_vertices(i, j);
    if (!ab) {
      EXPECT_EQ(exact, 0.0);
      continue;
    }
    const double scale = std::min(rbdem::signed_volume(i), rbdem::signed_volume(j));
    EXPECT_NEAR(a.volume, b.volume, 1e-12 * scale);
    EXPECT_NEAR(a.volume, exact, 1e-10 * std::max(exact, 1e-3 * scale)) << n;
    worst = std::max(worst, std::abs(a.volume - exact) / std::max(exact, 1e-3 * scale));
    EXPECT_NEAR(a.area, b.area, 1e-12);
    EXPECT_NEAR(a.depth, b.depth, 1e-12);
    expect_near(a.normal, -b.normal, 1e-9);
    expect_near(a.point, b.point, 1e-9);
    overlapping += a.volume > 1e-3 * scale;
  }
  EXPECT_GT(overlapping, 500);  // the sample exercises real overlaps
  RecordProperty("worst_relative_volume_error", sci(worst));
  RecordProperty("overlapping", overlapping);
}

// S = (S_i - S_j)/2 is the gradient of V in a translation of i (and minus that of j), and the force n |S| at the
// point of action has the moments of V's gradient in a rotation of j, about the axes normal to n.
TEST(ContactTets, AreaVectorAndPointAreTheVolumesDerivatives) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  const double h = 1e-6;
  int checked = 0;
  for (int n = 0; n < 4000 && checked < 150; ++n) {
    const Tet i = random_tet(rng, {0, 0, 0}, 1.0), j = random_tet(rng, {u(rng), u(rng), u(rng)}, 1.0);
    TetContact c;
    // Shallow overlaps, the contact regime (a deep, nearly engulfing overlap puts its point at the centroid).
    if (!contact_tets(i, j, c) || c.depth > 0.05 || c.volume < 1e-7) continue;
    ++checked;
    const Vec3 S = c.area * c.normal;
    for (int k = 0; k < 3; ++k) {
      Vec3 e;
      e[k] = h;
      const double dv = (overlap_volume(i, moved(j, e)) - overlap_volume(i, moved(j, -e))) / (2 * h);
      EXPECT_NEAR(dv, -S[k], 1e-6) << n;
    }
    // Rotations of j by +-phi about an axis e normal to n through the origin.
    const Vec3 t = std::abs(c.normal.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 e1 = (1.0 / rbdem::norm(rbdem::cross(c.normal, t))) * rbdem::cross(c.normal, t);
    for (const Vec3 e : {e1, rbdem::cross(c.normal, e1)}) {
      auto turned = [&](double phi) {
        const rbdem::Quat q = rbdem::from_rotation_vector(phi * e);
        Tet r = j;
        for (Vec3& p : r) p = rbdem::rotate(q, p);
        return overlap_volume(i, r);
      };
      const double dv = (turned(h) - turned(-h)) / (2 * h);
      EXPECT_NEAR(dv, -rbdem::dot(e, rbdem::cross(c.point, S)), 1e-6) << n;
    }
  }
  EXPECT_GT(checked, 50);
  RecordProperty("checked", checked);
}

// The same pair anywhere: translated far away and turned, the volume and the area move by round-off only.
TEST(ContactTets, RigidMotionOfThePairKeepsTheContact) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  const rbdem::Quat q = rbdem::from_rotation_vector({0.3, -1.1, 0.7});
  const Vec3 shift{1e3, -2e3, 5e2};
  for (int n = 0; n < 200; ++n) {
    const Tet i = random_tet(rng, {0, 0, 0}, 1.0), j = random_tet(rng, {u(rng), u(rng), u(rng)}, 1.0);
    Tet ri = i, rj = j;
    for (Vec3& p : ri) p = rbdem::rotate(q, p) + shift;
    for (Vec3& p : rj) p = rbdem::rotate(q, p) + shift;
    TetContact a, b;
    const bool ab = contact_tets(i, j, a);
    if (!ab || a.volume < 1e-6) continue;
    ASSERT_TRUE(contact_tets(ri, rj, b));
    EXPECT_NEAR(a.volume, b.volume, 1e-9);
    EXPECT_NEAR(a.area, b.area, 1e-9);
    expect_near(rbdem::rotate(q, a.normal), b.normal, 1e-8);
    expect_near(rbdem::rotate(q, a.point) + shift, b.point, 1e-8);
  }
}

// A pair of tetrahedra drawn from a small lattice: coincident, flat, sliver and touching ones are common.
Tet lattice_tet(std::mt19937_64& rng, double scale) {
  std::uniform_int_distribution<int> k(0, 3);
  Tet t;
  for (Vec3& p : t) p = {scale * k(rng), scale * k(rng), scale * k(rng)};
  return t;
}

// The largest coordinate difference of the pair.
double extent(const Tet& i, const Tet& j) {
  double e = 0;
  for (const Tet* t : {&i, &j})
    for (const Vec3& p : *t)
      for (int k = 0; k < 3; ++k) e = std::max(e, std::abs(p[k] - i[0][k]));
  return e;
}

// Every output finite, the volume within the smaller tetrahedron's, the area, the depth non-negative and the
// normals unit, over degenerate pairs (a small lattice: shared vertices, flat and coincident tetrahedra, faces on
// faces), random overlapping pairs and pairs of very different sizes.
TEST(ContactTets, NoNaNOverDegenerateAndRandomPairs) {
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> u(-1, 1);
  const int pairs = 100000;
  int touching = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int n = 0; n < pairs; ++n) {
    Tet i, j;
    const int kind = n % 4;
    if (kind == 0) i = lattice_tet(rng, 1.0), j = lattice_tet(rng, 1.0);
    else if (kind == 1) i = random_tet(rng, {0, 0, 0}, 1.0), j = random_tet(rng, {u(rng), u(rng), u(rng)}, 1.0);
    else if (kind == 2) i = random_tet(rng, {0, 0, 0}, 1.0), j = random_tet(rng, {0.3 * u(rng), 0, 0}, 1e-7);
    else i = lattice_tet(rng, 1e-3), j = moved(lattice_tet(rng, 1e-3), {1e-3 * u(rng), 0, 1e-18 * u(rng)});
    TetContact c;
    if (!contact_tets(i, j, c)) continue;
    ++touching;
    const double vmax = std::min(std::abs(rbdem::signed_volume(i)), std::abs(rbdem::signed_volume(j)));
    ASSERT_TRUE(std::isfinite(c.volume) && std::isfinite(c.area) && std::isfinite(c.depth)) << n;
    ASSERT_TRUE(std::isfinite(c.point.x + c.point.y + c.point.z)) << n;
    ASSERT_TRUE(std::isfinite(c.centroid.x + c.centroid.y + c.centroid.z)) << n;
    ASSERT_NEAR(rbdem::norm(c.normal), 1.0, 1e-12) << n;
    ASSERT_NEAR(rbdem::norm(c.axis), 1.0, 1e-12) << n;
    ASSERT_GE(c.volume, 0.0);
    const double e = extent(i, j);
    ASSERT_LE(c.volume, vmax * (1 + 1e-9) + 1e-12 * e * e * e) << n;
    ASSERT_GE(c.area, 0.0);
    ASSERT_GE(c.depth, 0.0);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GT(touching, pairs / 4);
  RecordProperty("pairs", pairs);
  RecordProperty("seconds", sci(seconds));
}

// tets_apart, the quick test that lets a pair list skip contact_tets, proves a pair apart only where
// contact_tets finds no contact (so the skip changes no result), and proves most pairs apart that are: along a box's
// side, along a face's normal where the boxes overlap, and not a pair that touches.
TEST(ContactTets, PairsProvedApartHaveNoContact) {
  auto apart = [](const Tet& i, const Tet& j) { return rbdem::tets_apart(rbdem::posed(i), rbdem::posed(j)); };
  const Vec3 c{1.0 / 3, 1.0 / 3, 1.0 / 3};
  Tet mirror;  // kCorner reflected through its slanted face's centroid: face on face, the boxes overlapping
  for (int k = 0; k < 4; ++k) mirror[std::size_t(k)] = 2.0 * c - kCorner[std::size_t(k)];
  const Vec3 n = (1.0 / std::sqrt(3.0)) * Vec3{1, 1, 1};
  TetContact t;
  EXPECT_TRUE(apart(kCorner, moved(kCorner, {1.01, 0, 0})));  // by a box's side
  EXPECT_TRUE(apart(kCorner, moved(mirror, 0.01 * n)));       // by the slanted face's normal
  EXPECT_TRUE(rbdem::aabbs_overlap(rbdem::aabb_of(kCorner), rbdem::aabb_of(moved(mirror, 0.01 * n))));
  EXPECT_FALSE(contact_tets(kCorner, moved(mirror, 0.01 * n), t));
  EXPECT_FALSE(apart(kCorner, mirror));  // touching face on face
  EXPECT_TRUE(contact_tets(kCorner, mirror, t));
  EXPECT_FALSE(apart(kCorner, moved(kCorner, {1.0, 0, 0})));  // a vertex on a vertex
  Tet bad = kCorner;
  bad[2].y = std::nan("");
  EXPECT_FALSE(apart(kCorner, bad));

  // Random pairs at every distance from overlapping to a few sizes apart, turned at random, of one size or of
  // sizes a thousand times apart, and the degenerate kinds of NoNaNOverDegenerateAndRandomPairs.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1), g(0, 1);
  int proved = 0, separated = 0, checked = 0;
  for (int k = 0; k < 200000; ++k) {
    Tet i, j;
    const int kind = k % 5;
    const double reach = std::pow(10.0, -4.0 * g(rng));  // the offset's scale, 1e-4 to 1
    if (kind == 0) i = lattice_tet(rng, 1.0), j = moved(lattice_tet(rng, 1.0), reach * Vec3{u(rng), u(rng), u(rng)});
    else if (kind == 1)
      i = random_tet(rng, {0, 0, 0}, 1.0), j = random_tet(rng, 1.5 * reach * Vec3{u(rng), u(rng), u(rng)}, 1.0);
    else if (kind == 2) i = random_tet(rng, {0, 0, 0}, 1.0), j = random_tet(rng, {0.6 + reach * u(rng), 0, 0}, 1e-3);
    else if (kind == 3) {  // slivers: a tetrahedron squashed along z by up to 1e-6
      i = random_tet(rng, {0, 0, 0}, 1.0), j = random_tet(rng, {u(rng), u(rng), u(rng)}, 1.0);
      for (Vec3& p : j) p.z *= std::pow(10.0, -6.0 * g(rng));
    } else i = mirror, j = moved(kCorner, reach * 1e-3 * Vec3{u(rng), u(rng), u(rng)} - 0.3 * reach * n);
    ++checked;
    const bool ij = contact_tets(i, j, t), ji = contact_tets(j, i, t);
    if (apart(i, j)) {
      ++proved;
      ASSERT_FALSE(ij) << k;
      ASSERT_FALSE(ji) << k;
    }
    ASSERT_EQ(apart(i, j), apart(j, i)) << k;
    separated += !ij;
  }
  EXPECT_GT(proved, 0.8 * separated);  // most pairs apart are proved so
  RecordProperty("pairs", checked);
  RecordProperty("separated", separated);
  RecordProperty("proved_apart", proved);
}

// What has no contact: a pair with a non-finite vertex, a zero or too large extent; boxes apart.
TEST(ContactTets, NonFiniteOrOutOfRangePairsHaveNoContact) {
  TetContact c;
  Tet bad = kCorner;
  bad[2].y = std::nan("");
  EXPECT_FALSE(contact_tets(kCorner, bad, c));
  EXPECT_FALSE(contact_tets(bad, kCorner, c));
  bad[2].y = INFINITY;
  EXPECT_FALSE(contact_tets(kCorner, bad, c));
  const Tet point{{{1, 1, 1}, {1, 1, 1}, {1, 1, 1}, {1, 1, 1}}};
  EXPECT_FALSE(contact_tets(point, point, c));
  const Tet huge{{{0, 0, 0}, {1e200, 0, 0}, {0, 1e200, 0}, {0, 0, 1e200}}};
  EXPECT_FALSE(contact_tets(huge, kCorner, c));
  EXPECT_TRUE(contact_tets(kCorner, kCorner, c));  // coincident: the whole tetrahedron
  EXPECT_NEAR(c.volume, 1.0 / 6, 1e-15);
  EXPECT_TRUE(rbdem::aabbs_overlap(rbdem::aabb_of(kCorner), rbdem::aabb_of(moved(kCorner, {1, 0, 0}))));
  EXPECT_FALSE(rbdem::aabbs_overlap(rbdem::aabb_of(kCorner), rbdem::aabb_of(moved(kCorner, {0, 1.1, 0}))));
  EXPECT_TRUE(rbdem::aabbs_overlap(rbdem::aabb_of(kCorner), rbdem::aabb_of(moved(kCorner, {0, 1.1, 0})), 0.05));
}

}  // namespace
