#!/usr/bin/env bash
# Installs rbdem into a scratch prefix and builds a tiny outside project with find_package(rbdem):
# proves the exported targets and headers work for users of the library.
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" > /dev/null
mkdir -p "$work/consumer"
cat > "$work/consumer/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.20)
project(consumer CXX)
set(CMAKE_CXX_STANDARD 20)
find_package(rbdem REQUIRED)
add_executable(consumer main.cpp)
target_link_libraries(consumer PRIVATE rbdem::meshing rbdem::dem rbdem::theory)
CMAKE
cat > "$work/consumer/main.cpp" <<'CPP'
#include <cstdio>
#include <theory/elasticity.hpp>
#include <dem/simulation.hpp>
#include <dem/specimen_mesh.hpp>
int main() {
  rbdem::Scene scene;
  scene.mesh.size = 0.004;
  const auto sim = rbdem::Simulation::create(scene, rbdem::make_mesh(scene));
  sim->add_platens({scene.loading.platen_velocity, 0.0});
  const rbdem::StaticResult st = sim->solve_static();
  const auto iso = rbdem::theory::TIConstants::isotropic(1e9, 0.25);
  std::printf("consumer: %zu blocks, %zu bonds, E_static %.3g Pa, E(45) = %.3g Pa\n", sim->num_blocks(),
              sim->num_bonds(), st.apparent_modulus, rbdem::theory::apparent_modulus(iso, 45.0, rbdem::theory::Plane::stress));
  return sim->num_bonds() > 0 && st.apparent_modulus > 0 ? 0 : 1;
}
CPP
cmake -S "$work/consumer" -B "$work/consumer/build" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$work/consumer/build" > /dev/null
"$work/consumer/build/consumer"
echo "check-consumer: find_package(rbdem) works"
