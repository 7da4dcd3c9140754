// A table of records (dem/records.hpp) in an HDF5 group: one 1-D dataset per field, named after it. result.h5's
// /history and /cracks and the checkpoint's curve and crack log are written and read by walking the records'
// field tables (dem/record_columns.hpp), so a field added to a record is stored without a change here. Doubles are
// stored as float64, int as int32, long and sizes as int64, the enumerations as int32 (their values).
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "dem/record_columns.hpp"
#include "io/h5.hpp"

namespace rbdem::io {

namespace detail {

// The stored element type of a field's value type.
template <class V>
using stored_t = std::conditional_t<std::is_same_v<V, double>, double,
                 std::conditional_t<std::is_same_v<V, long> || std::is_same_v<V, std::size_t>, std::int64_t,
                                    std::int32_t>>;

}  // namespace detail

// Writes every field of the rows (derived fields too, unless `stored_only`) into the group `loc`.
template <class Record>
void write_table(const h5::Writer& w, hid_t loc, int dim, const std::vector<Record>& rows, bool stored_only = false) {
  write_columns(dim, rows, [&](const Field& field, const auto& column, bool stored) {
    using V = typename std::decay_t<decltype(column)>::value_type;
    if (stored_only && !stored) return;
    if constexpr (std::is_same_v<V, std::string>) {
      static_assert(sizeof(V) == 0, "string fields are written as attributes, not table columns");
    } else {
      using S = detail::stored_t<V>;
      if constexpr (std::is_same_v<S, V>) {
        w.dataset(loc, field.name, column);
      } else {
        std::vector<S> out(column.size());
        for (std::size_t k = 0; k < column.size(); ++k) out[k] = S(column[k]);
        w.dataset(loc, field.name, out);
      }
    }
  });
}

// The rows back from the group `loc`. A stored field whose dataset is missing (a file written before the field
// existed) keeps its default in every row; columns of different lengths fail naming `file`.
template <class Record>
std::vector<Record> read_table(const h5::Reader& rd, hid_t loc, int dim, const std::string& file) {
  std::size_t rows = 0;
  bool found = false;
  Record::fields(dim, [&](const Field& field, auto get) {
    if (found || !stored_field<decltype(get), Record> || H5Lexists(loc, field.name, H5P_DEFAULT) <= 0) return;
    using V = std::decay_t<decltype(get(std::declval<const Record&>()))>;
    rows = rd.template dataset<detail::stored_t<V>>(loc, field.name).size(), found = true;
  });
  try {
    return read_columns<Record>(dim, [&](const Field& field, auto& column) {
      using V = typename std::decay_t<decltype(column)>::value_type;
      if (H5Lexists(loc, field.name, H5P_DEFAULT) <= 0) {
        column.assign(rows, V{});
        return;
      }
      const std::vector<detail::stored_t<V>> in = rd.template dataset<detail::stored_t<V>>(loc, field.name);
      column.resize(in.size());
      for (std::size_t k = 0; k < in.size(); ++k) column[k] = V(in[k]);
    });
  } catch (const std::invalid_argument& e) {
    h5::fail(file, std::string("reading a table (") + e.what() + ")");
  }
}

// One record's fields as attributes of the group `loc` (a frame's step, time, ... and label), and back.
template <class Record>
void write_attributes(const h5::Writer& w, hid_t loc, int dim, const Record& record) {
  Record::fields(dim, [&](const Field& field, auto get) {
    using V = std::decay_t<decltype(get(record))>;
    if constexpr (std::is_same_v<V, std::string>) w.attribute(loc, field.name, get(record));
    else w.attribute(loc, field.name, detail::stored_t<V>(get(record)));
  });
}

template <class Record>
void read_attributes(const h5::Reader& rd, hid_t loc, int dim, Record& record) {
  Record::fields(dim, [&](const Field& field, auto get) {
    if constexpr (stored_field<decltype(get), Record>) {
      using V = std::decay_t<decltype(get(record))>;
      if constexpr (std::is_same_v<V, std::string>) get(record) = rd.attribute_string(loc, field.name);
      else get(record) = V(rd.template attribute<detail::stored_t<V>>(loc, field.name));
    }
  });
}

}  // namespace rbdem::io
