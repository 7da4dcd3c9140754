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
target_link_libraries(consumer PRIVATE rbdem::dem rbdem::theory)
CMAKE
cat > "$work/consumer/main.cpp" <<'CPP'
#include <cstdio>
#include <theory/elasticity.hpp>
#include <dem/specimen_mesh.hpp>
#include <dem/topology.hpp>
int main() {
  rbdem::SpecimenGeometry g;
  const auto topo = rbdem::build_topology(rbdem::mesh_specimen(g, 0.004), 1.0, 2700.0);
  const auto iso = rbdem::theory::TIConstants::isotropic(1e9, 0.25);
  std::printf("consumer: %zu blocks, %zu bonds, E(45) = %.3g Pa\n", topo.blocks.size(), topo.bonds.size(),
              rbdem::theory::apparent_modulus(iso, 45.0, rbdem::theory::Plane::stress));
  return topo.bonds.size() > 0 ? 0 : 1;
}
CPP
cmake -S "$work/consumer" -B "$work/consumer/build" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$work/consumer/build" > /dev/null
"$work/consumer/build/consumer"
echo "check-consumer: find_package(rbdem) works"
