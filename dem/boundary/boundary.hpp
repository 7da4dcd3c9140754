// Boundary components: what acts on the specimen from outside, installed by a protocol (or a script) on a
// Simulation (dem/simulation.hpp) rather than built into the engine. Each component carries its own state in the
// snapshot, adds its forces in the step's force evaluation (in the order the components were installed, after the
// block-block contacts), adds its rows to the static elastic solve and gives its readings (force, displacement,
// work). This header is the dimension-free face that protocols, monitors and the Python module see; the engine's
// side of each component (its stage hooks) is dimension-specific (dem/boundary/hooks.hpp).
//
//   Platens     two rigid platens loading the specimen's top and bottom: the top one moves at a prescribed
//               velocity or under a servo to a target stress, the bottom one is fixed
//   Jacket      a confining pressure on the outer faces that are not on a platen, as a membrane applies it
//   BlockGroup  chosen blocks held fixed, moved at a prescribed velocity, or loaded by a constant force
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace rbdem {

class Boundary {
 public:
  virtual ~Boundary() = default;
  // The component's name: "platens", "jacket", or the name a group was given.
  virtual std::string name() const = 0;
  // J: the work the component has done on the specimen since the model was built (cumulative).
  virtual double work() const = 0;
  // J: the elastic energy it stores now (the platens' contacts); 0 for loads.
  virtual double energy() const { return 0.0; }
  // Its readings after the last step, as (name, value) pairs with the unit in the name ("top_force_n", ...).
  virtual std::vector<std::pair<std::string, double>> readings() const = 0;
};

// How the top platen moves: at a prescribed velocity, or under a servo that drives the mean platen stress towards
// a target: v = clamp(gain (target - stress), -max_velocity, max_velocity) (m/s, compression closing), recomputed
// every step from the last step's forces.
struct PlatenServo {
  double target_stress = 0;  // Pa, compression positive
  double gain = 0;           // m/s per Pa
  double max_velocity = 0;   // m/s, the rate limit
};

struct PlatenSettings {
  double velocity = 0;   // m/s, closing speed of the top platen (the bottom one is fixed)
  double friction = 0;   // Coulomb coefficient between the platens and the blocks
};

class Platens : public Boundary {
 public:
  std::string name() const override { return "platens"; }
  virtual double top_force() const = 0;     // N, compression positive, of the last step
  virtual double bottom_force() const = 0;  // N
  virtual double closure() const = 0;       // m, how far the top platen has moved towards the bottom one
  virtual double area() const = 0;          // m^2, the loaded area (2D: width x thickness)
  virtual double velocity() const = 0;      // m/s, the top platen's closing speed in the last step
  virtual void set_velocity(double v) = 0;  // a prescribed closing speed from the next step on (ends a servo)
  virtual void set_servo(const PlatenServo& servo) = 0;  // a servo from the next step on
  virtual bool servo_active() const = 0;
  virtual double friction() const = 0;
  // The mean platen stress of the last step, (top + bottom) / (2 area).
  double stress() const { return 0.5 * (top_force() + bottom_force()) / area(); }
};

class Jacket : public Boundary {
 public:
  std::string name() const override { return "jacket"; }
  virtual double pressure() const = 0;        // Pa
  virtual void set_pressure(double p) = 0;
  virtual int faces_lost() const = 0;         // jacket faces without pressure in the last step (loose fragments)
  virtual int faces_lost_max() const = 0;     // the most at any step so far
};

struct GroupSettings {
  enum class Mode { fixed, velocity, force };
  std::string name = "group";
  std::vector<int> blocks;        // the blocks of the group (ascending, each once)
  Mode mode = Mode::fixed;
  std::vector<double> value;      // velocity mode: the blocks' velocity (m/s, and rad/s for the rotations);
                                  // force mode: the force on each block (N, and N m); dof(dim) entries
};

class BlockGroup : public Boundary {
 public:
  virtual const GroupSettings& settings() const = 0;
  virtual const std::vector<int>& blocks() const = 0;
  // A new velocity or force (the mode's dof(dim) values) from the next step on.
  virtual void set_value(const std::vector<double>& value) = 0;
  // The sum over the group's blocks of the force the rest of the model and the other boundaries put on them in the
  // last step (N, and N m for the moment in 2D): the reaction of a fixed or driven group. dof(dim) entries.
  virtual std::vector<double> force() const = 0;
  // The mean displacement of the group's blocks from their reference positions (m), dim entries.
  virtual std::vector<double> displacement() const = 0;
};

}  // namespace rbdem
