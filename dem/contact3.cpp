// The tetrahedron-tetrahedron narrow phase: separating axes, then the overlap polyhedron by clipping each face by
// the other tetrahedron's half-spaces. See the header and docs/theory.md, section 11.9.
#include "dem/contact3.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace rbdem {

namespace {

// Tolerances, in units of the pair's extent (every coordinate below is in [-1, 1]): a signed distance below
// kSnap is zero (round-off of unit-sized coordinates is 1e-16, so this is 1e4 times it and still 1e-12 of the
// blocks); a face whose vertices are within kCoplanar of a plane of the other body lies in that plane (which
// moves the volume by at most kCoplanar times the face's area; a face crossing a plane at a smaller angle than
// that would be clipped along a line whose position is round-off over the angle, in each of the two faces a
// different one: sqrt(eps) balances the two errors at about 1e-8 of the extent cubed); an axis replaces the best one only when it is
// shallower by more than kPrefer, so that round-off never decides between a face normal and an edge cross product
// along the same direction; edges closer to parallel than a sine of 1e-9 (and faces whose edges are) give no
// axis, since their cross product's direction is round-off.
constexpr double kSnap = 1e-12;
constexpr double kCoplanar = 1e-8;
constexpr double kPrefer = 1e-9;
constexpr double kParallelSin2 = 1e-18;
constexpr double kFlat = 1e-9;
constexpr double kMaxExtent = 1e100;  // m: beyond it V = extent^3 may overflow
constexpr int kMaxVertices = 12;      // a triangle clipped by four planes has at most 7

// The faces of a positive tetrahedron, outward (counter-clockwise seen from outside), opposite vertex k; its edges.
constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
constexpr int kEdge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
// Face k's two edges from its first vertex, in its order (so that their cross product is the outward normal).
constexpr int kFaceEdge[4][2] = {{3, 4}, {2, 1}, {0, 2}, {1, 0}};

// The half-space m . x <= h of a face (m the unit outward normal); `valid` is false for a face with no direction.
struct Plane {
  Vec3 m;
  double h = 0;
  bool valid = false;
};

struct Body {
  Tet p;  // positive vertex order, in the pair's unit coordinates
  Plane face[4];
  Vec3 c;
  Vec3 edge[6];       // the edges kEdge, scaled
  bool flat = false;  // no volume of its own: its half-spaces do not bound it
};

// v / max_k |v_k|: the same direction with components in [-1, 1], so that products of two of them neither
// underflow nor lose their digits (the unit coordinates of a pair may hold values down to the subnormal range).
// Zero for a zero (or non-finite) vector.
Vec3 scaled(Vec3 v) {
  const double m = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  return m > 0.0 && m <= 1e300 ? Vec3{v.x / m, v.y / m, v.z / m} : Vec3{};
}

// The unit normal of two directions given scaled, false where they are closer to parallel than a sine of 1e-9
// (the cross product's direction would be round-off).
bool unit_cross(Vec3 a, Vec3 b, Vec3& u) {
  const Vec3 c = cross(a, b);
  if (!(dot(c, c) > kParallelSin2 * dot(a, a) * dot(b, b))) return false;
  u = (1.0 / norm(c)) * c;
  return true;
}

Body make_body(const Tet& t) {
  Body b;
  b.p = t;
  const double volume = signed_volume(t);
  if (volume < 0) std::swap(b.p[1], b.p[2]);
  double l2 = 0.0;
  for (int e = 0; e < 6; ++e) {
    const Vec3 d = b.p[kEdge[e][1]] - b.p[kEdge[e][0]];
    b.edge[e] = scaled(d), l2 = std::max(l2, dot(d, d));
  }
  bool all_valid = true;
  for (int k = 0; k < 4; ++k) {
    Plane& f = b.face[k];
    f.valid = unit_cross(b.edge[kFaceEdge[k][0]], b.edge[kFaceEdge[k][1]], f.m);
    if (f.valid) f.h = dot(f.m, b.p[kFace[k][0]]);
    all_valid = all_valid && f.valid;
  }
  b.c = centroid(b.p);
  // Flat: a face with no direction, or a volume below kFlat of the longest edge cubed (a face whose edges are
  // parallel to a sine of 1e-9 makes the volume that small too).
  b.flat = !all_valid || !(6.0 * std::abs(volume) > kFlat * l2 * std::sqrt(l2));
  return b;
}

double snapped_distance(const Plane& f, Vec3 x) {
  const double d = dot(f.m, x) - f.h;
  return std::abs(d) <= kSnap ? 0.0 : d;
}

// --- Separating axes -------------------------------------------------------------------------------------------

struct Axis {
  Vec3 u;
  double pen = std::numeric_limits<double>::infinity();
  ContactAxis kind = ContactAxis::none;
  int index = -1;
};

void project(const Tet& p, Vec3 u, double& lo, double& hi) {
  lo = hi = dot(u, p[0]);
  for (int k = 1; k < 4; ++k) {
    const double s = dot(u, p[k]);
    lo = std::min(lo, s), hi = std::max(hi, s);
  }
}

// Projects both bodies on the unit axis u: false when it separates them; else `best` becomes u (pointed from a to
// b) when it is shallower than `best` by more than kPrefer.
bool try_axis(const Body& a, const Body& b, Vec3 u, ContactAxis kind, int index, Axis& best) {
  double alo, ahi, blo, bhi;
  project(a.p, u, alo, ahi);
  project(b.p, u, blo, bhi);
  const double up = ahi - blo, down = bhi - alo;  // how far b must move along +u, along -u, to separate
  if (up < -kSnap || down < -kSnap) return false;
  const double pen = std::min(up, down);
  if (!(pen < best.pen - kPrefer)) return true;
  // The sense: the shorter way out; a tie (a symmetric pair) by the centroids, then +u.
  const bool plus = up < down - kPrefer || (!(down < up - kPrefer) && dot(u, b.c - a.c) >= 0.0);
  best = {plus ? u : -u, pen, kind, index};
  return true;
}

// The separating axis test in the fixed order faces of a, faces of b, edge pairs. False when an axis separates.
bool least_penetration(const Body& a, const Body& b, Axis& best) {
  for (int k = 0; k < 4; ++k)
    if (a.face[k].valid && !try_axis(a, b, a.face[k].m, ContactAxis::face_i, k, best)) return false;
  for (int k = 0; k < 4; ++k)
    if (b.face[k].valid && !try_axis(a, b, -b.face[k].m, ContactAxis::face_j, k, best)) return false;
  for (int ea = 0; ea < 6; ++ea) {
    for (int eb = 0; eb < 6; ++eb) {
      Vec3 u;
      if (!unit_cross(a.edge[ea], b.edge[eb], u)) continue;
      if (!try_axis(a, b, u, ContactAxis::edge_edge, 6 * ea + eb, best)) return false;
    }
  }
  return true;
}

// --- The overlap polyhedron ------------------------------------------------------------------------------------

struct Polygon {
  Vec3 v[kMaxVertices];
  int n = 0;
};

// Sutherland-Hodgman: the part of `in` inside the closed half-space (distances within kSnap count as on it).
void clip(const Polygon& in, const Plane& f, Polygon& out) {
  out.n = 0;
  double d[kMaxVertices];
  for (int k = 0; k < in.n; ++k) d[k] = snapped_distance(f, in.v[k]);
  for (int k = 0; k < in.n && out.n < kMaxVertices; ++k) {
    const int k1 = k + 1 < in.n ? k + 1 : 0;
    if (d[k] <= 0.0) out.v[out.n++] = in.v[k];
    if (((d[k] < 0.0 && d[k1] > 0.0) || (d[k] > 0.0 && d[k1] < 0.0)) && out.n < kMaxVertices)
      out.v[out.n++] = in.v[k] + (d[k] / (d[k] - d[k1])) * (in.v[k1] - in.v[k]);
  }
}

// A piece of the overlap's boundary: a face of one body clipped by the other. `s_sign` is +1 for a piece of i's
// boundary (in S_i), -1 for one of j's (in S_j), 0 for a piece where the two boundaries coincide with the same
// outward side (a free surface both blocks share: it bounds the volume once and pushes neither block).
struct Piece {
  Polygon poly;
  double s_sign = 0;
};

// Whether face k of x lies in plane g, to kCoplanar.
bool on_plane(const Body& x, int k, const Plane& g) {
  bool on = g.valid;
  for (int v = 0; v < 3; ++v) on = on && std::abs(dot(g.m, x.p[kFace[k][v]]) - g.h) <= kCoplanar;
  return on;
}

// The faces of x (s = +1: i, -1: j) clipped by y's half-spaces, appended to `pieces`. A face in a plane of y is
// not clipped by that plane: it is on it, and where the two planes cross inside the face at a small angle the
// crossing would be round-off divided by that angle, a different line in each face.
void clip_faces(const Body& x, const Body& y, double s, Piece* pieces, int& count) {
  for (int k = 0; k < 4; ++k) {
    if (!x.face[k].valid) continue;  // no area
    bool on[4], shared = false;
    for (int g = 0; g < 4; ++g) {
      on[g] = on_plane(x, k, y.face[g]);
      shared = shared || (on[g] && dot(y.face[g].m, x.face[k].m) > 0.0);
    }
    if (shared && s < 0) continue;  // counted once, from i
    // Clipped back and forth between the piece's own polygon and a scratch one, ending in the piece.
    Piece& piece = pieces[count];
    Polygon scratch;
    Polygon* from = &piece.poly;
    Polygon* to = &scratch;
    from->n = 3;
    for (int v = 0; v < 3; ++v) from->v[v] = x.p[kFace[k][v]];
    for (int g = 0; g < 4 && from->n >= 3; ++g) {
      if (!y.face[g].valid || on[g]) continue;
      clip(*from, y.face[g], *to);
      std::swap(from, to);
    }
    if (from->n < 3) continue;
    if (from != &piece.poly) piece.poly = *from;
    piece.s_sign = shared ? 0.0 : s;
    ++count;
  }
}

struct Integrals {
  double v6 = 0, v6_abs = 0;  // 6 V, and the sum of the fan's |6 V| (to see cancellation)
  Vec3 cv;                    // 24 V x the volume centroid
  double area = 0;            // the pieces' total area
  Vec3 ca;                    // 3 x that area x the area centroid
  Vec3 s, m;                  // S_i - S_j and M_i - M_j (moments about the origin)
  double r2 = 0;              // the largest squared distance of a vertex from the origin
};

// The divergence theorem over the pieces, as fans of triangles (v0, v_k, v_k+1) and of tetrahedra from the origin.
Integrals integrate(const Piece* pieces, int count) {
  Integrals I;
  for (int p = 0; p < count; ++p) {
    const Polygon& P = pieces[p].poly;
    for (int k = 0; k < P.n; ++k) I.r2 = std::max(I.r2, dot(P.v[k], P.v[k]));
    for (int k = 1; k + 1 < P.n; ++k) {
      const Vec3 a = P.v[0], b = P.v[k], c = P.v[k + 1], abc = (a + b) + c;
      const double w = dot(a, cross(b, c));
      I.v6 += w, I.v6_abs += std::abs(w), I.cv += w * abc;
      const Vec3 t = 0.5 * cross(b - a, c - a);
      const double area = norm(t);
      I.area += area, I.ca += area * abc;
      I.s += pieces[p].s_sign * t, I.m += pieces[p].s_sign * cross((1.0 / 3.0) * abc, t);
    }
  }
  return I;
}

Vec3 over(Vec3 v, double d) { return {v.x / d, v.y / d, v.z / d}; }
// v / |v| for v not zero, by way of `scaled` (a subnormal |v|^2 would lose the digits of |v|).
Vec3 unit(Vec3 v) {
  v = scaled(v);
  return over(v, norm(v));
}

// The contact from the pieces, in unit coordinates about the origin o (a point inside the overlap).
void contact_of(const Integrals& I, const Axis& axis, TetContact& out) {
  out.volume = std::max(0.0, I.v6 / 6.0);
  // The volume centroid while the fan from o (inside the overlap) is of one sign; the area centroid of the pieces
  // where the volume is round-off (two faces touching), to which it tends.
  // (Divisions, not products with a reciprocal: a subnormal volume or area has no finite reciprocal.)
  if (I.v6 > 0.5 * I.v6_abs && I.v6 > 0.0) out.centroid = over(I.cv, 4.0 * I.v6);
  else if (I.area > 0.0) out.centroid = over(I.ca, 3.0 * I.area);
  const Vec3 S = 0.5 * I.s, M = 0.5 * I.m;
  const double s = norm(S);
  out.area = s;
  out.normal = axis.u, out.point = out.centroid;
  if (!(s > 1e-8 * I.area)) return;  // S is round-off: one body inside the other, or no area
  out.normal = unit(S);
  // The point on the wrench's axis nearest the centroid c: p x S = M up to the twist along S.
  const Vec3 c = out.centroid, offset = cross(out.normal, over(M - cross(c, S), s));
  // Where the axis passes outside the overlap's bounding sphere (|S| small against the moments: a deep, nearly
  // engulfing overlap), the centroid: a point far off would carry the potential's moments but not be a contact.
  if (dot(c + offset, c + offset) <= I.r2) out.point = c + offset;
}

}  // namespace

