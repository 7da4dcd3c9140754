// How a module declares its scene section. The scene (dem/scene.hpp) is one registry of keys, each with its unit,
// allowed range, default and doc string; every section is declared by the module that reads it, through the
// builders below, and dem/scene.cpp collects them in file order:
//   [specimen] [joint_set] [joint_set2] [mesh]  dem/specimen_mesh.cpp  declare_geometry
//   [rock] [joint] [joint2] [rock2] dem/model.cpp           declare_materials
//   [loading]                       dem/driver/ucs.cpp      declare_loading
//   [numerics]                      dem/engine.cpp          declare_numerics
//   [elastic]                       dem/scene.cpp           declare_elastic (read by compare/gate, which the DEM
//                                                                            library does not link)
//   [output]                        dem/driver/monitors.cpp declare_output
// Internal to the DEM library.
#pragma once

#include <functional>
#include <string>
#include <variant>
#include <vector>

#include "dem/scene.hpp"

namespace rbdem::scene_keys {

using ValueRef = std::variant<double*, int*, bool*, std::string*>;

struct Entry {
  ParamInfo info;
  std::function<ValueRef(Scene&)> ref;
};

Entry real(std::string key, std::string unit, double lo, double hi, std::string doc,
           std::function<double&(Scene&)> get, bool lo_exclusive = false);
Entry positive(std::string key, std::string unit, double hi, std::string doc, std::function<double&(Scene&)> get);
Entry integer(std::string key, std::string unit, int lo, int hi, std::string doc, std::function<int&(Scene&)> get);
Entry boolean(std::string key, std::string doc, std::function<bool&(Scene&)> get);
Entry choice(std::string key, std::vector<std::string> choices, std::string doc,
             std::function<std::string&(Scene&)> get);
Entry text(std::string key, std::string doc, std::function<std::string&(Scene&)> get);

// The keys of a section, in the order they are declared (and printed).
struct Keys {
  std::vector<Entry> entries;
  void add(Entry e) { entries.push_back(std::move(e)); }
};

void declare_geometry(Keys& k);
void declare_materials(Keys& k);
void declare_loading(Keys& k);
void declare_numerics(Keys& k);
void declare_elastic(Keys& k);
void declare_output(Keys& k);

}  // namespace rbdem::scene_keys
