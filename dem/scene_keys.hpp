// How the scene's sections are declared. The scene (dem/scene.hpp) is one registry of keys, each with its unit,
// allowed range, default and doc string; dem/scene_keys.cpp declares every section through the builders below, and
// dem/scene.cpp collects them in this order:
//   [specimen] [joint_set] [joint_set2] [mesh]  declare_geometry   read by the meshing (dem/specimen_mesh.cpp)
//   [rock] [joint] [joint2] [rock2] [beds]      declare_materials  read by the model (dem/model.cpp)
//   [loading]                                   declare_loading    read by the tests between platens
//   [numerics]                                  declare_numerics   read by the engine and the driver
//   [elastic]                                   declare_elastic    read by compare/gate
//   [output]                                    declare_output     read by the recorders (dem/driver/monitors.cpp)
// Internal to the scene library.
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

// The rules of specimen.dimension (dem/scene_dimension.cpp): the shapes of each dimension and the keys of the other
// dimension set away from their default. Part of validate().
void validate_dimension(const Scene& scene);

}  // namespace rbdem::scene_keys