Aabb3 aabb_of(const Tet& t) {
  Aabb3 b{t[0], t[0]};
  for (int k = 1; k < 4; ++k)
    for (int c = 0; c < 3; ++c) b.lo[c] = std::min(b.lo[c], t[k][c]), b.hi[c] = std::max(b.hi[c], t[k][c]);
  return b;
}

bool aabbs_overlap(const Aabb3& a, const Aabb3& b, double margin) {
  for (int c = 0; c < 3; ++c)
    if (a.lo[c] - margin > b.hi[c] + margin || b.lo[c] - margin > a.hi[c] + margin) return false;
  return true;
}

namespace {

// The gap, over the pair's extent, that tets_apart asks for, and the shape a face must have for its normal to be
// tried: over the pair's extent, contact_tets's coordinates carry an error of about 1e-16 and its axes (from edges
// at least kApartEdge long, at angles whose sine is at least kApartSine) one of about 1e-16 / (kApartEdge
// kApartSine) = 1e-12 in direction, so a gap of kApart is above kSnap and every round-off by 1e7.
constexpr double kApart = 1e-4;
constexpr double kApartEdge = 1e-2;
constexpr double kApartSine = 1e-2;

// Whether the normal of one of x's faces puts all of y beyond x by more than `gap` (either side).
bool face_separates(const PosedTet& x, const PosedTet& y, double span, double gap) {
  for (int k = 0; k < 4; ++k) {
    // Every angle's sine |n| / (two edges) is at least |n| / l2; the shortest edge is at least that sine times l2.
    const double l2 = x.l2[k], n2 = x.n2[k];
    if (!(l2 >= kApartEdge * kApartEdge * span * span) || !(n2 >= kApartSine * kApartSine * l2 * l2)) continue;
    double xlo, xhi, ylo, yhi;
    project(x.t, x.n[k], xlo, xhi);
    project(y.t, x.n[k], ylo, yhi);
    const double g = std::max(ylo - xhi, xlo - yhi);  // along n, |n| times the distance
    if (g > 0.0 && g * g > gap * gap * n2) return true;
  }
  return false;
}

}  // namespace

