// The constant data of a 3D DEM model: one rigid block per tetrahedron of a TetMesh, one face bond per shared face
// (dem/laws/face_bond.hpp), the boundary faces the platens and the jacket act on. What the scene and the mesh fix
// and no step changes; the mutable state is ModelState<3> (dem/state3.hpp). The 3D counterpart of Model<2>
// (dem/model.hpp): per-block and per-bond arrays in block and bond order.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "dem/model.hpp"
#include "dem/records.hpp"
#include "dem/rigid3.hpp"
#include "dem/scene.hpp"
#include "dem/stages/face_bond_kernel.hpp"
#include "dem/stages/face_bonds3.hpp"
#include "mesh/tetmesh.hpp"

namespace rbdem {

// The law of one material in 3D: the face bond's strength and softening, its modulus and stiffness ratio, the
// linear part's friction.
struct FaceKindLaw {
  double modulus = 0;        // Pa, E*
  double kappa = 1;          // k_n / k_s
  double mu = 0;             // Coulomb coefficient of the linear part after breakage (and while bonded, with
  bool slip_bonded = false;  // slip_when_bonded)
  FaceBond bond;
  double bonded_mu() const;  // +inf unless slip_bonded
};

// A face of the specimen's surface on one block: its tag, area, the centroid from the block's centroid and the
// outward normal, at rest.
struct SurfaceFace {
  int block = 0;
  FaceTag tag = FaceTag::lateral;
  double area = 0;  // m^2
  double polar = 0;  // m^4, the polar moment about the face's centroid
  Vec3 r, normal;
  std::array<Vec3, 3> vertices;  // from the block's centroid, at rest
};

template <>
struct Model<3> {
  const TetMesh* mesh = nullptr;
  Vec3 lo, hi;                  // m, the bounding box at rest
  double volume = 0;            // m^3, the blocks' sum
  double loaded_area = 0;       // m^2, the sum of the top faces' areas (the platens' area)
  std::array<double, 2> axis{};  // m, the specimen's vertical axis (x, y): the centre of its bounding box

  // blocks
  std::vector<RigidBody3> body;          // mass and principal moments (mass scaling applied), principal axes
  std::vector<Vec3> x0;                  // m, reference centroid
  std::vector<std::array<Vec3, 4>> shape;  // m, the vertices from the centroid at rest
  std::vector<double> block_volume, inradius;  // m^3, m
  std::vector<int> layer;
  std::vector<int> fixed;
  std::size_t num_blocks() const { return body.size(); }

  // bonds
  std::vector<int> bi, bj;
  std::vector<BondKind> kind;
  std::vector<std::uint8_t> material;        // material id (dem/materials.hpp): rock, joint or joint2
  std::vector<int> interface;                // -1 rock, 0 the first joint set, 1 the second
  std::vector<std::array<int, 3>> face;      // mesh nodes of the shared face
  std::vector<stages::FaceBondFrame> frame;  // at rest: lever arms, face frame, section, stiffnesses
  std::vector<double> rupture;               // r_u of a softening bond; 0 brittle
  std::vector<double> strength_factor;       // the bond's strength over its material's (Weibull heterogeneity)
  std::array<FaceKindLaw, 4> law;            // by material id
  stages::FaceBondTable table;               // what the bond stage streams: the above as arrays, strengths in N
  std::size_t num_bonds() const { return bi.size(); }
  // The bonds of each block, in bond order: entries gather[offset[b] .. offset[b+1]) are 2 bond + (1 if b is j).
  std::vector<int> offset, gather;

  std::vector<SurfaceFace> surface;  // the specimen's surface, in the mesh's order

  // The face bond's law of bond b with its strength factor applied.
  FaceBond bond_law(std::size_t b) const;
  bool has_intact_bond(int block, const std::vector<std::uint8_t>& broken) const;
};

// The model of `mesh` with the scene's materials (rock inside a layer, joint across the first set's planes, joint2
// across the second's), density and mass scaling. The model points to `mesh`, which must outlive it. Throws
// SceneError for a scene the 3D model does not take (rock2 layers, joint2 groups by name).
Model<3> build_model(const TetMesh& mesh, const Scene& scene, double mass_scaling);

}  // namespace rbdem
