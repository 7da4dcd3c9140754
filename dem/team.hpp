// The size of the engine's thread team when other processes compete for the cores (docs/performance.md, "Runs
// side by side").
//
// The engine's threads meet at barriers several times per step. When the machine has fewer free cores than the
// team has threads, a thread that reaches a barrier waits for one that the kernel has descheduled, and a step that
// takes 0.2 ms alone takes a scheduler time slice or more: two 2-thread runs on 2 cores each ran 37 times slower
// than one alone. The team therefore watches its own threads' run delay, the time the kernel kept them runnable but
// off every core (Linux /proc/thread-self/schedstat): over windows of about 50 ms of wall time, each thread reads
// its own counter at the start of a step. When the delay is more than `contended` of the team's time, the team
// shrinks to the threads that the cores gave it; a smaller team probes one size up after a wait that doubles with
// each failed probe (0.5 s to 8 s) and stays there when the probe finds the cores free.
//
// No result depends on the team size (the engine's stages do the same sums in the same order at any thread count),
// so the numbers of a run are the same however often the team changes.
#pragma once

#include <vector>

namespace rbdem {

// Where a run's steps spent their wall time, measured on the thread that calls step() (the first of the team):
// what limits the speed-up on more cores (docs/performance.md, "Scaling").
struct StepTimes {
  double bonds = 0;   // s: the bond stage and the contact rebuild check, to the barrier (the slowest thread's)
  double serial = 0;  // s: the sections on one thread between barriers (the block stages' set-up, the contact and
                      // boundary sums)
  double blocks = 0;  // s: contacts, the boundary components' shares and the integration, to the region's end
  double events = 0;  // s: bond events and contact detection, on the steps that have them
  double rest = 0;    // s: before the first region and after the last (the partition, the components' step ends)
  long steps = 0, event_steps = 0;
  // Per phase (0 the bond kernel, 1 the contact and boundary shares, 2 the integration), summed over the steps run
  // on the full team: the mean of the threads' busy time and the busiest thread's. The stage's wall time above
  // the busiest thread's is what the threads spent meeting; the busiest above the mean, the uneven split.
  double busy_mean[3] = {}, busy_max[3] = {};
  long busy_steps = 0;
  double total() const { return bonds + serial + blocks + events + rest; }
};

// One thread's busy time in each phase of the step it is running (StepTimes::busy_mean), on its own cache line.
struct alignas(64) ThreadBusy {
  double phase[3] = {};
};

// The calling thread's run delay: nanoseconds spent runnable but waiting for a core since the thread started.
// -1 where the kernel does not report it (no /proc, a kernel without schedstats): the team then keeps its size.
long long thread_run_delay_ns();

class TeamSize {
 public:
  struct Options {
    double window_seconds = 0.05;  // wall time over which the delay is measured
    double contended = 0.15;       // run delay over the team's time above which the team shrinks
    double first_probe_seconds = 0.5, last_probe_seconds = 8.0;  // wait before probing a larger team
  };
  // What the team did so far (the run log and tests).
  struct Counts {
    long windows = 0;             // windows measured
    long shrinks = 0;             // times the team shrank
    long probes = 0, failed_probes = 0;
    double contended_seconds = 0;  // wall time of the windows that found the cores taken
    double smaller_seconds = 0;    // wall time of the windows measured on fewer threads than the most
    int smallest = 0;             // the smallest team used
  };

  // max_threads: the most threads a step may use; adapt = false keeps the team at max_threads.
  TeamSize(int max_threads, bool adapt, Options options);
  TeamSize(int max_threads, bool adapt) : TeamSize(max_threads, adapt, Options{}) {}

  int size() const { return size_; }  // the most threads of the next step
  const Counts& counts() const { return counts_; }

  // The step protocol, on the thread that calls step(): begin(now, team) before the step's parallel region says
  // whether its threads read their run delay (read(t) on thread t of `team`, inside the region); end(now) after the
  // region decides the next size. `now` is wall time in seconds.
  bool begin(double now, int team);
  void read(int t);  // record(t, thread_run_delay_ns(), the calling thread's kernel id)
  void end(double now);
  // What read() records (tests feed it chosen delays): thread t's run delay and kernel thread id.
  void record(int t, long long delay_ns, long thread_id);

 private:
  bool usable_window(int team) const;
  void decide(double now, double fraction);

  Options options_;
  int max_ = 1, size_ = 1;
  bool adapt_ = false, sampling_ = false, probing_ = false, broken_ = false;
  int team_ = 0;                    // threads of the open window (0: none open)
  double window_start_ = 0;         // wall time the open window started
  double next_probe_ = 0, probe_wait_ = 0;
  std::vector<long long> delay_, delay_now_;  // per thread: run delay at the window's start, at this sample
  std::vector<long> tid_, tid_now_;           // the kernel thread that read it (a new thread restarts the window)
  Counts counts_;
};

}  // namespace rbdem
