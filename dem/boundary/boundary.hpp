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
//   BlockGroup  chosen blocks held fixed, moved at a prescribed velocity, loaded by a constant force, or moved
//               rigidly by a servo, along each degree of freedom its own way (a shear box)
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

// A servo along a group's degree of freedom (GroupSettings::Mode::servo): the group moves rigidly along it at
//     v = clamp(gain (load + F), -max_velocity, max_velocity),   load = value - stiffness (u - origin),
// F the force the rest of the model put on the group's blocks in the last step (its reaction, force()), u the
// group's displacement along the dof (displacement()) and `value` the group's value for that dof: an overdamped
// rigid body under a load that comes to rest where the reaction balances it. `stiffness` > 0 puts a spring in series
// with the load, as a constant normal stiffness (CNS) shear test has one between its normal jack and the reaction
// frame: the load grows by stiffness x (u - origin) as the group moves away from `origin`.
struct GroupServo {
  double gain = 0;          // m/s per N (rad/s per N m for a rotation)
  double max_velocity = 0;  // m/s (rad/s), the rate limit
  double stiffness = 0;     // N/m (N m per rad), the spring in series with the load; 0 = a constant load
  double origin = 0;        // m (rad), the displacement at which the spring adds nothing
};

struct GroupSettings {
  // What a group does along a degree of freedom: held fixed, moved at a prescribed velocity, loaded by a constant
  // force on each of its blocks (which then move freely), moved rigidly by a servo (GroupServo), or moved rigidly
  // as one body under the rest of the model's force on it plus its value (a load on the whole group; 0: free).
  enum class Mode { fixed, velocity, force, servo, free };
  std::string name = "group";
  std::vector<int> blocks;        // the blocks of the group (ascending, each once)
  Mode mode = Mode::fixed;        // the mode of every degree of freedom, unless `modes` gives one for each
  std::vector<double> value;      // velocity mode: the blocks' velocity (m/s, and rad/s for the rotations);
                                  // force mode: the force on each block (N, and N m); servo and free modes: the
                                  // load on the whole group (N, N m); dof(dim) entries
  // One mode per degree of freedom (dof(dim) entries; empty: `mode` along each), for a group that does different
  // things along its dofs, as a shear box moved along the joint, under a servo across it and held from turning:
  // {velocity, servo, fixed}. Fixed, velocity, servo and free dofs mix (the blocks move with the group); force (each
  // block on its own) does not. A free dof follows the central difference of the group as one body (its blocks'
  // mass; for the rotation each block turns about its own centroid, as a prescribed rotation turns it) with the
  // engine's local damping.
  std::vector<Mode> modes;
  GroupServo servo;               // the servo of the servo dofs
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
  // The servo of the servo dofs from the next step on (its gain, rate limit, spring and origin).
  virtual void set_servo(const GroupServo& servo) = 0;
  // The mode of each degree of freedom from the next step on (dof(dim) entries), among fixed, velocity, servo and
  // free (a group's blocks cannot change between moving with the group and moving on their own: force mode stays
  // as it was set); values as set_value gives them. A dof keeps its last velocity when it turns free.
  virtual void set_modes(const std::vector<GroupSettings::Mode>& modes) = 0;
  // The mode along degree of freedom d (GroupSettings::modes, else GroupSettings::mode).
  GroupSettings::Mode mode(int d) const {
    const GroupSettings& s = settings();
    return s.modes.empty() ? s.mode : s.modes[std::size_t(d)];
  }
  // The velocity of the group along each dof in the last step (m/s, rad/s): the prescribed one, the servo's, 0 when
  // fixed; a force group's blocks move freely (0). dof(dim) entries.
  virtual std::vector<double> velocity() const = 0;
  // The stiffness of the intact bonds that tie the group's blocks to the rest of the model, summed along each dof in
  // their linearised form (the parallel bond and the closed linear part; N/m, N m per rad): what a servo on the group
  // pushes against within one step, from which its gain is chosen. dof(dim) entries.
  virtual std::vector<double> attachment_stiffness() const = 0;
};

}  // namespace rbdem
