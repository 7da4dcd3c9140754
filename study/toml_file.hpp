// Reading the study layer's TOML files (studies, calibration targets) with errors that name the file and the fix.
#pragma once

#include <filesystem>
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

}  // namespace rbdem::study
