// The constant data of a DEM model: what the scene and the topology fix and no step changes. Blocks, bond frames,
// the laws of each bond kind, the CSR adjacency of the force gather, the platen stiffnesses. Plain arrays
// (structure of arrays): what the bond kernel reads for one bond sits at the same index of contiguous arrays, so
// the loop streams them and can be vectorised (dem/stages/bonds.cpp). The mutable state is ModelState
// (dem/state.hpp); the stages read both (docs/architecture.md).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "dem/laws/linear_contact.hpp"
#include "dem/laws/parallel_bond.hpp"
#include "dem/scene.hpp"
#include "dem/static_result.hpp"
#include "dem/topology.hpp"

namespace rbdem {

// The stiffnesses of one bond in the linearised form (the static solve, the stability estimate, the energies), and
// the linearised law of its linear part.
struct BondStiffness {
  double kbnA, kbsA, kbnI;  // parallel bond: N/m, N/m, N m
  double knA, ksA, mu;      // linear part (closed edge): N/m, N/m, -
  bool slip_bonded;         // the linear part slides while the bond is intact
  double A, I, L;           // m^2, m^4, m: the section (ParallelBond::section) and the edge length

  // The linear part's state (StaticResult::LinearState) at the opening dn and shear displacement ds of the bond
  // point: open unless closed (dn < 0); closed, it sticks while |k_s A ds| <= mu k_n A (-dn), else it slides.
  std::uint8_t linear_state(double dn, double ds) const {
    if (!(dn < 0.0)) return StaticResult::open;
    return !slip_bonded || std::abs(ksA * ds) <= mu * (-knA * dn)
               ? StaticResult::stick
               : (ds > 0 ? StaticResult::slip_positive : StaticResult::slip_negative);
  }
  // Its shear force in `state`: -k_s A ds sticking, -+ mu k_n A (-dn) sliding, 0 open.
  double linear_shear(std::uint8_t state, double dn, double ds) const {
    if (state == StaticResult::stick) return -ksA * ds;
    if (state == StaticResult::open) return 0.0;
    return (state == StaticResult::slip_positive ? -1.0 : 1.0) * mu * (-knA * dn);
  }
  // d F_s / d dn of a sliding linear part (F_s = sign(ds) mu k_n A dn): the non-symmetric term of the static
  // stiffness; 0 in the other states.
  double slip_coupling(std::uint8_t state) const {
    if (state != StaticResult::slip_positive && state != StaticResult::slip_negative) return 0.0;
    return -(state == StaticResult::slip_positive ? 1.0 : -1.0) * mu * knA;
  }
};

// The laws and parameters of one material (dem/materials.hpp: rock, joint, joint2, rock2).
struct BondKindLaw {
  double modulus = 0;         // Pa, E*
  double kappa = 1;           // k_n / k_s
  double mu = 0;              // Coulomb coefficient of the linear part and of later contacts of this kind
  bool slip_bonded = false;   // the linear part of an intact bond slides at mu F_n (else it sticks: mu = inf)
  double tan_dilation = 0;    // tan(i) of its contacts after breakage (LinearContact::tan_dilation)
  ParallelBond bond;
  // The Coulomb coefficient of the linear part while the bond is intact.
  double bonded_mu() const { return slip_bonded ? mu : std::numeric_limits<double>::infinity(); }
  // The linearised stiffnesses of a bond of normal stiffness K (N/m) on an edge of length L (m) in a slice of
  // thickness t (m): the parallel bond's K, K / kappa and K L^2 / 12 (ParallelBond::rotational), the closed linear
  // part's K and K / kappa, and the section.
  BondStiffness stiffness(double K, double L, double t) const {
    const ParallelBond::Section sec = bond.section(L, t);
    return {K, K / kappa, bond.rotational(K, L), K, K / kappa, mu, slip_bonded, sec.A, sec.I, L};
  }
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
  std::vector<double> strength_factor;   // the bond's strength over its material's (1 without heterogeneity)
  std::vector<double> stiffness_factor;  // the bond's E* over its material's (1 without stiffness heterogeneity)
  std::size_t size() const { return L.size(); }
};

template <int dim>
struct Model;

template <>
struct Model<2> {
  const Topology<2>* topology = nullptr;
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

  double skin = 0;                  // m, broad-phase skin (0.2 mean edge lengths)

  BondStiffness stiffness(int bond) const;
  // The linear contact law of a pair of blocks after their bond broke (bond >= 0) or that were never
  // neighbours (bond = -1).
  LinearContact pair_law(int i, int j, int bond) const;
  // Whether blocks i and j share an intact bond, given the bonds' broken flags.
  bool bonded(int i, int j, const std::vector<std::uint8_t>& broken) const;
  // Whether block b has at least one intact bond.
  bool has_intact_bond(int b, const std::vector<std::uint8_t>& broken) const;
};

// Builds the model of `topo` with the scene's materials and mass scaling. The model keeps a pointer to `topo`,
// which must outlive it.
Model<2> build_model(const Topology<2>& topo, const Scene& scene, double mass_scaling);

}  // namespace rbdem