PosedTet posed(const Tet& t) {
  PosedTet p;
  p.t = t;
  p.box = aabb_of(t);
  for (int k = 0; k < 4; ++k) {
    const Vec3 a = t[std::size_t(kFace[k][0])], b = t[std::size_t(kFace[k][1])], c = t[std::size_t(kFace[k][2])];
    const Vec3 e1 = b - a, e2 = c - a, e3 = c - b;
    p.n[k] = cross(e1, e2), p.n2[k] = dot(p.n[k], p.n[k]);
    p.l2[k] = std::max({dot(e1, e1), dot(e2, e2), dot(e3, e3)});
  }
  return p;
}

bool tets_apart(const PosedTet& i, const PosedTet& j) {
  const Aabb3 &bi = i.box, &bj = j.box;
  double span = 0.0;  // at least contact_tets's extent (its coordinates' largest difference from i's first vertex)
  for (int c = 0; c < 3; ++c) span = std::max(span, std::max(bi.hi[c], bj.hi[c]) - std::min(bi.lo[c], bj.lo[c]));
  if (!(span > 0.0 && span <= kMaxExtent)) return false;  // not finite, a point, or beyond contact_tets's range
  const double gap = kApart * span;
  for (int c = 0; c < 3; ++c)
    if (bj.lo[c] - bi.hi[c] > gap || bi.lo[c] - bj.hi[c] > gap) return true;
  return face_separates(i, j, span, gap) || face_separates(j, i, span, gap);
}

