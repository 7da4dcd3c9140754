// Small specimens with closed-form answers, shared by the verification cases and the unit tests.
#pragma once

#include "dem/scene.hpp"
#include "mesh/trimesh.hpp"

namespace rbdem::verify {

// A rhombus of two isosceles triangles sharing the edge (-a, 0)-(a, 0): block 0 below, block 1 above. Both
// centroids lie on the y axis at -b/3 and b/3, so a normal force at the edge midpoint makes no moment, and the
// bond's centroid distance is d = 2 b / 3 and its length L = 2 a.
inline TriMesh rhombus(double a, double b, int layer0 = 0, int layer1 = 0) {
  TriMesh m;
  m.nodes = {{-a, 0}, {a, 0}, {0, -b}, {0, b}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}};
  m.layer = {layer0, layer1};
  m.layer_names = {"layer_0", "layer_1"};
  return m;
}

// Two right triangles with their hypotenuses facing each other, 0.1 a apart, not bonded.
inline TriMesh facing_triangles(double a) {
  TriMesh m;
  m.nodes = {{0, 0}, {a, a}, {0, a}, {0.1 * a, 0}, {1.1 * a, 0}, {1.1 * a, a}};
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  m.layer = {0, 0};
  m.layer_names = {"a", "b"};
  return m;
}

// The paper scene with unbreakable bonds and no damping: pure elastic dynamics.
inline Scene elastic_scene() {
  Scene s;
  s.numerics.damping = 0.0;
  s.rock.tensile_strength = s.rock.cohesion = s.joint.tensile_strength = s.joint.cohesion = 1e15;
  return s;
}

}  // namespace rbdem::verify
