// Reading the study layer's TOML files (studies, calibration targets) with errors that name the file and the fix.
#pragma once

#include <algorithm>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "dem/scene.hpp"

namespace rbdem::study {

// Parses `path`; a missing or unreadable file gives "cannot read <what> file '<path>': check the path (<hint>)", a
// syntax error "<path>:<line>:<column>: TOML syntax error: ...", both as SceneError.
inline toml::table read_toml_file(const std::filesystem::path& path, std::string_view what, std::string_view hint) {
  const auto unreadable = [&] {
    return SceneError(fmt::format("cannot read {} file '{}': check the path ({})", what, path.string(), hint));
  };
  if (!std::filesystem::is_regular_file(path)) throw unreadable();
  try {
    return toml::parse_file(path.string());
  } catch (const toml::parse_error& e) {
    throw SceneError(fmt::format("{}:{}:{}: TOML syntax error: {}", path.string(), e.source().begin.line,
                                 e.source().begin.column, e.description()));
  } catch (const std::exception&) {
    throw unreadable();
  }
}

// Refuses a key of `t` that is not in `allowed`, naming the key, where it is and the keys allowed there.
inline void check_keys(const toml::table& t, std::initializer_list<std::string_view> allowed, const std::string& where) {
  for (const auto& [k, v] : t) {
    if (std::find(allowed.begin(), allowed.end(), k.str()) == allowed.end()) {
      std::string list;
      for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      throw SceneError(fmt::format("{}: unknown key '{}' (allowed: {})", where, k.str(), list));
    }
  }
}

// A TOML number (integer or floating point) as double; `where` names the key in the error.
inline double toml_number(const toml::node& node, const std::string& where) {
  if (auto f = node.as_floating_point()) return f->get();
  if (auto i = node.as_integer()) return double(i->get());
  throw SceneError(where + ": expected a number");
}

// A TOML scalar as the text `--set key=value` takes.
inline std::string toml_value_text(const toml::node& node, const std::string& where) {
  if (auto f = node.as_floating_point()) return fmt::format("{}", f->get());
  if (auto i = node.as_integer()) return fmt::format("{}", i->get());
  if (auto b = node.as_boolean()) return b->get() ? "true" : "false";
  if (auto s = node.as_string()) return s->get();
  throw SceneError(where + ": expected a number, a boolean or a string");
}

}  // namespace rbdem::study
