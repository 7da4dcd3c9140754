// The deal.II module's entry point (see fe_module.hpp): the table of its solves. Everything else in the module is
// hidden, so its definitions never clash with the front library's forwarding functions of the same names.
#include "continuum/fe_module.hpp"
#include "continuum/solvers.hpp"

extern "C" __attribute__((visibility("default"))) const rbdem::continuum::FeModule* rbdem_fe_module() {
  using namespace rbdem::continuum;
  static const FeModule table = [] {
    FeModule m;
    m.solve_elastic = &solve_elastic;
    m.solve_elastic_jointed = &solve_elastic_jointed;
    m.solve_disc = &solve_disc;
    m.solve_hole = &solve_hole;
    m.layer_interface_edges = &layer_interface_edges;
    m.count_node_copies = &count_node_copies;
    m.dealii_version = &dealii_version;
    m.solve_elastic_3d = &solve_elastic_3d;
    m.solve_elastic_3d_jointed = &solve_elastic_3d_jointed;
    m.share_blas_lock = &internal::share_blas_lock;
    return m;
  }();
  return &table;
}
