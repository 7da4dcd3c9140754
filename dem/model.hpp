// The constant data of a DEM model: what the scene and the topology fix and no step changes. Blocks, bond frames,
// the laws of each bond kind, the CSR adjacency of the force gather, the platen stiffnesses. Plain arrays
// (structure of arrays): what the bond kernel reads for one bond sits at the same index of contiguous arrays, so
// the loop streams them and can be vectorised (dem/stages/bonds.cpp). The mutable state is ModelState
// (dem/state.hpp); the stages read both (docs/architecture.md).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "dem/laws/linear_contact.hpp"
#include "dem/laws/parallel_bond.hpp"
#include "dem/scene.hpp"
#include "dem/topology.hpp"

namespace rbdem {

// The laws and parameters of one material (dem/materials.hpp: rock, joint, joint2, rock2).
struct BondKindLaw {
  double modulus = 0;         // Pa, E*
  double kappa = 1;           // k_n / k_s
  double mu = 0;              // Coulomb coefficient of the linear part and of later contacts of this kind
  bool slip_bonded = false;   // the linear part of an intact bond slides at mu F_n (else it sticks: mu = inf)
  double inertia_divisor = 12.0;  // I = t L^3 / inertia_divisor (12; common/fault_injection.hpp plants 6)
  ParallelBond bond;
  // The Coulomb coefficient of the linear part while the bond is intact.
  double bonded_mu() const { return slip_bonded ? mu : std::numeric_limits<double>::infinity(); }
};

// Constant per-bond data, one array per field, in bond order. Lever arms from each centroid to the edge midpoint
// and the reference normal (i -> j), in the blocks' reference frames; the edge length and its inverse; the
// stiffnesses K = (E*/d) L t (N/m, the parallel bond's normal stiffness and the closed linear part's),
// Ks = K / kappa and KI = K L^2 / 12 (N m); the area A = L t.
struct BondFrames {
  std::vector<double> rix, riy, rjx, rjy, n0x, n0y;
  std::vector<double> L, inv_L, K, Ks, KI, A;
  std::vector<double> rupture;  // r_u of a softening bond (docs/model.md); 0 for brittle kinds
  // The kind's law per bond, so the kernel streams it: the linear part's Coulomb coefficient while bonded (+inf:
  // it sticks), the strength in force units sigma_c A and c A, tan(phi_b) and beta_m.
  std::vector<double> mu_bonded, tension_limit, cohesion_A, tan_phi, beta_m;
  std::vector<double> strength_factor;  // the bond's strength over its material's (1 without heterogeneity)
  std::size_t size() const { return L.size(); }
};

// The stiffnesses of one bond (diagnostics, the static solve).
struct BondStiffness {
  double kbnA, kbsA, kbnI;  // parallel bond: N/m, N/m, N m
  double knA, ksA, mu;      // linear part (closed edge): N/m, N/m, -
  bool slip_bonded;         // the linear part slides while the bond is intact
  double A, I, L;           // m^2, m^4, m
};

struct Model {
  const Topology* topology = nullptr;
  double thickness = 1.0, width = 0, height = 0;  // m
  double xmin = 0, xmax = 0, ymin = 0, ymax = 0;  // m, the specimen's bounding box

  // blocks
  std::vector<double> mass, inv_mass, inertia;  // kg, 1/kg, kg m^2 (mass scaling applied)
  std::vector<double> x0, y0;                   // m, reference centroid
  std::vector<double> radius, inradius;         // m
  std::vector<std::array<double, 6>> shape;     // body-frame vertices (m), counter-clockwise
  std::vector<int> layer;
  std::vector<std::uint8_t> block_material;     // material id per block (rock or rock2)
  std::vector<int> fixed;  // kinematically fixed (tests, the reference studies); int, not a byte: the integrator
                           // reads it in vector lanes beside doubles, and the vectoriser takes no byte flags there
  std::size_t num_blocks() const { return mass.size(); }

  // bonds
  std::vector<int> bi, bj;
  std::vector<BondKind> kind;
  std::vector<std::uint8_t> material;  // material id per bond (dem/materials.hpp), the index of its law
  BondFrames frame;
  std::array<BondKindLaw, 4> law;      // by material id
  std::size_t num_bonds() const { return bi.size(); }
  // CSR of the force gather: entries csr_entry[csr_offset[b] .. csr_offset[b+1]) are 2 bond + (1 if b is j).
  std::vector<int> csr_offset, csr_entry;
  // The same entries, gather_width per block (the most bonds of any block, at least 3: a triangle mesh's blocks
  // have at most three), padded with 2 num_bonds() + 1, whose slot is always zero: the integrator's gather then has
  // no loop of varying length (dem/stages/integrator.cpp).
  std::vector<int> gather;
  int gather_width = 3;

  // platens: the half-plane contact of each block (k_n from the block's mirror image, d = 2 inradius)
  std::vector<double> platen_kn;    // Pa/m
  std::vector<double> platen_lref;  // m, the block's edge on the platen, else the inradius-based length
  double skin = 0;                  // m, broad-phase skin (0.2 mean edge lengths)

  // The jacket: the outer edges a confining pressure acts on (every boundary edge not on a platen), with their end
  // points in the block's reference frame (relative to the reference centroid), outside to the right of a -> b.
  struct JacketEdges {
    std::vector<int> block;
    std::vector<double> ax, ay, bx, by;  // m
    std::size_t size() const { return block.size(); }
  } jacket;

  BondStiffness stiffness(int bond) const;
  // The linear contact law of a pair of blocks after their bond broke (bond >= 0) or that were never
  // neighbours (bond = -1).
  LinearContact pair_law(int i, int j, int bond) const;
  // The linear contact law of a block against a platen.
  LinearContact platen_law(int block, double mu) const;
  // Whether blocks i and j share an intact bond, given the bonds' broken flags.
  bool bonded(int i, int j, const std::vector<std::uint8_t>& broken) const;
  // Whether block b has at least one intact bond.
  bool has_intact_bond(int b, const std::vector<std::uint8_t>& broken) const;
};

// Builds the model of `topo` with the scene's materials and mass scaling. The model keeps a pointer to `topo`,
// which must outlive it.
Model build_model(const Topology& topo, const Scene& scene, double mass_scaling);

}  // namespace rbdem
