// The narrow phase of the contact between two tetrahedral blocks in 3D: from the world vertices of tetrahedra i and
// j, whether they touch and, if they do, the contact the linear contact law (dem/laws/linear_contact.hpp) needs.
// docs/theory.md, section 11.9.
//
// Two results, each with its own job:
//  - The separating axis test over the 4 + 4 face normals and the 36 edge-edge cross products (degenerate axes,
//    from parallel edges or flat faces, skipped). It decides whether the pair touches, and its axis of least
//    penetration gives `axis` and `depth`, the minimum translation that separates the pair (exact for convex
//    polyhedra). Ties within round-off keep the first axis in the fixed order faces of i, faces of j, edge pairs,
//    so a face-on contact keeps the face's normal however the depth varies by round-off.
//  - The overlap polyhedron, as the faces of i clipped by j's four half-spaces and the faces of j clipped by i's
//    (convex polygon clipping, at most 7 vertices per face). Its volume V and centroid follow from the divergence
//    theorem. The contact's area vector is the one of Feng, Han and Owen's 2D contact (dem/contact_geometry.hpp)
//    one dimension up,
//        S = (S_i - S_j) / 2,     S_i = int over the part of i's boundary inside j of n_i dA   (S_j alike)
//    S_i = dV/dx_i is the gradient of the overlap volume in a translation of i, and S_i = -S_j because the two
//    pieces close the overlap's boundary. S is the vector area of the curve where the two boundaries cross, so it
//    depends continuously on the poses; a contact whose crossing curve is planar (face on face, a vertex or an
//    edge into a face) has S exactly along that plane's normal. The contact normal is S / |S| (from i to j) and
//    the contact area A_c = |S|, so the potential k_n V^2 / (2 A) of the linear contact law gives
//        F_n = K V A_c / A^2         (K = k_n A, LinearContact::normal_force(V, A_c) with inv_lref = 1 / A)
//    along the normal, the force of a conservative potential: what face_linear_part (dem/laws/face_bond.hpp) does
//    for an intact bond's face. The force acts at `point`, on the central axis of the wrench of that potential
//    nearest the overlap's centroid, so that the moments are those of the potential too (as the 2D contact puts
//    its point on the line of action); the twist about the normal it cannot carry is zero for a planar crossing
//    curve.
// Where S vanishes (one tetrahedron inside the other, or no area at all: an edge on an edge, a vertex on a face)
// the normal is the separating axis's and the area is |S|, so the contact carries no force, as in 2D.
//
// Deterministic (a function of the eight vertices alone), no allocation, and finite for any finite input: the
// vertices are taken relative to i's first vertex and scaled by the pair's extent, and the tolerances are relative
// to that extent. A pair whose vertices are not finite, or whose extent is zero or above 1e100 m, has no contact.
#pragma once

#include <cstdint>

#include "dem/geometry3.hpp"

namespace rbdem {

// An axis-aligned box, the broad phase's test.
struct Aabb3 {
  Vec3 lo, hi;  // m
};
Aabb3 aabb_of(const Tet& t);
// True when the boxes, each grown by `margin` (m) on every side, overlap or touch.
bool aabbs_overlap(const Aabb3& a, const Aabb3& b, double margin = 0.0);

// Which separating axis gave `axis`: a face of i, a face of j (index 0..3, the face opposite that vertex), or the
// edges a of i and b of j (index 6 a + b; the edges are 01, 02, 03, 12, 13, 23).
enum class ContactAxis : std::uint8_t { none, face_i, face_j, edge_edge };

struct TetContact {
  Vec3 normal;          // unit, from i to j: the direction of the force on j
  double area = 0;      // m^2, A_c = |S|
  double volume = 0;    // m^3, V, the overlap volume
  Vec3 point;           // m, where the force acts
  Vec3 centroid;        // m, the overlap's centroid (of its boundary pieces' areas where V is round-off)
  Vec3 axis;            // unit, from i to j: the separating axis of least penetration
  double depth = 0;     // m, the penetration along `axis`: the least translation that separates the pair
  ContactAxis axis_kind = ContactAxis::none;
  int axis_index = -1;
};

// Returns true when tetrahedra i and j touch or overlap (no separating axis with a gap above round-off: 1e-12 of
// the pair's extent), and fills `out`; false leaves `out` as it was. Either vertex order (positive or negative
// signed volume) is accepted. A flat tetrahedron (a volume below 1e-9 of its longest edge cubed) has no volume to
// clip: it touches by the separating axes alone, with no volume and no area.
bool contact_tets(const Tet& i, const Tet& j, TetContact& out);

// A tetrahedron in its pose with what tets_apart reads of it, computed once per pose: its box and, per face
// (kFace order: the face opposite vertex k), the cross product of two of its edges (the normal, not unit), that
// product's square and the square of the face's longest edge.
struct PosedTet {
  Tet t;
  Aabb3 box;
  Vec3 n[4];
  double n2[4], l2[4];
};
PosedTet posed(const Tet& t);

// A quick test that proves a pair apart: true only where a plane separates the two tetrahedra by more than 1e-4 of
// the pair's extent, found along a coordinate axis or the normal of a well-shaped face (angles over 0.6 deg, edges
// over 1e-2 of the extent). Such a gap is far beyond what round-off and contact_tets's tolerances reach, so
// contact_tets(i.t, j.t) returns false there: a caller may skip it and have the same result. False proves nothing.
// A pair list keeps many pairs up to a skin apart, which this rejects for a few comparisons instead of the
// separating axes and the clipping.
bool tets_apart(const PosedTet& i, const PosedTet& j);

}  // namespace rbdem
