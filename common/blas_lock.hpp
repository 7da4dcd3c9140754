// One BLAS call at a time in the whole process.
//
// The BLAS that Debian's CHOLMOD, UMFPACK and gmsh link (OpenBLAS, built with OpenMP) is not safe to enter from two
// threads at once: its work buffers are shared, and two calls side by side return numbers that differ from one
// call alone, silently (by round-off or by more). rbdem runs threads of its own that each reach the BLAS: the cases
// of a sweep, the dips of the elastic gate, a Python program's threads. Every call into code that uses the BLAS (the
// 3D static solve's CHOLMOD factor and solves, gmsh's meshing and reading, the deal.II models' direct and AMG
// solves) holds this one lock, so results do not depend on what else the process runs. It is one mutex for the
// whole program (or Python module): the core takes it around the calls into the gmsh module, and hands it to the
// deal.II module, whose solvers take it (continuum/fe_module.hpp); neither module has a copy of its own in use.
#pragma once

#include <mutex>

namespace rbdem {

inline std::mutex& blas_mutex() {
  static std::mutex m;
  return m;
}

// Holds the BLAS for its lifetime.
class BlasLock {
 public:
  BlasLock() : guard_(blas_mutex()) {}

 private:
  std::lock_guard<std::mutex> guard_;
};

}  // namespace rbdem
