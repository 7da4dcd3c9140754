// What the two halves of the compiled module share (python/bindings.cpp: the test functions, the gate, verify,
// sweeps; python/simulation.cpp: rbdem.Simulation): the scene keys from Python, the scene's resolution as the
// command line's, the records as dicts of NumPy arrays, and the errors the Python layer maps to its classes.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "dem/driver/result.hpp"
#include "dem/record_columns.hpp"
#include "dem/records.hpp"
#include "dem/scene.hpp"
#include "dem/specimen.hpp"

namespace rbdem::python {

namespace py = pybind11;

// One scene key set from Python: `origin` names where it came from in messages ("scene", "overrides").
struct Assignment {
  std::string origin, key, value;
};

// Sets the keys in order, naming the Python argument instead of the CLI's --set in the messages.
void apply_assignments(Scene& scene, const std::vector<Assignment>& sets);

// The scene of a Python call, as the CLI's resolve_scene (apps/cli_common.cpp) makes it: defaults <- file <- the
// dict scene's keys <- beta <- overrides, validated, then checked for likely unit mistakes unless `force`.
Scene resolve(const std::string& file, const std::vector<Assignment>& scene_keys, std::optional<double> beta,
              const std::vector<Assignment>& overrides, bool force);

py::array_t<double> array_of(const std::vector<double>& v);
// The curve's table, plus the mean platen stress (stress_pa) for convenience.
py::dict curve_arrays(int dim, const std::vector<CurvePoint>& curve);
// Each frame as a dict: its table's scalars and its pose components (x_m, y_m, theta_rad in 2D).
py::list frame_list(const std::vector<Frame>& frames);
// The blocks of the specimen as meshed (before loading): centroid, area, mass and the layer of each block.
py::dict block_arrays(const Specimen& sp);

// The compiled class rbdem.Simulation wraps (python/simulation.cpp).
void bind_simulation(py::module_& m);

// Exceptions the Python layer maps to its own classes (python/rbdem/__init__.py).
struct GateFailed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The Python exception a hook caught (KeyboardInterrupt from PyErr_CheckSignals, or the callback's own), raised
// again once the run has unwound.
struct PendingError {
  std::optional<py::error_already_set> error;
};

// The driver's progress hook for a run from Python: with the GIL taken, checks for Ctrl-C and calls `progress`
// (None: no callback) as progress(step, strain, stress, peak, cracks); a Python exception from either sets `cancel`
// and is kept in `pending`. Always installed, callback or not: it is where Ctrl-C is noticed. The hook refers to
// `progress`, `cancel` and `pending` and holds no Python object itself (the driver copies it without the GIL).
std::function<void(const RunProgress&)> progress_hook(const py::object& progress, std::atomic<bool>& cancel,
                                                      PendingError& pending);

// A table of records as a dict of NumPy arrays, one per field of its field table (dem/records.hpp), under the
// names of the CSV columns; the enumerations as lists of their names.
template <class Record>
py::dict record_arrays(int dim, const std::vector<Record>& rows) {
  py::dict d;
  write_columns(dim, rows, [&](const Field& field, const auto& column, bool) {
    using V = typename std::decay_t<decltype(column)>::value_type;
    if constexpr (std::is_enum_v<V>) {
      std::vector<std::string> names;
      for (const V v : column) names.push_back(name_of(v));
      d[field.name] = names;
    } else if constexpr (std::is_same_v<V, std::string>) {
      d[field.name] = column;
    } else {
      py::array_t<V> a(py::ssize_t(column.size()));
      std::copy(column.begin(), column.end(), a.mutable_data());
      d[field.name] = a;
    }
  });
  return d;
}

}  // namespace rbdem::python

namespace pybind11::detail {
// A scene key from Python: (origin, key, value) with the value already as text (python/rbdem/__init__.py).
template <>
struct type_caster<rbdem::python::Assignment> {
  PYBIND11_TYPE_CASTER(rbdem::python::Assignment, const_name("tuple[str, str, str]"));
  bool load(handle src, bool convert) {
    make_caster<std::tuple<std::string, std::string, std::string>> t;
    if (!t.load(src, convert)) return false;
    auto [origin, key, v] = cast_op<std::tuple<std::string, std::string, std::string>>(std::move(t));
    value = {origin, key, v};
    return true;
  }
};
}  // namespace pybind11::detail
