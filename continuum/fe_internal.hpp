// What the deal.II models of continuum/ share (fe_model.cpp, fe_joints.cpp, fe_disc.cpp) besides the linear solves
// (solvers.hpp); defined in fe_model.cpp. Internal to continuum/: it includes deal.II, which nothing outside this
// folder may.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <vector>

#include <deal.II/base/quadrature.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>

#include "continuum/fe_3d.hpp"
#include "continuum/fe_model.hpp"

namespace rbdem::continuum::internal {

// Wall time since the last lap (or construction), in seconds: the stage timings of the solvers' results.
class Stopwatch {
 public:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// The displacement space of the simplex models (the plane, disc and 3D twins): vector FE_SimplexP of `degree` on
// `tria`, the linear mapping, the Gauss rule of degree + 1, the DoFs distributed and the matrix's sparsity pattern.
template <int dim>
struct SimplexSpace {
  SimplexSpace(const dealii::Triangulation<dim>& tria, unsigned degree)
      : fe(dealii::FE_SimplexP<dim>(degree), dim), mapping(dealii::FE_SimplexP<dim>(1)), quadrature(degree + 1),
        dof(tria) {
    dof.distribute_dofs(fe);
    dealii::DynamicSparsityPattern dsp(dof.n_dofs(), dof.n_dofs());
    dealii::DoFTools::make_sparsity_pattern(dof, dsp);
    pattern.copy_from(dsp);
  }
  const dealii::FESystem<dim> fe;
  const dealii::MappingFE<dim> mapping;
  const dealii::QGaussSimplex<dim> quadrature;
  dealii::DoFHandler<dim> dof;
  dealii::SparsityPattern pattern;
};

// The DoF of each vertex's displacement components, vertex -> {u_x, u_y(, u_z)}: the node copies of the models with
// the joints (one vertex per copy), whose interface elements and ties address the copies' DoFs directly.
template <int dim>
std::vector<std::array<dealii::types::global_dof_index, dim>> vertex_dofs(const dealii::DoFHandler<dim>& dof,
                                                                          std::size_t n_vertices) {
  const dealii::FiniteElement<dim>& fe = dof.get_fe();
  std::vector<std::array<dealii::types::global_dof_index, dim>> out(n_vertices);
  for (const auto& cell : dof.active_cell_iterators())
    for (const unsigned v : cell->vertex_indices())
      for (unsigned k = 0; k < fe.n_dofs_per_vertex(); ++k) {
        const unsigned component = fe.system_to_component_index(v * fe.n_dofs_per_vertex() + k).first;
        out[cell->vertex_index(v)][component] = cell->vertex_dof_index(v, k);
      }
  return out;
}

// Voigt [xx, yy, xy] with engineering shear -> the tensor with sigma = C : eps.
dealii::SymmetricTensor<4, 2> stiffness_tensor(const Stiffness3& C);

// K += the elastic stiffness of every cell of `dof` (vector-valued, C constant), integrated with FEValues.
void assemble_fe_values(const dealii::DoFHandler<2>& dof, const dealii::Mapping<2>& mapping,
                        const dealii::Quadrature<2>& q, const dealii::SymmetricTensor<4, 2>& C,
                        dealii::SparseMatrix<double>& K);

// ---- What the two 3D twins share (fe_3d.cpp defines them; fe_joints3.cpp uses them) ------------------------------

// sigma = C : eps with C = S^-1, S the rotated compliance in Voigt form with engineering shear: C_ijkl is the Voigt
// entry of the pairs (ij) and (kl) (the engineering factor 2 of a shear strain is the sum over kl and lk).
dealii::SymmetricTensor<4, 3> stiffness_tensor_3d(const theory::TIConstants& c, double dip_deg,
                                                  double dip_direction_deg);

// The specimen's heights (the platens) and the tolerance of a node on them (1e-6 of the largest extent).
struct Extent3 {
  double zmin = 0, zmax = 0, tol = 0;
  dealii::Point<3> centre;  // of the bounding box: where the AMG's rotation modes turn about
};
Extent3 extent_of(const TetMesh& mesh);

// Volume integrals of the solution: the volume, sigma_zz and the strain (plus, in the jointed model, the
// interfaces' jumps).
struct Integrals3 {
  double volume = 0, sigma_zz = 0;
  dealii::SymmetricTensor<2, 3> strain;
};

// The axial force, the two moduli and the lateral strains and Poisson's ratios of fe_3d.hpp from the integrals.
void fill_moduli_3d(const Integrals3& sum, const Extent3& z, double dip_deg, double dip_direction_deg,
                    double platen_displacement, Fe3Result& r);

}  // namespace rbdem::continuum::internal
