// Simulations for the tests: the 2D model of a scene's mesh (or of a topology built by hand) with the boundary
// components a test needs, and its engine for the tests of the engine itself.
#pragma once

#include <functional>
#include <memory>

#include "dem/simulation_impl.hpp"
#include "dem/specimen_mesh.hpp"

namespace rbdem::fixtures {

// The simulation of `scene`'s mesh with the platens of a compression test (the scene's platen speed and friction).
inline std::unique_ptr<SimulationImpl<2>> with_platens(const Scene& scene) {
  auto sim = std::make_unique<SimulationImpl<2>>(scene, make_mesh(scene));
  sim->add_platens({scene.loading.platen_velocity, scene.loading.platen_friction});
  return sim;
}
inline std::unique_ptr<SimulationImpl<2>> with_platens(const Scene& scene, const Topology<2>& topo,
                                                      const std::function<void(EngineOptions&)>& engine = nullptr) {
  auto sim = std::make_unique<SimulationImpl<2>>(scene, topo, SimulationOptions{}, engine);
  sim->add_platens({scene.loading.platen_velocity, scene.loading.platen_friction});
  return sim;
}

}  // namespace rbdem::fixtures
