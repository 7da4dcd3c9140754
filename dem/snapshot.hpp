// Snapshot: the state of a simulation as a list of named fields, dimension-free. Simulation::snapshot() makes one
// from the engine's ModelState (walking its field table, dem/state.hpp) and from each boundary component's state;
// Simulation::restore() puts one back, and a run continues bit for bit as if it had never stopped. Checkpoints
// (io/checkpoint.cpp) and the Python module store a snapshot by walking its fields: a name with '/' is a field of a
// group ("platens/top_y", "cracks/time_s").
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace rbdem {

// Which index space a field's entries belong to (a restore checks each against the model).
enum class Extent : std::uint8_t { blocks, bonds, contacts, eligible, free, scalar };

struct Snapshot {
  using Value = std::variant<double, long, int, bool, std::vector<double>, std::vector<int>, std::vector<std::uint8_t>,
                             std::vector<std::uint64_t>>;
  struct Entry {
    std::string name;
    Extent extent = Extent::scalar;
    Value value;
  };
  int dim = 2;
  std::vector<Entry> entries;

  template <class T>
  void add(std::string name, Extent extent, T value) {
    entries.push_back({std::move(name), extent, Value(std::move(value))});
  }
  // The entry named `name`; throws std::invalid_argument naming it when there is none or it has another type.
  template <class T>
  const T& get(std::string_view name) const {
    for (const Entry& e : entries)
      if (e.name == name) {
        if (const T* v = std::get_if<T>(&e.value)) return *v;
        throw std::invalid_argument("the snapshot's field '" + std::string(name) + "' has another type");
      }
    throw std::invalid_argument("the snapshot has no field '" + std::string(name) +
                                "': it was written by another version of rbdem or for another model");
  }
  bool has(std::string_view name) const {
    for (const Entry& e : entries)
      if (e.name == name) return true;
    return false;
  }
};

}  // namespace rbdem
