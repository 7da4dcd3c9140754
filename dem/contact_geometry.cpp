// Convex polygon overlap by clipping boundary segments (Cyrus-Beck) and Green's theorem. See the header.
#include "dem/contact_geometry.hpp"

#include <algorithm>
#include <cmath>

namespace rbdem {

namespace {

inline double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

// A convex CCW polygon relative to the common origin: its vertices v and edges e_k = v_(k+1) - v_k. N > 0: N
// vertices, known when compiling (the loops unroll and the wrap-around is a constant); N = 0: n vertices.
struct Polygon {
  double v[16], e[16];
  int n;
};
template <int N>
[[gnu::always_inline]] inline void make_polygon(const double* p, int n, double ox, double oy, Polygon& P) {
  if constexpr (N > 0) n = N;
  P.n = n;
  for (int k = 0; k < n; ++k) P.v[2 * k] = p[2 * k] - ox, P.v[2 * k + 1] = p[2 * k + 1] - oy;
  for (int k = 0; k < n; ++k) {
    const int k1 = k + 1 < n ? k + 1 : 0;
    P.e[2 * k] = P.v[2 * k1] - P.v[2 * k], P.e[2 * k + 1] = P.v[2 * k1 + 1] - P.v[2 * k + 1];
  }
}

// side[k * nq + v] = cross(e_k of P, Q's vertex v - P's vertex k): where Q's vertex v lies against P's edge k (>= 0:
// inside its half-plane). The separating test and the clipping both read these.
template <int NP, int NQ>
[[gnu::always_inline]] inline void sides(const Polygon& P, const Polygon& Q, double* side) {
  const int np = NP > 0 ? NP : P.n, nq = NQ > 0 ? NQ : Q.n;
  for (int k = 0; k < np; ++k)
    for (int v = 0; v < nq; ++v)
      side[k * nq + v] = cross(P.e[2 * k], P.e[2 * k + 1], Q.v[2 * v] - P.v[2 * k], Q.v[2 * v + 1] - P.v[2 * k + 1]);
}

// True when an edge of P separates it from Q (all of Q strictly outside the edge's half-plane). For convex
// polygons in 2D an edge normal always separates disjoint shapes, so this is an exact early exit.
template <int NP, int NQ>
[[gnu::always_inline]] inline bool separated(const Polygon& P, const Polygon& Q, const double* side) {
  const int np = NP > 0 ? NP : P.n, nq = NQ > 0 ? NQ : Q.n;
  for (int k = 0; k < np; ++k) {
    bool all_out = true;
    for (int v = 0; v < nq; ++v) all_out = all_out && side[k * nq + v] < 0.0;
    if (all_out) return true;
  }
  return false;
}

// Parameter interval [t0, t1] of Q's edge s, the segment q_s + t e_s with t in [0, 1], inside P (side: sides(P,
// Q)). Points on P's boundary count as inside, except, when `skip_shared` is set, a segment lying exactly on an
// edge of P with the same direction: that piece of the overlap's boundary was already counted from the other
// polygon (Green's theorem must see it once).
template <int NP, int NQ>
[[gnu::always_inline]] inline bool clip_edge(const Polygon& P, const Polygon& Q, const double* side, int s,
                                             double& t0, double& t1, bool skip_shared = false) {
  const int np = NP > 0 ? NP : P.n, nq = NQ > 0 ? NQ : Q.n;
  t0 = 0.0, t1 = 1.0;
  const double dx = Q.e[2 * s], dy = Q.e[2 * s + 1];
  for (int k = 0; k < np; ++k) {
    const double ex = P.e[2 * k], ey = P.e[2 * k + 1];
    // inside: cross(e, x - a) >= 0; along the segment: f(t) = f0 + t df
    const double f0 = side[k * nq + s];
    const double df = cross(ex, ey, dx, dy);
    if (df == 0.0) {
      if (f0 < 0.0) return false;
      if (skip_shared && f0 == 0.0 && ex * dx + ey * dy > 0.0) return false;
      continue;
    }
    const double t = -f0 / df;
    if (df > 0.0) t0 = std::max(t0, t);
    else t1 = std::min(t1, t);
    if (t0 >= t1) return false;
  }
  return t1 > t0;
}

struct Integrals {
  double area2 = 0;          // 2 x area
  double cx6 = 0, cy6 = 0;   // 6 x area x centroid
  double sx = 0, sy = 0;     // S
  double v = 0;              // V
  bool any = false;
};

// Adds a boundary piece p0 -> p1 (counter-clockwise along the overlap's boundary) to the area integrals.
inline void add_area(Integrals& I, double x0, double y0, double x1, double y1) {
  const double c = cross(x0, y0, x1, y1);
  I.area2 += c;
  I.cx6 += (x0 + x1) * c;
  I.cy6 += (y0 + y1) * c;
}

// Adds the part of B's edge inside A: its normal x length to S and its moment to V.
inline void add_normal(Integrals& I, double x0, double y0, double x1, double y1) {
  const double nx = y1 - y0, ny = -(x1 - x0);  // outward normal of a CCW edge, times its length
  I.sx += nx, I.sy += ny;
  I.v += cross(0.5 * (x0 + x1), 0.5 * (y0 + y1), nx, ny);
}

bool finish(const Integrals& I, double ox, double oy, Overlap& out) {
  const double area = 0.5 * I.area2;
  const double s = std::hypot(I.sx, I.sy);
  if (!I.any || !(area > 0.0) || !(s > 0.0)) return false;
  const double ux = I.sx / s, uy = I.sy / s;  // from B into A
  // Contact point: the overlap centroid projected onto the line of action {x : x cross u = V/|S|}.
  const double cx = I.cx6 / (3.0 * I.area2), cy = I.cy6 / (3.0 * I.area2);
  const double mu = cross(cx, cy, ux, uy) - I.v / s;  // move along perp(u) = (-uy, ux)
  out.area = area;
  out.nx = ux, out.ny = uy;
  out.chord = s;
  out.px = ox + cx - mu * uy;
  out.py = oy + cy + mu * ux;
  return true;
}

// overlap_polygons with NA and NB vertices known when compiling (> 0), or na and nb (0).
template <int NA, int NB>
bool overlap_polygons_of(const double* a, int na, const double* b, int nb, Overlap& out) {
  // Work relative to A's first vertex: small numbers, no cancellation against far-away origins.
  const double ox = a[0], oy = a[1];
  Polygon A, B;
  make_polygon<NA>(a, na, ox, oy, A);
  make_polygon<NB>(b, nb, ox, oy, B);
  na = A.n, nb = B.n;
  double side_ab[64], side_ba[64];  // B's vertices against A's edges, A's against B's
  sides<NA, NB>(A, B, side_ab);
  if (separated<NA, NB>(A, B, side_ab)) return false;
  sides<NB, NA>(B, A, side_ba);
  if (separated<NB, NA>(B, A, side_ba)) return false;
  Integrals I;
  double t0, t1;
  for (int k = 0; k < nb; ++k) {  // B's boundary inside A
    if (!clip_edge<NA, NB>(A, B, side_ab, k, t0, t1)) continue;
    const int k1 = k + 1 < nb ? k + 1 : 0;
    const double px = B.v[2 * k], py = B.v[2 * k + 1], qx = B.v[2 * k1], qy = B.v[2 * k1 + 1];
    const double x0 = px + t0 * (qx - px), y0 = py + t0 * (qy - py);
    const double x1 = px + t1 * (qx - px), y1 = py + t1 * (qy - py);
    add_area(I, x0, y0, x1, y1);
    add_normal(I, x0, y0, x1, y1);
    I.any = true;
  }
  if (!I.any) return false;  // convex: if no part of B's boundary is in A, either no overlap or A inside B
  for (int k = 0; k < na; ++k) {  // A's boundary inside B
    if (!clip_edge<NB, NA>(B, A, side_ba, k, t0, t1, true)) continue;
    const int k1 = k + 1 < na ? k + 1 : 0;
    const double px = A.v[2 * k], py = A.v[2 * k + 1], qx = A.v[2 * k1], qy = A.v[2 * k1 + 1];
    add_area(I, px + t0 * (qx - px), py + t0 * (qy - py), px + t1 * (qx - px), py + t1 * (qy - py));
  }
  return finish(I, ox, oy, out);
}

}  // namespace

bool overlap_polygons(const double* a, int na, const double* b, int nb, Overlap& out) {
  // Two triangles (every pair of blocks of a triangle mesh) take the code compiled for them.
  if (na == 3 && nb == 3) return overlap_polygons_of<3, 3>(a, na, b, nb, out);
  return overlap_polygons_of<0, 0>(a, na, b, nb, out);
}

bool overlap_halfplane(const double* b, int nb, double px, double py, double mx, double my, Overlap& out) {
  const double ox = b[0], oy = b[1];
  double B[16];
  for (int k = 0; k < nb; ++k) B[2 * k] = b[2 * k] - ox, B[2 * k + 1] = b[2 * k + 1] - oy;
  const double qx = px - ox, qy = py - oy;
  auto depth = [&](double x, double y) { return (x - qx) * mx + (y - qy) * my; };  // > 0 inside the platen
  Integrals I;
  double enter[2] = {0, 0}, leave[2] = {0, 0};
  bool has_enter = false, has_leave = false;
  for (int k = 0; k < nb; ++k) {
    const int k1 = k + 1 < nb ? k + 1 : 0;
    const double x0 = B[2 * k], y0 = B[2 * k + 1], x1 = B[2 * k1], y1 = B[2 * k1 + 1];
    const double d0 = depth(x0, y0), d1 = depth(x1, y1);
    if (d0 <= 0 && d1 <= 0) continue;
    double ax = x0, ay = y0, bx = x1, by = y1;
    if (d0 <= 0) {  // entering the platen
      const double t = d0 / (d0 - d1);
      ax = x0 + t * (x1 - x0), ay = y0 + t * (y1 - y0);
      enter[0] = ax, enter[1] = ay, has_enter = true;
    }
    if (d1 <= 0) {  // leaving it
      const double t = d0 / (d0 - d1);
      bx = x0 + t * (x1 - x0), by = y0 + t * (y1 - y0);
      leave[0] = bx, leave[1] = by, has_leave = true;
    }
    add_area(I, ax, ay, bx, by);
    add_normal(I, ax, ay, bx, by);
    I.any = true;
  }
  if (!I.any || !has_enter || !has_leave) return false;  // fully inside the platen is not a contact state
  add_area(I, leave[0], leave[1], enter[0], enter[1]);   // the chord along the platen face closes the boundary
  return finish(I, ox, oy, out);
}

}  // namespace rbdem
