// The stages of one explicit step, each with one job (docs/architecture.md):
//   rotations    cos and sin of every block's rotation: at the end of the integrator, and after a restore
//                or an edit                                                  (integrator.cpp)
//   bonds        every intact bond's parallel bond and linear part -> one force slot per bond, and the bonds whose
//                failure test held                                           (bonds.cpp)
//   bond events  softening and breakage in bond order, the crack log         (bonds.cpp)
//   detection    the broad phase: candidate pairs among free-face blocks     (contacts.cpp)
//   contacts     narrow phase and the linear contact law per pair            (contacts.cpp)
//   boundaries   the boundary components the simulation installed (dem/boundary/: platens, jacket, block
//                groups), through their hooks (dem/boundary/hooks.hpp), in the order installed
//   integrator   per-block gather in a fixed order, local damping, central difference (integrator.cpp)
// Every stage reads the constant Model, reads or writes the ModelState and the engine's Workspace, and runs on at
// most `threads` OpenMP threads. Each bond and each contact pair writes into its own slot; the per-block gather
// sums them in a fixed order, so results are bit-identical at any thread count.
//
// A force evaluation either advances time (`advance`: the shear histories move on by dt, energies are booked, the
// failure test runs) or only evaluates the forces at the current state (the reference integrators,
// compare/reference_integrator.hpp): one code path serves both.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "dem/contact_geometry.hpp"
#include "dem/model.hpp"
#include "dem/state.hpp"

