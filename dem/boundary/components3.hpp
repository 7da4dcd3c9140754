// The boundary components of the 3D model: each implements its dimension-free interface (dem/boundary/boundary.hpp)
// and the 3D engine's hooks (dem/boundary/hooks3.hpp), as components.hpp does in 2D.
//
//   PlatensImpl<3>   platens3.cpp   two rigid horizontal planes, the top one at top_z closing at its velocity (or
//                                   under a servo), the bottom one fixed at the specimen's lowest point; each acts
//                                   on every block that crosses it with the linear contact law on the overlap
//                                   volume, k_n from the block's mirror image (d = 2 x inradius)
//   JacketImpl<3>    jacket3.cpp    a confining pressure on the lateral faces (follower forces)
//   BlockContacts3   contacts3.cpp  contacts between blocks that were never neighbours (installed by the
//                                   simulation itself, first): the tetrahedron-tetrahedron narrow phase
//                                   (dem/contact3.hpp) and the linear contact law on the overlap volume
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "dem/boundary/boundary.hpp"
#include "dem/boundary/hooks3.hpp"
#include "dem/contact3.hpp"

namespace rbdem {

template <int dim>
class PlatensImpl;
template <int dim>
class JacketImpl;

// The part of a tetrahedron beyond a plane: the vertices' depths d_k past it (positive beyond) give the overlap's
// volume, centroid and the area of its section by the plane. Exact for any depths (the clipped solid is a
// tetrahedron or a prism, split into tetrahedra without cancellation).
struct TetOverlap {
  double volume = 0, area = 0;  // m^3, m^2
  Vec3 centroid;                // m
};
TetOverlap tet_beyond_plane(const std::array<Vec3, 4>& v, const std::array<double, 4>& depth);

template <>
class PlatensImpl<3> : public Platens, public BoundaryHooks<3> {
 public:
  PlatensImpl(const Model<3>& model, const PlatenSettings& settings);

  double top_force() const override { return top_force_; }
  double bottom_force() const override { return bottom_force_; }
  double closure() const override { return zmax_ - top_z_; }
  double area() const override { return area_; }
  double velocity() const override { return velocity_; }
  void set_velocity(double v) override { velocity_ = v, servo_on_ = false; }
  void set_servo(const PlatenServo& servo) override { servo_ = servo, servo_on_ = true; }
  bool servo_active() const override { return servo_on_; }
  double friction() const override { return friction_; }
  double work() const override { return work_; }
  double energy() const override { return energy_; }
  std::vector<std::pair<std::string, double>> readings() const override;

  double add_forces(const Model<3>& m, const ModelState<3>& s, std::vector<Vec3>& force, std::vector<Vec3>& moment,
                    double dt, bool advance) override;
  // Each candidate's contact (its overlap with the platen, the costly part) for the thread's share of candidates;
  // add_forces sums them in candidate order.
  void prepare_forces(const Model<3>& m, const ModelState<3>& s, double dt, int thread, int threads) override;
  void after_step(const Model<3>&, ModelState<3>&, double dt) override { top_z_ -= velocity_ * dt; }
  void loads(const Model<3>& m, const ModelState<3>& s, int component, BoundaryLoads& out) const override;
  void add_stiffness(const Model<3>& m, std::vector<BlockStiffness3>& k) const override;
  void static_rows(const Model<3>& m, std::vector<PlatenRow3>& rows) const override;
  void apply_static(const Model<3>& m, const StaticResult& st, double factor) override;
  double stored_energy() const override { return energy_; }
  double work_done() const override { return work_; }
  void save(Snapshot& s) const override;
  void load(const Snapshot& s, const Model<3>& m) override;

 private:
  struct Contact {
    Vec3 force, point;  // on the block, at the overlap's centroid
    double fn = 0, energy = 0, friction = 0;
    bool touching = false;
  };
  // Candidate k's contact (the top platen's candidates first) at the state s, its shear history `fs` updated.
  Contact contact(const Model<3>& m, const ModelState<3>& s, int block, bool top, double dt, Vec3& fs) const;

  double zmin_ = 0, zmax_ = 0, area_ = 0, friction_ = 0;
  std::vector<double> kn_;  // Pa/m per block: E* / (2 inradius), the platen as the block's mirror image
  std::vector<double> kappa_;
  std::vector<int> top_candidates_, bottom_candidates_;  // blocks that can reach a platen, ascending
  // state
  double top_z_ = 0, velocity_ = 0;
  bool servo_on_ = false;
  PlatenServo servo_;
  double top_force_ = 0, bottom_force_ = 0, energy_ = 0, work_ = 0;
  std::vector<double> fs_;  // the shear history of each candidate (top first), x and y (N)
  // workspace: the contacts prepare_forces computed for this step's add_forces (prepared_ until it used them)
  std::vector<Contact> contacts_;
  bool prepared_ = false;
};

template <>
class JacketImpl<3> : public Jacket, public BoundaryHooks<3> {
 public:
  JacketImpl(const Model<3>& model, double pressure);

  double pressure() const override { return pressure_; }
  void set_pressure(double p) override { pressure_ = p; }
  int faces_lost() const override { return lost_; }
  int faces_lost_max() const override { return lost_max_; }
  double work() const override { return work_; }
  std::vector<std::pair<std::string, double>> readings() const override;
  // The load of a pressure p in the reference configuration, 6 entries per block (StaticOptions::load).
  std::vector<double> reference_load(const Model<3>& m, double p) const;

