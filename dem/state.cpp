// The state's size and index checks, walking the field table. See state.hpp.
#include "dem/state.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <fmt/format.h>

namespace rbdem {

void check_state_fits(const ModelState& s, std::size_t blocks, std::size_t bonds) {
  const std::size_t eligible = s.eligible.size(), contacts = s.contacts.size();
  std::string bad;
  auto in_range = [](const std::vector<int>& v, std::size_t n) {
    return std::all_of(v.begin(), v.end(), [n](int k) { return k >= 0 && std::size_t(k) < n; });
  };
  s.fields([&](const char* name, const auto& field, Extent extent, bool) {
    using T = std::decay_t<decltype(field)>;
    std::size_t size = 0;
    if constexpr (std::is_same_v<T, ContactPairs>) {
      const auto& C = field;
      const std::size_t n = C.key.size();
      if (C.i.size() != n || C.j.size() != n || C.bond.size() != n || C.law.size() != n || C.fs.size() != n ||
          C.fn.size() != n || C.chord.size() != n)
        bad += fmt::format(" {}: columns of unequal length;", name);
      if (!in_range(C.i, blocks) || !in_range(C.j, blocks))
        bad += fmt::format(" {}: a block index out of range;", name);
      if (std::any_of(C.bond.begin(), C.bond.end(), [bonds](int b) { return b < -1 || b >= int(bonds); }))
        bad += fmt::format(" {}: a bond index out of range;", name);
      return;
    } else if constexpr (std::is_same_v<T, std::vector<Crack>>) {
      if (!std::all_of(field.begin(), field.end(), [bonds](const Crack& c) { return c.bond >= 0 && std::size_t(c.bond) < bonds; }))
        bad += fmt::format(" {}: a bond index out of range;", name);
      return;
    } else if constexpr (std::is_arithmetic_v<T>) {
      return;
    } else {
      size = field.size();
      if constexpr (std::is_same_v<T, std::vector<int>>)
        if (!in_range(field, blocks)) bad += fmt::format(" {}: a block index out of range;", name);
    }
    std::size_t want = size;
    switch (extent) {
      case Extent::blocks: want = blocks; break;
      case Extent::bonds: want = bonds; break;
      case Extent::contacts: want = contacts; break;
      case Extent::eligible: want = eligible; break;
      case Extent::free:
      case Extent::scalar: break;
    }
    if (size != want) bad += fmt::format(" {} has {} entries, expected {};", name, size, want);
  });
  if (!bad.empty())
    throw std::invalid_argument(fmt::format("the state does not fit this model ({} blocks and {} bonds in the state, "
                                            "{} and {} here): it was written for another scene or mesh ({})",
                                            s.x.size(), s.broken.size(), blocks, bonds, bad.substr(1, bad.size() - 2)));
}

}  // namespace rbdem
