// What differs between a two-dimensional and a three-dimensional model, named once per dimension. The engine's
// types (Topology, Model, ModelState, Engine, the boundary components, SimulationImpl) are templates on `dim` in
// deal.II's style and Dim<dim> is where their sizes and names come from; the code above the Simulation interface
// (dem/simulation.hpp) reads the dimension at run time through the functions below.
//
// Dimension 2 is the paper's slice: triangular blocks with three degrees of freedom (u_x, u_y, theta), bonds on
// shared edges. A three-dimensional model adds Dim<3> (tetrahedra, six degrees of freedom, a rotation stored as a
// unit quaternion, bonds on shared triangular faces) and the specialisations of the engine's types.
#pragma once

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rbdem {

template <int dim>
struct Dim;

template <>
struct Dim<2> {
  static constexpr int dof = 3;             // per block: u_x, u_y, theta
  static constexpr int pose = 3;            // per block: x, y (m), theta (rad)
  static constexpr int block_vertices = 3;  // a block is a triangle
  static constexpr int face_vertices = 2;   // a bond's face is an edge
  static constexpr std::array<const char*, 3> pose_names = {"x", "y", "theta"};
  static constexpr std::array<const char*, 3> pose_units = {"m", "m", "rad"};
  static constexpr const char* cell_type = "Triangle";  // XDMF topology of the blocks
  // The world position of the body-frame vector v (dim components) of a block at `pose` (one block's pose
  // components in order): p + R(theta) v.
  static void place(const double* pose, const double* v, double* out) {
    const double c = std::cos(pose[2]), s = std::sin(pose[2]);
    out[0] = pose[0] + c * v[0] - s * v[1];
    out[1] = pose[1] + s * v[0] + c * v[1];
  }
};

// Tetrahedral blocks. The rotation is the unit quaternion (w, x, y, z) that turns the block from its reference
// configuration (the mesh) into its current one, so a block at rest has (1, 0, 0, 0) whatever its shape; its
// principal axes are a constant of the block (dem/rigid3.hpp).
template <>
struct Dim<3> {
  static constexpr int dof = 6;             // per block: u_x, u_y, u_z and three rotations
  static constexpr int pose = 7;            // per block: x, y, z (m), the unit quaternion qw, qx, qy, qz
  static constexpr int block_vertices = 4;  // a block is a tetrahedron
  static constexpr int face_vertices = 3;   // a bond's face is a triangle
  static constexpr std::array<const char*, 7> pose_names = {"x", "y", "z", "qw", "qx", "qy", "qz"};
  static constexpr std::array<const char*, 7> pose_units = {"m", "m", "m", "1", "1", "1", "1"};
  static constexpr const char* cell_type = "Tetrahedron";
  // p + q v q*, with q = (pose[3], pose[4], pose[5], pose[6]) unit: v + 2 w (u x v) + 2 u x (u x v).
  static void place(const double* pose, const double* v, double* out) {
    const double w = pose[3], ux = pose[4], uy = pose[5], uz = pose[6];
    const double tx = 2.0 * (uy * v[2] - uz * v[1]), ty = 2.0 * (uz * v[0] - ux * v[2]),
                 tz = 2.0 * (ux * v[1] - uy * v[0]);
    out[0] = pose[0] + v[0] + w * tx + (uy * tz - uz * ty);
    out[1] = pose[1] + v[1] + w * ty + (uz * tx - ux * tz);
    out[2] = pose[2] + v[2] + w * tz + (ux * ty - uy * tx);
  }
};

// Whether this build's engine models dimension `dim`: 2 and 3.
constexpr bool engine_dimension(int dim) { return dim == 2 || dim == 3; }

// The same at run time, for code above the Simulation interface.
inline void check_dimension(int dim) {
  if (!engine_dimension(dim))
    throw std::invalid_argument("dimension " + std::to_string(dim) + ": this build models dimensions 2 and 3");
}

// f(Dim<dim>{}) for a dimension the engine models; throws (check_dimension) for any other.
template <class F>
decltype(auto) with_dimension(int dim, F&& f) {
  check_dimension(dim);
  if (dim == 3) return f(Dim<3>{});
  return f(Dim<2>{});
}

inline int pose_size(int dim) {
  return with_dimension(dim, [](auto d) { return decltype(d)::pose; });
}
inline int dof_per_block(int dim) {
  return with_dimension(dim, [](auto d) { return decltype(d)::dof; });
}
inline int block_vertices(int dim) {
  return with_dimension(dim, [](auto d) { return decltype(d)::block_vertices; });
}
inline const char* pose_name(int dim, int component) {
  return with_dimension(dim, [&](auto d) { return decltype(d)::pose_names[std::size_t(component)]; });
}
inline const char* pose_unit(int dim, int component) {
  return with_dimension(dim, [&](auto d) { return decltype(d)::pose_units[std::size_t(component)]; });
}
inline const char* cell_type(int dim) {
  return with_dimension(dim, [](auto d) { return decltype(d)::cell_type; });
}
inline void place(int dim, const double* pose, const double* v, double* out) {
  with_dimension(dim, [&](auto d) { decltype(d)::place(pose, v, out); });
}

}  // namespace rbdem