namespace rbdem {

template <int dim>
class BoundaryHooks;

template <int dim>
struct Workspace;

// What the step derives from the state and writes before it reads: never part of a snapshot.
template <>
struct Workspace<2> {
  std::vector<double> cos_t, sin_t;                   // of each block's theta
  // Per block, x, y, theta, vx, vy, omega, cos and sin in one record: what the bond kernel reads of its blocks
  // (records.hpp). Written with cos and sin, from the same state.
  static constexpr int kRecordFields = 8;
  struct alignas(64) Record {
    double f[kRecordFields];
  };
  std::vector<Record> record;
  // Per bond, the forces it applies: fx, fy on j (on i the opposite), and m[2 bond], m[2 bond + 1] the moments on i
  // and on j, so that a CSR entry (2 bond + 1 if the block is j) indexes its moment directly. Arrays, not records:
  // the bond kernel stores and the integrator gathers them in vector lanes. One zero slot follows the last bond's
  // (Model::gather pads with it).
  struct Slots {
    std::vector<double> fx, fy, m;
    void assign(std::size_t bonds) {
      fx.assign(bonds + 1, 0.0), fy.assign(bonds + 1, 0.0), m.assign(2 * bonds + 2, 0.0);
    }
    void zero(std::size_t b) { fx[b] = fy[b] = m[2 * b] = m[2 * b + 1] = 0.0; }
  };
  Slots slot;
  std::vector<double> keep;                           // per bond: fraction of its elastic forces it carries;
                                                      // -1 for a broken bond (the kernel's "alive" test)
  std::size_t damaged = 0;                            // intact bonds past their strength (softening)
  std::vector<int> flag;                              // per bond: the failure test held this step
  std::vector<std::vector<int>> flagged;              // per thread: bonds whose failure test held (bond_events
                                                      // sorts them into bond order)
  struct EventForces {
    double fn, fs, m, px, py;                         // undamaged parallel-bond forces and the bond point
  };
  std::vector<int> events;                            // the flagged bonds of a step, in bond order
  std::vector<EventForces> event_forces;              // and their forces
  std::vector<double> cfx, cfy, cm;                   // per block: contact and boundary forces of this step
  struct PairForce {
    double fx, fy, mi, mj, friction;                  // force on j, moments on i and j, friction work
    bool touching;                                    // false: all zero
  };
  std::vector<PairForce> pair_force;                  // per contact pair
  // The next piece of a range to hand out (run_pieces, below), on its own cache line; copies start from 0 (a
  // workspace copied holds no stage in progress).
  struct alignas(64) Cursor {
    std::atomic<int> next{0};
    Cursor() = default;
    Cursor(const Cursor&) {}
    Cursor& operator=(const Cursor&) { return *this; }
  };
  // The contact stage hands out the pairs in chunks of kPairChunk, in pair order, to whichever thread asks next
  // (one range, [0, pairs), for run_pieces): the pairs that touch lie where the cracks are, not spread over the
  // blocks. in_contact[k]: the pairs of chunk k that touch this step, in pair order, so that the chunks read in
  // order are the pairs in order.
  static constexpr int kPairChunk = 64;
  std::vector<std::vector<int>> in_contact;
  std::vector<int> pair_bounds{0, 0};
  std::vector<Cursor> pair_next = std::vector<Cursor>(1);
  // How a step's bond stage and block stage share the bonds and the blocks among its threads: contiguous ranges in
  // index order. They start with equal block counts and each thread's bonds those numbered from its blocks (a bond
  // is numbered from its lower block), so that a thread reads mostly the blocks it moved itself. No result depends
  // on where the boundaries lie (every item's work and every sum's order are fixed), so they then follow the
  // threads' measured speed: every kRebalanceSteps steps, rebalance() moves the bond and the block boundaries
  // towards equal times (docs/performance.md, "A fourth round"). Block boundaries stay multiples of kBlockGrain:
  // the damping work, summed per grain and then in grain order, is the same at any thread count and split.
  //
  // Each range is run in pieces (kBondPiece bonds, kBlockPiece blocks) taken through the range's cursor: a thread
  // runs its own range from the front and, once done, takes the pieces left in the others' ranges (run_pieces), so
  // that a thread the system held up for a moment does not hold up the step. Every piece runs once, whichever
  // thread takes it.
  struct Partition {
    static constexpr int kBlockGrain = 64;
    static constexpr int kRebalanceSteps = 64;
    static constexpr int kBondPiece = 256, kBlockPiece = 4 * kBlockGrain;
    int threads = 0;
    std::vector<int> block, bond;                     // threads + 1 boundaries each
    std::vector<double> bond_seconds, block_seconds;  // per thread: time in the stage since the last rebalance
    std::vector<double> bond_items, block_items;      // per thread: bonds and blocks it ran in that time
    std::vector<Cursor> bond_next, block_next;        // per range: the next piece to hand out
    int steps = 0;                                    // steps since the last rebalance
  };
  Partition part;
  // The share [lo, hi) of `bounds` (one of the partition's boundary lists) for thread t of a team of nt threads:
  // its own range when the team has the partition's size, else everything on thread 0 (a team smaller than asked,
  // as inside another parallel region, still computes every item).
  std::array<int, 2> share(const std::vector<int>& bounds, int t, int nt) const {
    if (nt == part.threads) return {bounds[std::size_t(t)], bounds[std::size_t(t) + 1]};
    return {t == 0 ? bounds.front() : bounds.back(), bounds.back()};
  }
  // Runs f(lo, hi) on the pieces of `piece` items of the ranges [bounds[v], bounds[v + 1]) (one of the partition's
  // boundary lists, with `next` its cursors): thread t of a team of nt first on its own range, then on what is left
  // of the others' in turn. Returns the items thread t ran. The cursors must be reset before the stage.
  template <class F>
  static int run_pieces(const std::vector<int>& bounds, std::vector<Cursor>& next, int piece, int t, F&& f) {
    const int ranges = int(bounds.size()) - 1;
    int items = 0;
    for (int k = 0; k < ranges; ++k) {
      const std::size_t v = std::size_t((t + k) % ranges);
      const int lo = bounds[v], hi = bounds[v + 1];
      if (lo + piece * next[v].next.load(std::memory_order_relaxed) >= hi) continue;  // nothing left there
      for (int a = lo + piece * next[v].next.fetch_add(1, std::memory_order_relaxed); a < hi;
           a = lo + piece * next[v].next.fetch_add(1, std::memory_order_relaxed)) {
        const int b = std::min(hi, a + piece);
        f(a, b);
        items += b - a;
      }
    }
    return items;
  }
  static void reset(std::vector<Cursor>& next) {
    for (Cursor& c : next) c.next.store(0, std::memory_order_relaxed);
  }
  // The broad phase's cell grid at its last rebuild (contacts.cpp): each eligible block's cell key and position
  // then, sorted by (key, block). After bond breaks the lists are updated against it instead of rebuilt.
  struct GridEntry {
    std::uint64_t key;
    int block;
    double x, y;
  };
  struct BroadGrid {
    bool valid = false;                               // false after a restore or an edit: the next one rebuilds
    double xmin = 0, ymin = 0, cell = 0, rmax = 0;    // origin, cell size, the largest eligible radius (m)
    std::vector<GridEntry> entries;
    std::size_t rebuilds = 0, updates = 0;            // how often each ran since the engine started
  };
  BroadGrid grid;
  std::vector<int> broken_now;                        // bonds broken since the last broad phase
  std::vector<double> damping_work;                   // per block grain: the damping work of the step (J)
  std::vector<std::uint8_t> moved;                    // per thread: one of its eligible blocks moved half a skin
};

struct StepContext {
  double dt = 0;        // s; 0 when only evaluating
  bool advance = true;  // advance histories and book energies
  int threads = 1;
};

namespace stages {

// cos and sin of every block's rotation, and the block records; the same for some blocks (block groups).
void update_rotations(const ModelState<2>& s, Workspace<2>& w, int threads);
void update_rotations_of(const ModelState<2>& s, Workspace<2>& w, const std::vector<int>& blocks);

// The partition for `threads` threads (set up again when the thread count changed; the bond stage and the
// integrator call it).
void partition(const Model<2>& m, Workspace<2>& w, int threads);
// Counts a step; every Partition::kRebalanceSteps steps, moves the boundaries towards equal measured times.
void rebalance(Workspace<2>& w);

// Each stage below that runs on threads is also given in parts, for a team its caller has opened already (the
// engine's step runs its stages in one parallel region): X_begin once before the team, X_share(t, nt) on each
// thread t of the team of nt, X_end once after every share. X itself is the three in a region of its own.

// The bond stage: slots of every bond (zero for broken ones) and, when advancing with breakage on, the bonds whose
// failure test held in w.flagged. Runs the partition's bond ranges in pieces (Workspace<2>::run_pieces);
// bond_forces_share returns the bonds its thread ran.
void bond_forces(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c);
void bond_forces_begin(const Model<2>& m, Workspace<2>& w, const StepContext& c);
int bond_forces_share(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c, int t, int nt);
// Whether any bond is flagged for bond_events.
inline bool events_pending(const Workspace<2>& w) {
  for (const auto& list : w.flagged)
    if (!list.empty()) return true;
  return false;
}
// Bond events in bond order: softening bonds advance their damage, bonds past their strength break (slot zeroed,
// free faces marked, the pair's contact takes over the linear shear force, crack logged, on_crack called).
// Returns the number of bonds that broke.
// The flagged bonds' forces are evaluated first, on `threads` threads; the events then run serially.
int bond_events(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const std::function<void(const Crack&)>& on_crack,
                int threads);
// The damage factor of every bond from its drive (after a restore or an edit).
void refresh_keep(const Model<2>& m, const ModelState<2>& s, Workspace<2>& w);

struct DetectionOptions {
  bool contacts = true;                // block-block contacts at all
  bool skip_bonded_pairs = true;       // no narrow phase for pairs joined by an intact bond
  bool search_free_faces_only = true;  // broad phase over free-face blocks only
  bool update_after_breaks = true;     // after bond breaks, update the lists instead of rebuilding them
};
// The boundary components' hooks, in the order installed (dem/boundary/hooks.hpp).
using Hooks = std::vector<BoundaryHooks<2>*>;
// The broad phase, when a block moved half a skin since the last rebuild or a component asks for one (the platen
// moved half a skin: a rebuild), or a bond broke (an update of the lists with the broken pairs and the blocks that
// gained a free face, or a rebuild after a restore or an edit). The components follow the lists (their
// candidates).
void detect_contacts(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const DetectionOptions& o,
                     const Hooks& hooks, int threads);
// The same test by a team (rebuild_due after every share): true when detect_contacts would rebuild.
void rebuild_check_begin(Workspace<2>& w, int threads);
void rebuild_check_share(const Model<2>& m, const ModelState<2>& s, Workspace<2>& w, int t, int nt);
bool rebuild_due(const Model<2>& m, const ModelState<2>& s, const Workspace<2>& w, const Hooks& hooks);
// The per-block accumulators w.cfx, w.cfy, w.cm of the contact and boundary forces are zero between steps: the
// stages below add to them and whoever reads them (integrate, gather_forces) resets them, each thread its own
// blocks, so no serial pass clears them and no block's accumulator changes cores (docs/performance.md).
void clear_accumulators(Workspace<2>& w);
// Narrow phase and contact law per pair, summed in pair order into w.cfx, w.cfy, w.cm.
void contact_forces(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c);
void contact_forces_begin(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c);
void contact_forces_share(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c, int t, int nt);
void contact_forces_end(ModelState<2>& s, Workspace<2>& w, const StepContext& c);
// Gather in fixed CSR order (resetting the accumulators), Cundall local damping alpha, central difference, and
// then, on the same thread and block range, the new rotations' cos and sin and the block records
// (update_rotations). Runs on the partition's block ranges. Throws InstabilityError when a position becomes non-finite.
void integrate(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, double damping, int threads);
// integrate_share returns false when a position of its blocks is not finite; integrate_end throws then. It runs
// the block ranges in pieces (Workspace<2>::run_pieces) and sets *items (when given) to the blocks it ran.
void integrate_begin(const Model<2>& m, Workspace<2>& w, int threads);
bool integrate_share(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, double damping, int t, int nt,
                     int* items);
void integrate_end(ModelState<2>& s, Workspace<2>& w, bool finite);
// The total generalized force on every block without damping (the same gather as integrate(), resetting the
// accumulators too).
void gather_forces(const Model<2>& m, Workspace<2>& w, std::vector<double>& fx, std::vector<double>& fy,
                   std::vector<double>& moment);

// The vertices of block b at its current position (x0, y0, x1, y1, x2, y2).
void block_vertices(const Model<2>& m, const ModelState<2>& s, const Workspace<2>& w, int b, double* out);
// The overlap of contact pair p, false when its blocks do not touch: their polygons clipped, block j's moved back
// towards i by the pair's opening (its dilation, LinearContact::update_shear), so that faces its asperities hold
// apart still press on each other. With no opening, the blocks' own overlap.
bool pair_overlap(const Model<2>& m, const ModelState<2>& s, const Workspace<2>& w, std::size_t p, Overlap& ov);

}  // namespace stages
}  // namespace rbdem
