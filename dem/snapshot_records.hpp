// A table of records (cracks) in a snapshot: one snapshot column per stored field of the record's field table
// (dem/record_columns.hpp), named "<name>/<field>", enums as bytes. The 2D and 3D states store their crack logs
// through these, so a field added to a record is checkpointed in both dimensions without a change here.
#pragma once

#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "dem/record_columns.hpp"
#include "dem/snapshot.hpp"

namespace rbdem {

template <class Record>
void save_records(int dim, const std::vector<Record>& rows, const std::string& name, Extent extent, Snapshot& snap) {
  write_columns(dim, rows, [&](const Field& f, const auto& column, bool stored) {
    if (!stored) return;
    using V = typename std::decay_t<decltype(column)>::value_type;
    if constexpr (std::is_enum_v<V>) {
      std::vector<std::uint8_t> bytes(column.size());
      for (std::size_t k = 0; k < column.size(); ++k) bytes[k] = std::uint8_t(column[k]);
      snap.add(name + "/" + f.name, extent, std::move(bytes));
    } else {
      snap.add(name + "/" + f.name, extent, column);
    }
  });
}

// The rows back; throws std::invalid_argument when the columns differ in length (read_columns).
template <class Record>
std::vector<Record> load_records(int dim, const Snapshot& snap, const std::string& name) {
  return read_columns<Record>(dim, [&](const Field& f, auto& column) {
    using V = typename std::decay_t<decltype(column)>::value_type;
    if constexpr (std::is_enum_v<V>) {
      const auto& bytes = snap.get<std::vector<std::uint8_t>>(name + "/" + f.name);
      column.resize(bytes.size());
      for (std::size_t k = 0; k < bytes.size(); ++k) column[k] = V(bytes[k]);
    } else {
      column = snap.get<std::vector<V>>(name + "/" + f.name);
    }
  });
}

}  // namespace rbdem
