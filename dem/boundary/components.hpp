// The boundary components of the 2D model: each implements its dimension-free interface (dem/boundary/boundary.hpp)
// and the engine's hooks (dem/boundary/hooks.hpp). A 3D model adds the specialisations for dim = 3.
//
//   PlatensImpl<2>     platens.cpp   two rigid walls, the top one at top_y closing at its velocity (or under a
//                                    servo), the bottom one fixed at the specimen's lowest point; each acts on its
//                                    candidate blocks as a half-plane with the linear contact law, k_n from the
//                                    block's mirror image (d = 2 x inradius)
//   JacketImpl<2>      jacket.cpp    a confining pressure on the outer edges that are not on a platen (follower
//                                    forces)
//   BlockGroupImpl<2>  groups.cpp    chosen blocks fixed, moved at a prescribed velocity, loaded by a constant
//                                    force or moved rigidly by a servo, each degree of freedom its own way
#pragma once

#include <string>
#include <vector>

#include "dem/boundary/boundary.hpp"
#include "dem/boundary/hooks.hpp"
#include "dem/engine.hpp"

namespace rbdem {

template <int dim>
class PlatensImpl;
template <int dim>
class JacketImpl;
template <int dim>
class BlockGroupImpl;

template <>
class PlatensImpl<2> : public Platens, public BoundaryHooks<2> {
 public:
  PlatensImpl(const Model<2>& model, const PlatenSettings& settings);

  // Platens
  double top_force() const override { return top_force_; }
  double bottom_force() const override { return bottom_force_; }
  double closure() const override { return ymax_ - top_y_; }
  double area() const override { return width_ * thickness_; }
  double velocity() const override { return velocity_; }
  void set_velocity(double v) override { velocity_ = v, servo_on_ = false; }
  void set_servo(const PlatenServo& servo) override { servo_ = servo, servo_on_ = true; }
  bool servo_active() const override { return servo_on_; }
  double friction() const override { return friction_; }
  double work() const override { return work_; }
  double energy() const override { return energy_; }
  std::vector<std::pair<std::string, double>> readings() const override;
  // The top platen's position (m): the reference integrators evaluate the forces with the platen where it is at
  // their time.
  double top_y() const { return top_y_; }
  void set_top_y(double y) { top_y_ = y; }

  // BoundaryHooks<2>
  void on_rebuild(const Model<2>& m, const ModelState<2>& s, const std::vector<int>& eligible) override;
  void on_join(const Model<2>& m, const ModelState<2>& s, const std::vector<int>& joining) override;
  bool rebuild_due(const Model<2>& m) const override;
  void forces_begin(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c) override;
  bool shares() const override { return true; }
  void forces_share(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c, int t,
                    int nt) override;
  void forces_end(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c) override;
  void after_step(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, double dt) override;
  void loads(const Model<2>& m, const ModelState<2>& s, const Workspace<2>& w, int component,
             const std::vector<double>& others, BoundaryLoads& out) const override;
  void add_stiffness(const Model<2>& m, std::vector<double>& kt, std::vector<double>& kr) const override;
  void static_supports(const Model<2>& m, StaticSupports2& supports) const override;
  void apply_static(const Model<2>& m, const ModelState<2>& s, const StaticResult& st, double factor) override;
  double stored_energy() const override { return energy_; }
  double work_done() const override { return work_; }
  void save(Snapshot& s) const override;
  void load(const Snapshot& s, const Model<2>& m) override;

 private:
  struct Force {
    double fx, fy, m, fn, energy, friction;  // on the block; normal force; elastic energy, friction work
    bool touching;
  };
  void contact(const Model<2>& m, ModelState<2>& s, const Workspace<2>& w, const StepContext& c, int k);
  void add_candidates(const Model<2>& m, const ModelState<2>& s, const std::vector<int>& blocks, double top);
  LinearContact law(const Model<2>& m, int block) const;

