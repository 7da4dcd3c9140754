// One face bond's kinematics and forces in 3D: the relative motion of two tetrahedral blocks at their shared face,
// in total form in a co-rotated face frame, and the calls of the laws (FaceBond for the parallel bond, the linear
// contact law on the compressed part of the face for the linear part: dem/laws/face_bond.hpp). The 3D analogue of
// eval_bond (bond_kernel.hpp); docs/theory.md, "The face bond in 3D".
//
// A block's pose is its centroid x and the unit quaternion q that turns it from the reference configuration. The
// bond's material point on each block is p = x + q r0 q*, with r0 the face centroid's offset from the block's
// centroid at rest. The face frame turns with the mean rotation of the pair, q_m = q_i sqrt(q_i* q_j) (the midpoint
// of the shortest arc from q_i to q_j), and the relative rotation is the rotation vector theta of q_i* q_j. Both
// are unchanged by any rigid motion of the pair, however large, so the forces are objective, and exchanging the
// blocks turns q_i* q_j into its inverse and leaves q_m as it is, so the forces on the two blocks are exchanged.
#pragma once

#include <utility>

#include "dem/geometry3.hpp"
#include "dem/laws/face_bond.hpp"
#include "dem/vec3.hpp"

namespace rbdem::stages {

// The constants of one face bond, fixed at the reference configuration.
struct FaceBondFrame {
  Vec3 ri, rj;          // m, the face centroid from block i's and from block j's centroid at rest
  Mat3 axes;            // the face frame at rest: rows e1, e2, n (n from i to j)
  FaceSection section;  // A, I1, I2, J, r_max, the vertices in (y1, y2)
  FaceStiffness k;      // the parallel bond's stiffnesses; the linear part has the same kb_n A and kb_s A
  double mu = 0;        // the linear part's friction while the bond is intact (+inf: it never slides)
};

// The frame of the bond on `face` between the blocks whose centroids are ci and cj at rest, of the law `law` with
// effective modulus E* (Pa) and the linear part's friction mu: n is oriented from i to j (the face's vertex order
// is turned when it points the other way) and d = n . (c_j - c_i), as the 2D bond's.
inline FaceBondFrame face_bond_frame(Vec3 ci, Vec3 cj, Tri face, const FaceBond& law, double modulus, double mu) {
  Face f = face_of(face);
  if (dot(f.normal, cj - ci) < 0) std::swap(face[1], face[2]), f = face_of(face);
  FaceBondFrame b;
  b.ri = f.centroid - ci, b.rj = f.centroid - cj;
  b.axes = {{f.e1, f.e2, f.normal}};
  b.section = FaceSection::of(f);
  b.k = law.stiffness(modulus, dot(f.normal, cj - ci), b.section);
  b.mu = mu;
  return b;
}

// One block's kinematics: centroid, rotation from rest, velocity and angular velocity (world).
struct BlockKin3 {
  Vec3 x;
  Quat q;
  Vec3 v, omega;
};

struct FaceBondEval {
  FaceMotion motion;        // the relative motion in the face frame
  FaceForces pb;            // the parallel bond's forces, undamaged (failure reads these)
  FaceLinearPart linear;    // the linear part; (fs1, fs2) is the new shear history
  Vec3 f;                   // N, the force on j (world; damage applied); -f acts on i
  Vec3 mi, mj;              // N m, the moments on i and j about their centroids (world)
  Vec3 p;                   // m, the bond point (world)
};

// The relative motion of the pair at the bond and the frame it is measured in.
struct FaceKinematics {
  FaceMotion motion;
  Mat3 frame;      // the face frame now: rows e1, e2, n turned by q_m (world components)
  Vec3 g, ci, cj;  // the gap p_j - p_i and the bond point (midway) from each centroid
};
inline FaceKinematics face_kinematics(const FaceBondFrame& b, const BlockKin3& I, const BlockKin3& J) {
  FaceKinematics k;
  Quat rel = conj(I.q) * J.q;
  if (rel.w < 0) rel = {-rel.w, -rel.x, -rel.y, -rel.z};  // the shorter arc: q and -q are one rotation
  const Mat3 Rm = matrix(I.q * half_rotation(rel));
  k.frame = {{Rm * b.axes.r[0], Rm * b.axes.r[1], Rm * b.axes.r[2]}};
  const Vec3 ai = rotate(I.q, b.ri), aj = rotate(J.q, b.rj);
  k.g = (J.x + aj) - (I.x + ai);
  k.ci = ai + 0.5 * k.g, k.cj = aj - 0.5 * k.g;
  // The gap in the face frame now; the rotation vector of rel is in i's body axes, which are the mean frame's
  // too (sqrt(rel) turns about the same axis), so the rest frame's axes resolve it.
  const Vec3 d = k.frame * k.g, t = b.axes * rotation_vector(rel);
  k.motion = {d.x, d.y, d.z, t.x, t.y, t.z};
  return k;
}

// Bond b's forces. `fs1`, `fs2` are the linear part's shear history (face frame); its new value is out.linear
// (dt = 0 evaluates without advancing it). `keep` (1 - damage) scales the parallel bond's forces on the blocks.
inline FaceBondEval eval_face_bond(const FaceBondFrame& b, const BlockKin3& I, const BlockKin3& J, double dt,
                                   double fs1, double fs2, double keep) {
  FaceBondEval out;
  const FaceKinematics k = face_kinematics(b, I, J);
  const FaceMotion& u = k.motion;
  out.motion = u;
  out.pb = FaceBond::forces(b.k, u);
  // The linear part on the compressed part of the face, at the centroid of that part; the slip rate is the
  // relative velocity of the two blocks' material points there.
  const FaceOverlap o = face_overlap(b.section, u.dn, u.t1, u.t2);
  const Vec3 lever = k.frame.transposed_times({o.c1, o.c2, 0.0});
  const Vec3 pc = k.ci + lever;  // the contact point from i's centroid; from j's it is pc - (x_j - x_i)
  const Vec3 pcj = k.cj + lever;
  const Vec3 vrel = (J.v + cross(J.omega, pcj)) - (I.v + cross(I.omega, pc));
  const Vec3 vs = k.frame * vrel;
  const LinearContact law{b.k.kn, b.k.ks, b.mu, 1.0 / b.section.A};
  out.linear = face_linear_part(law, o, vs.x, vs.y, dt, fs1, fs2);
  // Frame components to world: the parallel bond at the bond point, the linear part at the contact point.
  const FaceForces& f = out.pb;
  const Vec3 fb = k.frame.transposed_times({f.fs1, f.fs2, f.fn});
  const Vec3 mb = k.frame.transposed_times({f.m1, f.m2, f.mt});
  const Vec3 fl = k.frame.transposed_times({out.linear.fs1, out.linear.fs2, out.linear.fn});
  out.f = keep * fb + fl;
  const Vec3 ml = cross(lever, fl);  // the linear part's moment about the bond point
  out.mj = cross(k.cj, out.f) + ml + keep * mb;
  out.mi = -(cross(k.ci, out.f) + ml + keep * mb);
  out.p = I.x + k.ci;
  return out;
}

}  // namespace rbdem::stages
