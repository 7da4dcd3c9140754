// Overlap geometry of two convex polygons, and of a convex polygon with a half-plane (a platen).
//
// This is the narrow phase of docs/theory.md, section 7 (Feng, Han and Owen 2012). For polygons A and B that overlap, with
// nu_B the outward normal of B:
//   area    A_o = area of A intersect B                      (Green's theorem over the clipped boundaries)
//   S       = integral of nu_B ds over the part of B's boundary inside A  = dA_o/dx_B (translation of B)
//   V       = integral of (x cross nu_B) ds over the same part           = dA_o/dtheta_B (rotation about the origin)
// For the common two-crossing case |S| is the chord between the two boundary crossings and S/|S| its normal,
// pointing from B into A. The force on B, -f S/|S|, acts on the line {x : x cross S/|S| = V/|S|}; the contact
// point is the overlap centroid projected onto that line. No special cases for vertex-edge, edge-edge or
// vertex-vertex: they all come out of the same integrals.
#pragma once

namespace rbdem {

struct Overlap {
  double area = 0;        // m^2 (per unit thickness)
  double nx = 0, ny = 0;  // unit normal, from B into A (the direction of the force on A)
  double chord = 0;       // |S|, m: the contact chord length
  double px = 0, py = 0;  // contact point, m (on the line of action, nearest the overlap centroid)
};

// Polygons as counter-clockwise vertex lists (x0, y0, x1, y1, ...). Returns false when they do not overlap.
bool overlap_polygons(const double* a, int na, const double* b, int nb, Overlap& out);

// Polygon B against the half-plane {x : (x - p) . m > 0} (the inside of a platen; m points into the platen).
// Returns false when B stays out of it. The normal points from B into the platen (= m).
bool overlap_halfplane(const double* b, int nb, double px, double py, double mx, double my, Overlap& out);

}  // namespace rbdem
