// The geometry of a tetrahedral block and of a bond's triangular face, in closed form: what a 3D model's blocks
// (mass, centroid, inertia, principal axes) and bonds (the face's area, normal and second moments) are built from.
// docs/theory.md, "The face bond in 3D".
//
// Second moments of a simplex. For the vertices p_k of a triangle (area A) or of a tetrahedron (volume V),
// measured from any origin, the integrals of the dyad x x^T over the simplex are
//     triangle:     A / 12 (sum_k p_k p_k^T + s s^T),      s = sum_k p_k
//     tetrahedron:  V / 20 (sum_k p_k p_k^T + s s^T)
// (the simplex's quadrature of degree two; Tonon 2004 writes the tetrahedron's out term by term). About the
// centroid s = 0 and only the sum of the vertex dyads is left. The inertia tensor of a uniform block of density rho
// is rho (tr(C) 1 - C) with C the tetrahedron's integral.
#pragma once

#include <array>

#include "dem/vec3.hpp"

namespace rbdem {

using Tet = std::array<Vec3, 4>;
using Tri = std::array<Vec3, 3>;

// A symmetric 3x3 tensor (components xx, yy, zz, yz, xz, xy).
struct Sym3 {
  double xx = 0, yy = 0, zz = 0, yz = 0, xz = 0, xy = 0;
  Vec3 operator*(Vec3 v) const {
    return {xx * v.x + xy * v.y + xz * v.z, xy * v.x + yy * v.y + yz * v.z, xz * v.x + yz * v.y + zz * v.z};
  }
};

// Signed volume (m^3): positive when (p1 - p0, p2 - p0, p3 - p0) is right-handed.
double signed_volume(const Tet& t);
Vec3 centroid(const Tet& t);
// The inertia tensor (kg m^2) of the uniform tetrahedron of density rho (kg/m^3) about its centroid.
Sym3 inertia_tensor(const Tet& t, double rho);

// Principal moments (ascending) and axes of a symmetric tensor: rows of `axes` are the unit axes, right-handed,
// with T axes[k] = moments[k] axes[k]; `rotation` is the unit quaternion that turns the world axes x, y, z into
// them (its matrix has the axes as columns).
struct Principal {
  Vec3 moments;
  Mat3 axes;
  Quat rotation;
};
Principal principal(const Sym3& tensor);

// A uniform tetrahedral block: what the integrator needs of it.
struct TetBody {
  double volume = 0, mass = 0;  // m^3, kg
  Vec3 centroid;                // m
  Principal inertia;            // principal moments (kg m^2) and axes about the centroid
};
TetBody tet_body(const Tet& t, double rho);

// A bond's triangular face: area, centroid, the unit normal (p1 - p0) x (p2 - p0) / |..| (so the vertex order sets
// its sense), the in-plane principal axes e1, e2 (e1 x e2 = n; e1 along the face's longer spread) and the second
// moments of area about them through the centroid, I1 = int y2^2 dA and I2 = int y1^2 dA (so I1 <= I2), the polar
// moment J = I1 + I2, the vertices in (y1, y2) coordinates, and the largest distance r_max from the centroid to a
// vertex.
struct Face {
  double area = 0;  // m^2
  Vec3 centroid, normal, e1, e2;
  double I1 = 0, I2 = 0, J = 0;  // m^4
  std::array<double, 3> y1{}, y2{};  // m
  double r_max = 0;                  // m
};
Face face_of(const Tri& t);

}  // namespace rbdem
