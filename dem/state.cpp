// The state's size and index checks and its snapshot, walking the field table. See state.hpp.
#include "dem/state.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <fmt/format.h>

#include "dem/snapshot_records.hpp"

namespace rbdem {

void check_state_fits(const ModelState<2>& s, std::size_t blocks, std::size_t bonds) {
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
          C.fn.size() != n || C.chord.size() != n || C.opening_x.size() != n ||
          C.opening_y.size() != n)
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

void save_state(const ModelState<2>& state, Snapshot& snap) {
  state.fields([&](const char* name, const auto& field, Extent extent, bool) {
    using T = std::decay_t<decltype(field)>;
    const std::string n = name;
    if constexpr (std::is_same_v<T, ContactPairs>) {
      snap.add(n + "/i", extent, field.i);
      snap.add(n + "/j", extent, field.j);
      snap.add(n + "/bond", extent, field.bond);
      std::vector<double> law;  // K, Ks, mu, 1 / L_ref, tan(i) of each pair: bit-exact
      law.reserve(5 * field.law.size());
      for (const LinearContact& c : field.law) law.insert(law.end(), {c.K, c.Ks, c.mu, c.inv_lref, c.tan_dilation});
      snap.add(n + "/law", extent, std::move(law));
      snap.add(n + "/fs", extent, field.fs);
      snap.add(n + "/fn", extent, field.fn);
      snap.add(n + "/chord", extent, field.chord);
      snap.add(n + "/opening_x", extent, field.opening_x);
      snap.add(n + "/opening_y", extent, field.opening_y);
      snap.add(n + "/key", extent, field.key);
    } else if constexpr (std::is_same_v<T, std::vector<Crack>>) {
      save_records(2, field, n, extent, snap);
    } else {
      snap.add(n, extent, field);
    }
  });
}

void load_state(const Snapshot& snap, ModelState<2>& state) {
  state.fields([&](const char* name, auto& field, Extent, bool) {
    using T = std::decay_t<decltype(field)>;
    const std::string n = name;
    if constexpr (std::is_same_v<T, ContactPairs>) {
      field.i = snap.get<std::vector<int>>(n + "/i");
      field.j = snap.get<std::vector<int>>(n + "/j");
      field.bond = snap.get<std::vector<int>>(n + "/bond");
      const auto& law = snap.get<std::vector<double>>(n + "/law");
      if (law.size() % 5 != 0) throw std::invalid_argument("the snapshot's contact laws are not five numbers each");
      field.law.resize(law.size() / 5);
      for (std::size_t k = 0; k < field.law.size(); ++k)
        field.law[k] = {law[5 * k], law[5 * k + 1], law[5 * k + 2], law[5 * k + 3], law[5 * k + 4]};
      field.fs = snap.get<std::vector<double>>(n + "/fs");
      field.fn = snap.get<std::vector<double>>(n + "/fn");
      field.chord = snap.get<std::vector<double>>(n + "/chord");
      field.opening_x = snap.get<std::vector<double>>(n + "/opening_x");
      field.opening_y = snap.get<std::vector<double>>(n + "/opening_y");
      field.key = snap.get<std::vector<std::uint64_t>>(n + "/key");
    } else if constexpr (std::is_same_v<T, std::vector<Crack>>) {
      field = load_records<Crack>(2, snap, n);
    } else {
      field = snap.get<T>(n);
    }
  });
}

}  // namespace rbdem