  // constant: the specimen and the contact stiffness of each block against a platen
  double ymin_ = 0, ymax_ = 0, width_ = 0, thickness_ = 1, skin_ = 0, friction_ = 0;
  std::vector<double> kn_;    // Pa/m, E* / (2 inradius) per block: the platen as the block's mirror image
  std::vector<double> lref_;  // m, L_ref: the block's edge on the platen, else the inradius-based length
  std::vector<int> edge_block;                        // the boundary edges on the platens: block, top or bottom,
  std::vector<std::uint8_t> edge_top;                 // length, midpoint relative to the centroid
  std::vector<double> edge_length, edge_rx, edge_ry;
  // state
  double top_y_ = 0, velocity_ = 0;
  bool servo_on_ = false;
  PlatenServo servo_;
  double top_force_ = 0, bottom_force_ = 0, energy_ = 0, work_ = 0;
  double ref_top_ = 0;                                // top_y at the broad phase's last rebuild
  std::vector<int> top_candidates_, bottom_candidates_;  // blocks that may touch before the next rebuild, ascending
  std::vector<double> top_fs_, bottom_fs_;             // per block shear history (N)
  // derived: one record per candidate (the top platen's first)
  std::vector<Force> force_;
};

template <>
class JacketImpl<2> : public Jacket, public BoundaryHooks<2> {
 public:
  JacketImpl(const Model<2>& model, double pressure);

  double pressure() const override { return pressure_; }
  void set_pressure(double p) override { pressure_ = p; }
  int faces_lost() const override { return lost_; }
  int faces_lost_max() const override { return lost_max_; }
  double work() const override { return work_; }
  std::vector<std::pair<std::string, double>> readings() const override;
  // The load of a pressure p in the reference configuration, 3 entries per block (StaticOptions::load).
  std::vector<double> reference_load(const Model<2>& m, double p) const;

  void forces_end(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c) override;
  void loads(const Model<2>& m, const ModelState<2>& s, const Workspace<2>& w, int component,
             const std::vector<double>& others, BoundaryLoads& out) const override;
  double work_done() const override { return work_; }
  void save(Snapshot& s) const override;
  void load(const Snapshot& s, const Model<2>& m) override;

 private:
  // The pressure's force on outer edge e of a block rotated by (co, si): L n p t at the edge's midpoint (rx, ry
  // from the centroid).
  struct FaceForce {
    double fx, fy, rx, ry;
  };
  FaceForce face_force(std::size_t e, double co, double si) const;
  // Whether edge e's block takes the pressure: it still has an intact bond or a contact that carried force.
  bool loaded(const Model<2>& m, const ModelState<2>& s, std::size_t e) const;
  // The outer edges a pressure acts on (every boundary edge not on a platen), with their end points in the block's
  // reference frame (relative to the reference centroid), outside to the right of a -> b.
  std::vector<int> block_;
  std::vector<double> ax_, ay_, bx_, by_;
  double thickness_ = 1;
  double pressure_ = 0, work_ = 0;
  int lost_ = 0, lost_max_ = 0;
  std::vector<std::uint8_t> touching_;  // derived: per block, in a contact that carries force this step
};

template <>
class BlockGroupImpl<2> : public BlockGroup, public BoundaryHooks<2> {
 public:
  // Fixes the group's blocks in `engine` for the fixed and velocity modes.
  BlockGroupImpl(Engine<2>& engine, const GroupSettings& settings);

  std::string name() const override { return settings_.name; }
  const GroupSettings& settings() const override { return settings_; }
  const std::vector<int>& blocks() const override { return settings_.blocks; }
  void set_value(const std::vector<double>& value) override;
  std::vector<double> force() const override { return force_; }
  std::vector<double> displacement() const override;
  void set_servo(const GroupServo& servo) override;
  void set_modes(const std::vector<GroupSettings::Mode>& modes) override;
  std::vector<double> velocity() const override;
  std::vector<double> attachment_stiffness() const override;
  double work() const override { return work_; }
  std::vector<std::pair<std::string, double>> readings() const override;

  void forces_end(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c) override;
  void after_step(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, double dt) override;
  void loads(const Model<2>& m, const ModelState<2>& s, const Workspace<2>& w, int component,
             const std::vector<double>& others, BoundaryLoads& out) const override;
  bool holds_blocks() const override { return settings_.mode != GroupSettings::Mode::force; }
  void static_supports(const Model<2>& m, StaticSupports2& supports) const override;
  double work_done() const override { return work_; }
  void save(Snapshot& s) const override;
  void load(const Snapshot& s, const Model<2>& m) override;

 private:
  double dof_velocity(int d, const std::vector<double>& displacement, double dt) const;

  const Engine<2>& engine_;
  GroupSettings settings_;
  std::vector<double> force_ = std::vector<double>(3, 0.0);
  std::vector<double> velocity_ = std::vector<double>(3, 0.0);
  double work_ = 0;
};

}  // namespace rbdem
