// The 3D state's snapshot, walking its field table. See state3.hpp.
#include "dem/state3.hpp"

#include <stdexcept>
#include <string>
#include <type_traits>

#include <fmt/format.h>

#include "dem/snapshot_records.hpp"

namespace rbdem {

void save_state(const ModelState<3>& state, Snapshot& snap) {
  state.fields([&](const char* name, const auto& field, Extent extent) {
    using T = std::decay_t<decltype(field)>;
    const std::string n = name;
    if constexpr (std::is_same_v<T, std::vector<Crack>>) {
      save_records(3, field, n, extent, snap);
    } else {
      snap.add(n, extent, field);
    }
  });
}

void load_state(const Snapshot& snap, ModelState<3>& state, std::size_t blocks, std::size_t bonds) {
  std::string bad;
  state.fields([&](const char* name, auto& field, Extent extent) {
    using T = std::decay_t<decltype(field)>;
    const std::string n = name;
    if constexpr (std::is_same_v<T, std::vector<Crack>>) {
      field = load_records<Crack>(3, snap, n);
      for (const Crack& c : field)
        if (c.bond < 0 || std::size_t(c.bond) >= bonds) bad += " cracks: a bond index out of range;";
    } else {
      field = snap.get<T>(n);
      if constexpr (!std::is_arithmetic_v<T>) {
        const std::size_t want = extent == Extent::blocks ? blocks : bonds;
        if (field.size() != want) bad += fmt::format(" {} has {} entries, expected {};", n, field.size(), want);
      }
    }
  });
  if (!bad.empty())
    throw std::invalid_argument(fmt::format("the state does not fit this model of {} blocks and {} bonds: it was "
                                            "written for another scene or mesh ({})", blocks, bonds,
                                            bad.substr(1, bad.size() - 2)));
}

}  // namespace rbdem
