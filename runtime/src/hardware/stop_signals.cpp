// The stop signals (controller.hpp): every signal whose default would end the process counts as
// a stop request, SIGPIPE is ignored, while a StopSignals lives.
#include <time.h>

#include <cmath>
#include <csignal>
#include <cstring>
#include <string>

#include "symoro/hardware/controller.hpp"

namespace symoro::hardware {

namespace {
// Lock-free, so the handler may touch it (a signal handler may only use lock-free atomics).
std::atomic<int> g_stop{0};
static_assert(std::atomic<int>::is_always_lock_free, "the stop flag must be lock-free for the signal handler");
// When the last counted request arrived (CLOCK_MONOTONIC, ns; 0: none yet), and whether it was
// typed at the terminal.
std::atomic<long long> g_last_ns{0};
std::atomic<bool> g_last_typed{false};
std::atomic<int> g_last_signal{0};  // the signal of the last counted request
static_assert(std::atomic<long long>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "the signal handler's state must be lock-free");

// One stop request per deliberate act. GNU timeout and systemd send SIGTERM to the process and
// again to its group, microseconds apart: counted twice, that pair would end the hold at once
// and drop the arm. So a further signal counts only when it comes kStopEscalationDelay after the
// last counted one, or when it and that one are both typed at the terminal (Ctrl-C, Ctrl-\: the
// kernel sends those, si_code SI_KERNEL; kill(), timeout and systemd send SI_USER).
extern "C" void stop_signal_handler(int sig, siginfo_t* info, void*) {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);  // async-signal-safe
  const long long now = static_cast<long long>(ts.tv_sec) * 1'000'000'000LL + ts.tv_nsec;
  const bool typed = (sig == SIGINT || sig == SIGQUIT) && info != nullptr && info->si_code == SI_KERNEL;
  const long long last = g_last_ns.load(std::memory_order_relaxed);
  const long long delay = std::llround(kStopEscalationDelay * 1e9);
  if (last != 0 && now - last < delay && !(typed && g_last_typed.load(std::memory_order_relaxed))) return;
  g_last_ns.store(now, std::memory_order_relaxed);
  g_last_typed.store(typed, std::memory_order_relaxed);
  g_last_signal.store(sig, std::memory_order_relaxed);
  g_stop.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

std::atomic<int>& stop_flag() { return g_stop; }

std::string last_stop_signal() {
  const int sig = g_last_signal.load(std::memory_order_relaxed);
  if (sig == 0) return "";
  if (sig >= SIGRTMIN && sig <= SIGRTMAX) return "SIGRTMIN+" + std::to_string(sig - SIGRTMIN);
  const char* name = sigabbrev_np(sig);
  return name ? std::string("SIG") + name : "signal " + std::to_string(sig);
}

const std::vector<int>& stop_signals() {
  static const std::vector<int> signals = [] {
    // Every catchable signal whose default action ends the process (signal(7)), but for SIGPIPE
    // (ignored) and the faults a program cannot continue after (SIGSEGV, SIGBUS, SIGFPE, SIGILL,
    // SIGABRT, SIGTRAP, SIGSYS: the servos' bus watchdog covers those, docs/safety.md).
    std::vector<int> v{SIGINT,  SIGTERM,   SIGHUP,  SIGQUIT, SIGUSR1, SIGUSR2,
                       SIGALRM, SIGVTALRM, SIGPROF, SIGXCPU, SIGXFSZ, SIGIO};
#ifdef SIGPWR
    v.push_back(SIGPWR);
#endif
#ifdef SIGSTKFLT
    v.push_back(SIGSTKFLT);
#endif
    for (int s = SIGRTMIN; s <= SIGRTMAX; ++s) v.push_back(s);
    return v;
  }();
  return signals;
}

StopSignals::StopSignals() : signals_(stop_signals()), previous_(signals_.size()) {
  g_stop.store(0);
  g_last_ns.store(0);
  g_last_typed.store(false);
  g_last_signal.store(0);
  struct sigaction sa {};
  sa.sa_sigaction = stop_signal_handler;
  sigemptyset(&sa.sa_mask);
  for (int s : signals_) sigaddset(&sa.sa_mask, s);  // one handler at a time: the check and update stay whole
  sa.sa_flags = SA_SIGINFO;                          // no SA_RESTART: a sleeping loop wakes up at once
  for (std::size_t i = 0; i < signals_.size(); ++i) sigaction(signals_[i], &sa, &previous_[i]);
  // A closed stdout or stderr (`dynid control ... | head -1`) must not end the run: a write
  // there fails with EPIPE instead.
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGPIPE, &ignore, &pipe_previous_);
}

StopSignals::~StopSignals() {
  for (std::size_t i = 0; i < signals_.size(); ++i) sigaction(signals_[i], &previous_[i], nullptr);
  sigaction(SIGPIPE, &pipe_previous_, nullptr);
  g_stop.store(0);  // served its run: a later run without handlers must not stop at once
  g_last_ns.store(0);
  g_last_signal.store(0);
}

}  // namespace symoro::hardware