  double add_forces(const Model<3>& m, const ModelState<3>& s, std::vector<Vec3>& force, std::vector<Vec3>& moment,
                    double dt, bool advance) override;
  void loads(const Model<3>& m, const ModelState<3>& s, int component, BoundaryLoads& out) const override;
  double work_done() const override { return work_; }
  void save(Snapshot& s) const override;
  void load(const Snapshot& s, const Model<3>& m) override;

 private:
  // The pressure's force -p A n on lateral face k of a block at rotation q, and its point from the centroid.
  std::pair<Vec3, Vec3> face_force(const Model<3>& m, std::size_t k, Quat q) const;
  std::vector<std::size_t> faces_;  // the lateral faces (indices into Model<3>::surface)
  double pressure_ = 0, work_ = 0;
  int lost_ = 0, lost_max_ = 0;
};

// Contacts between blocks that share no face (a broken bond's pair is the bond's: its linear part goes on), among
// the blocks that have lost a bond or never had one. The broad phase: each such block's box grown by a skin, the pairs whose boxes
// overlap, rebuilt when a block moved half a skin from where it was at the last rebuild or a bond broke. The
// narrow phase: contact_tets; the law: the potential k_n V^2 / (2 A) on the overlap volume, F_n = k_n V A_c / A
// along the contact normal (k_n = E* / (r_i + r_j), r the inradii; A the smaller of the two blocks' mean face
// areas), the incremental shear -(k_n / kappa) A_c v_s dt Coulomb-limited to mu F_n (the joint's mu across
// layers, else the rock's), at the contact's point. The broad phase runs serially at the step's start
// (begin_step); the narrow phase on the step's threads, each pair into its own record (prepare_forces); add_forces
// sums the records in pair order: the same at any thread count.
class BlockContacts3 : public BoundaryHooks<3> {
 public:
  explicit BlockContacts3(const Model<3>& model);

  // The rebuild test and the rebuild, with the positions and cracks of the step's start.
  void begin_step(const Model<3>& m, const ModelState<3>& s) override;
  // The narrow phase of the pairs the thread takes from a shared cursor, in pieces, into their records.
  void prepare_forces(const Model<3>& m, const ModelState<3>& s, double dt, int thread, int threads) override;
  double add_forces(const Model<3>& m, const ModelState<3>& s, std::vector<Vec3>& force, std::vector<Vec3>& moment,
                    double dt, bool advance) override;
  void loads(const Model<3>& m, const ModelState<3>& s, int component, BoundaryLoads& out) const override;
  double stored_energy() const override { return energy_; }
  double work_done() const override { return 0.0; }
  void save(Snapshot& s) const override;
  void load(const Snapshot& s, const Model<3>& m) override;
  // The pairs in contact now (the last step's), as the state tables give them.
  ContactStates states(const Model<3>& m, const ModelState<3>& s) const;
  std::size_t pairs() const { return pi_.size(); }
  long rebuilds() const { return rebuilds_; }

 private:
  struct Force {
    Vec3 force, point;  // on j (-force on i), at the point
    double fn = 0, energy = 0, friction = 0;
    bool touching = false;
  };
  void rebuild(const Model<3>& m, const ModelState<3>& s);
  bool rebuild_due(const Model<3>& m, const ModelState<3>& s) const;
  Force contact(const Model<3>& m, const ModelState<3>& s, std::size_t k, double dt, Vec3& fs) const;
  Force contact(const Model<3>& m, const ModelState<3>& s, std::size_t k, const Tet& ti, const Tet& tj, double dt,
                Vec3& fs) const;
  bool index_pairs(std::size_t num_blocks);

  double skin_ = 0;
  std::vector<double> mean_face_;                 // m^2 per block
  std::vector<std::vector<int>> neighbours_;      // per block, the blocks it shares a face with, ascending
  // state (the snapshot): the pairs, their shear histories (world, N), the blocks searched and where they were
  std::vector<int> pi_, pj_;
  std::vector<double> fs_;
  std::vector<int> eligible_;
  std::vector<double> ref_;                       // 3 per eligible block
  long broken_seen_ = -1;                         // the crack count at the last rebuild (-1: none yet)
  long rebuilds_ = 0;
  double energy_ = 0;
  // workspace: this step's narrow phase, one record per pair and its new shear history (prepared_ from begin_step
  // until add_forces used them); the threads take pieces of the pairs from cursor_
  std::vector<Force> records_;        // read where touching_ is 1
  std::vector<std::uint8_t> touching_;
  std::vector<double> new_fs_;        // 3 per pair, as fs_, which it replaces in add_forces
  // each pair's two blocks as places in eligible_, and each eligible block's tetrahedron in its pose at the step's
  // start (begin_step): the pairs of a block read it instead of turning its vertices again
  std::vector<int> ki_, kj_;
  // computed by the first thread that needs it in the step: ready_[k] is 2 s + 2 once posed_[k] holds step s's
  // pose (2 s + 1 while a thread computes it), s counted by begin_step
  const PosedTet& posed_at(const Model<3>& m, const ModelState<3>& s, std::size_t k) const;
  mutable std::vector<PosedTet> posed_;
  mutable std::unique_ptr<std::atomic<long>[]> ready_;
  long generation_ = 0;
  std::atomic<std::size_t> cursor_{0};
  bool prepared_ = false;
};

}  // namespace rbdem
