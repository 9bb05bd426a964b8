// The loop's clocks (loop_clock.hpp): the steady clock the arm runs on, and a test's stepped clock.
#include "symoro/hardware/loop_clock.hpp"

#include <time.h>

#include <cerrno>
#include <utility>

namespace symoro::hardware {

namespace {
// Sleeps to `t` on CLOCK_MONOTONIC (libstdc++'s steady_clock); false when a stop request ended
// the sleep early. A signal (no SA_RESTART) interrupts it: it ends only for a stop request.
bool sleep_steady(LoopClock::time_point t, const std::atomic<int>& stop, int seen) {
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
  timespec ts{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR)
    if (stop.load(std::memory_order_relaxed) > seen) return false;
  return true;
}

class SteadyLoopClock final : public LoopClock {
 public:
  time_point now() const override { return std::chrono::steady_clock::now(); }
  void sleep_until(time_point t, const std::atomic<int>& stop, int seen) override { sleep_steady(t, stop, seen); }
  time_point io_deadline(time_point t) const override { return t; }
};
}  // namespace

LoopClock& steady_loop_clock() {
  static SteadyLoopClock clock;
  return clock;
}

SteppedClock::SteppedClock(bool paced, std::chrono::milliseconds io_timeout)
    : start_(std::chrono::steady_clock::now()), paced_(paced), io_timeout_(io_timeout) {}

LoopClock::time_point SteppedClock::now() const {
  return start_ + std::chrono::nanoseconds(elapsed_ns_.load(std::memory_order_acquire));
}

void SteppedClock::sleep_until(time_point t, const std::atomic<int>& stop, int seen) {
  const std::int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>(t - start_).count();
  if (ns <= elapsed_ns_.load(std::memory_order_relaxed)) return;
  if (paced_) {
    if (!sleep_steady(t + paused_, stop, seen)) return;
    const auto late = std::chrono::steady_clock::now() - (t + paused_);
    if (late > std::chrono::microseconds(100)) paused_ += late;
  }
  if (before_step_) before_step_();
  // The loop is the only writer; the plant's thread reads (release: the commands written after
  // this step are seen with it).
  elapsed_ns_.store(ns, std::memory_order_release);
}

LoopClock::time_point SteppedClock::io_deadline(time_point) const {
  return std::chrono::steady_clock::now() + io_timeout_;
}

double SteppedClock::seconds() const { return elapsed_ns_.load(std::memory_order_acquire) * 1e-9; }

}  // namespace symoro::hardware