bool contact_tets(const Tet& i, const Tet& j, TetContact& out) {
  // The pair in unit coordinates: relative to i's first vertex, divided by the largest coordinate difference.
  const Vec3 origin = i[0];
  double extent = 0.0;
  for (const Tet* t : {&i, &j})
    for (const Vec3& p : *t)
      for (int c = 0; c < 3; ++c) {
        if (!std::isfinite(p[c])) return false;
        extent = std::max(extent, std::abs(p[c] - origin[c]));
      }
  if (!(extent > 0.0 && extent <= kMaxExtent)) return false;
  Tet ui, uj;
  for (int k = 0; k < 4; ++k) {
    const Vec3 a = i[std::size_t(k)] - origin, b = j[std::size_t(k)] - origin;
    ui[std::size_t(k)] = {a.x / extent, a.y / extent, a.z / extent};
    uj[std::size_t(k)] = {b.x / extent, b.y / extent, b.z / extent};
  }
  if (!aabbs_overlap(aabb_of(ui), aabb_of(uj), 0.5 * kSnap)) return false;
  const Body a = make_body(ui), b = make_body(uj);
  Axis axis;
  if (!least_penetration(a, b, axis)) return false;
  if (axis.kind == ContactAxis::none) {  // no valid axis (both bodies degenerate): the line of centroids
    const Vec3 d = b.c - a.c;
    axis.u = dot(scaled(d), scaled(d)) > 0.0 ? unit(d) : Vec3{0, 0, 1}, axis.pen = 0.0;
  }

  if (a.flat || b.flat) {  // touching, but no volume to clip: no area, no force
    out = TetContact{};
    out.normal = out.axis = axis.u;
    out.point = out.centroid = origin + (0.5 * extent) * (a.c + b.c);
    out.depth = std::max(0.0, axis.pen) * extent;
    out.axis_kind = axis.kind, out.axis_index = axis.index;
    return true;
  }
  Piece pieces[8];
  int count = 0;
  clip_faces(a, b, +1.0, pieces, count);
  clip_faces(b, a, -1.0, pieces, count);
  // The origin of the integrals: the mean of the pieces' vertices, inside the (convex) overlap.
  Vec3 o = 0.5 * (a.c + b.c);
  int nv = 0;
  Vec3 sum;
  for (int p = 0; p < count; ++p)
    for (int k = 0; k < pieces[p].poly.n; ++k) sum += pieces[p].poly.v[k], ++nv;
  if (nv > 0) o = (1.0 / nv) * sum;
  for (int p = 0; p < count; ++p)
    for (int k = 0; k < pieces[p].poly.n; ++k) pieces[p].poly.v[k] -= o;

  TetContact c;
  contact_of(integrate(pieces, count), axis, c);
  // Back to metres.
  out.normal = c.normal, out.axis = axis.u;
  out.area = c.area * extent * extent;
  out.volume = c.volume * extent * extent * extent;
  out.depth = std::max(0.0, axis.pen) * extent;
  out.point = origin + extent * (o + c.point);
  out.centroid = origin + extent * (o + c.centroid);
  out.axis_kind = axis.kind, out.axis_index = axis.index;
  return true;
}

}  // namespace rbdem
