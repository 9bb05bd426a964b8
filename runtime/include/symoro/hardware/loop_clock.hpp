// The time the control loop runs on (ControlOptions::clock).
//
// The arm's clock is the steady clock: the loop sleeps to absolute deadlines on CLOCK_MONOTONIC
// and a late wake-up is late (an overrun, skipped deadlines, the arm on held currents meanwhile).
//
// A SteppedClock is a test's clock: it stands still while the loop works and jumps to each
// deadline the loop sleeps to, so the loop is never late and the machine's load cannot reach
// what it controls. An emulated arm that integrates on the same clock (VirtualBus's plant
// clock) then sees a cycle every period exactly, however long the host took; the bus still waits
// for replies in real time, up to the clock's io_timeout per transaction. Unpaced, the loop runs
// as fast as the bus answers; paced, a step also waits for its deadline in real time, except
// that the time the host was late is left out (the clock pauses), so that signals and other
// threads meet the loop about when they would on the arm. Real-time behaviour (periods, jitter,
// overruns) is measured on the steady clock, by bench_control_loop.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>

namespace symoro::hardware {

class LoopClock {
 public:
  using time_point = std::chrono::steady_clock::time_point;
  virtual ~LoopClock() = default;
  virtual time_point now() const = 0;
  // Returns at `t`, or earlier once the stop requests in `stop` have passed `seen`.
  virtual void sleep_until(time_point t, const std::atomic<int>& stop, int seen) = 0;
  // The steady-clock deadline for a bus transaction that should end by `t` on this clock.
  virtual time_point io_deadline(time_point t) const = 0;
};

// The steady clock (the default): sleep_until is clock_nanosleep TIMER_ABSTIME on
// CLOCK_MONOTONIC, woken early by a stop request (a signal interrupts it); io_deadline(t) = t.
LoopClock& steady_loop_clock();

class SteppedClock final : public LoopClock {
 public:
  // Starts at the steady clock's now; each bus transaction may take up to `io_timeout` of real
  // time (a loaded machine may keep the emulated servos' thread from a core for a while).
  explicit SteppedClock(bool paced = false, std::chrono::milliseconds io_timeout = std::chrono::milliseconds(1000));
  time_point now() const override;
  // Moves the clock to `t` when `t` is later, after the before-step hook. Unpaced it never
  // waits; paced it waits for `t` in real time (less the pauses), or until a stop request.
  void sleep_until(time_point t, const std::atomic<int>& stop, int seen) override;
  // Called on the loop's thread before the clock moves. A command has no reply to wait for: an
  // emulated arm may read it only after the step, and integrate the period on the command before
  // it. The hook makes sure the arm has taken what was sent at the present time (a ping through
  // the same bus: its reply comes after the command).
  void set_before_step(std::function<void()> hook) { before_step_ = std::move(hook); }
  // The steady clock's now + io_timeout, whatever `t`.
  time_point io_deadline(time_point t) const override;
  // Seconds since the clock started: thread-safe, for a plant that integrates on this clock.
  double seconds() const;

 private:
  time_point start_;
  bool paced_;
  std::chrono::steady_clock::duration paused_{};  // real time left out while the loop was late
  std::atomic<std::int64_t> elapsed_ns_{0};
  std::chrono::milliseconds io_timeout_;
  std::function<void()> before_step_;
};

}  // namespace symoro::hardware
