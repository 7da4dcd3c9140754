// A table of records (dem/records.hpp) as columns, one per field of its field table: what every writer stores (the
// checkpoint, result.h5, the CSV files, the Python records) and what the readers give back. Writing a new field of
// a record needs no change here or in the writers.
#pragma once

#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "dem/records.hpp"

namespace rbdem {

// Calls f(field, column, stored) for each field of Record's table, in its order: `column` a std::vector of the
// field's value type with that field of every row, `stored` false for derived fields.
template <class Record, class F>
void write_columns(int dim, const std::vector<Record>& rows, F&& f) {
  Record::fields(dim, [&](const Field& field, auto get) {
    using V = std::decay_t<decltype(get(std::declval<const Record&>()))>;
    std::vector<V> column;
    column.reserve(rows.size());
    for (const Record& r : rows) column.push_back(get(r));
    f(field, column, stored_field<decltype(get), Record>);
  });
}

// The rows back from their stored columns: for each stored field, f(field, column) fills `column` (a std::vector
// of the field's value type) from the store. Throws std::invalid_argument when two columns differ in length.
template <class Record, class F>
std::vector<Record> read_columns(int dim, F&& f) {
  std::vector<Record> rows;
  bool first = true;
  Record::fields(dim, [&](const Field& field, auto get) {
    if constexpr (stored_field<decltype(get), Record>) {
      using V = std::decay_t<decltype(get(std::declval<Record&>()))>;
      std::vector<V> column;
      f(field, column);
      if (first) rows.resize(column.size()), first = false;
      if (column.size() != rows.size())
        throw std::invalid_argument(std::string("the column ") + field.name + " has " +
                                    std::to_string(column.size()) + " entries where the others have " +
                                    std::to_string(rows.size()));
      for (std::size_t k = 0; k < rows.size(); ++k) get(rows[k]) = column[k];
    }
  });
  return rows;
}

}  // namespace rbdem
