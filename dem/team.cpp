#include "dem/team.hpp"

#include <fcntl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace rbdem {

namespace {

// The calling thread's schedstat file, opened once per thread (the descriptor stays bound to the thread that
// opened it; pread at offset 0 reads the counters afresh, about 0.3 us).
struct SchedStat {
  int fd = -2;  // -2: not yet opened; -1: not available
  ~SchedStat() {
    if (fd >= 0) ::close(fd);
  }
};

long thread_id() { return long(::syscall(SYS_gettid)); }

}  // namespace

long long thread_run_delay_ns() {
  thread_local SchedStat file;
  if (file.fd == -2) file.fd = ::open("/proc/thread-self/schedstat", O_RDONLY | O_CLOEXEC);
  if (file.fd < 0) return -1;
  char text[96];
  const ssize_t n = ::pread(file.fd, text, sizeof text - 1, 0);
  if (n <= 0) return -1;
  text[n] = '\0';
  // "exec_ns run_delay_ns timeslices"
  char* end = nullptr;
  std::strtoll(text, &end, 10);
  if (end == text) return -1;
  char* end2 = nullptr;
  const long long delay = std::strtoll(end, &end2, 10);
  return end2 == end ? -1 : delay;
}

TeamSize::TeamSize(int max_threads, bool adapt, Options options)
    : options_(options), max_(std::max(max_threads, 1)), size_(max_), adapt_(adapt && max_ > 1) {
  const std::size_t n = std::size_t(max_);
  delay_.assign(n, 0), delay_now_.assign(n, 0), tid_.assign(n, 0), tid_now_.assign(n, 0);
  probe_wait_ = options_.first_probe_seconds;
  counts_.smallest = max_;
}

bool TeamSize::begin(double now, int team) {
  sampling_ = false;
  if (!adapt_ || broken_) return false;
  if (team_ == team && now - window_start_ < options_.window_seconds) return false;
  std::fill(tid_now_.begin(), tid_now_.end(), 0);
  sampling_ = true;
  return true;
}

void TeamSize::read(int t) { record(t, thread_run_delay_ns(), thread_id()); }

void TeamSize::record(int t, long long delay_ns, long id) {
  delay_now_[std::size_t(t)] = delay_ns;
  tid_now_[std::size_t(t)] = id;
}

bool TeamSize::usable_window(int team) const {
  if (team_ != team) return false;
  for (int t = 0; t < team; ++t)
    if (tid_now_[std::size_t(t)] != tid_[std::size_t(t)] || tid_now_[std::size_t(t)] == 0) return false;
  return true;
}

void TeamSize::end(double now) {
  if (!sampling_) return;
  sampling_ = false;
  // The team of this sample: the threads that read (a sweep's budget may have run the step on fewer than size()).
  int team = 0;
  while (team < max_ && tid_now_[std::size_t(team)] != 0) ++team;
  for (int t = 0; t < team; ++t)
    if (delay_now_[std::size_t(t)] < 0) {
      broken_ = true;  // the kernel does not report run delays: keep the size
      return;
    }
  if (usable_window(team)) {
    long long delay = 0;
    for (int t = 0; t < team; ++t) delay += delay_now_[std::size_t(t)] - delay_[std::size_t(t)];
    const double wall = now - window_start_;
    if (wall > 0) decide(now, double(delay) * 1e-9 / (double(team) * wall));
  }
  team_ = team, window_start_ = now;
  std::copy(delay_now_.begin(), delay_now_.begin() + team, delay_.begin());
  std::copy(tid_now_.begin(), tid_now_.begin() + team, tid_.begin());
}

void TeamSize::decide(double now, double fraction) {
  ++counts_.windows;
  if (team_ < max_) counts_.smaller_seconds += now - window_start_;
  const bool probe = probing_;
  probing_ = false;
  if (fraction > options_.contended) {
    counts_.contended_seconds += now - window_start_;
    if (probe) {
      ++counts_.failed_probes;
      probe_wait_ = std::min(2 * probe_wait_, options_.last_probe_seconds);
    }
    // The cores gave the team about (1 - fraction) of its threads' time: keep that many threads.
    const int fit = int(std::lround(double(team_) * (1 - fraction)));
    const int next = std::clamp(std::min(fit, team_ - 1), 1, max_);
    if (next < size_) ++counts_.shrinks;
    size_ = std::min(size_, next);
    next_probe_ = now + probe_wait_;
    counts_.smallest = std::min(counts_.smallest, size_);
    return;
  }
  if (probe) probe_wait_ = options_.first_probe_seconds;  // the larger team found its cores free
  if (size_ < max_ && team_ == size_ && now >= next_probe_) {
    ++counts_.probes;
    probing_ = true;
    size_ = std::min(max_, size_ + std::max(1, size_ / 2));
  }
}

}  // namespace rbdem
