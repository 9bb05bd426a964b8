// The task farm on one machine (the MPI farm: mpi_ranks.cmake): every task once, its results in
// the order emitted, failures that stay with their task (an exception, a process killed by a
// signal), isolation that starts every task from the same state, and the peak memory of an
// isolated task's own process.
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "symoro/parallel/farm.hpp"

namespace {

using symoro::parallel::Farm;
using symoro::parallel::FarmOptions;
using symoro::parallel::FarmSummary;
using symoro::parallel::TaskEnd;

struct Collected {
  std::map<std::size_t, std::vector<std::string>> results;
  std::vector<TaskEnd> ends;
};

FarmSummary run(const std::vector<std::string>& tasks, Farm farm, bool isolate, int workers, Collected& c) {
  farm.on_result = [&](std::size_t i, const std::string& r) { c.results[i].push_back(r); };
  farm.on_end = [&](const TaskEnd& e) { c.ends.push_back(e); };
  FarmOptions o;
  o.isolate = isolate;
  o.workers = workers;
  return symoro::parallel::run_farm(tasks, farm, o);
}

std::vector<std::string> numbered(int n) {
  std::vector<std::string> v;
  for (int i = 0; i < n; ++i) v.push_back(std::to_string(i));
  return v;
}

class FarmModes : public ::testing::TestWithParam<bool> {};

TEST_P(FarmModes, EveryTaskOnceWithItsResultsInOrder) {
  const auto tasks = numbered(23);
  Farm farm;
  farm.work = [](const std::string& t, const std::function<void(const std::string&)>& emit) {
    for (int k = 0; k < 3; ++k) emit(t + ":" + std::to_string(k) + ":" + std::string(std::stoi(t) * 1000, 'x'));
  };
  Collected c;
  const FarmSummary s = run(tasks, farm, GetParam(), 3, c);
  EXPECT_EQ(s.ranks, 1);
  EXPECT_EQ(s.workers, 3);
  ASSERT_EQ(c.ends.size(), tasks.size());
  std::set<std::size_t> ended;
  for (const TaskEnd& e : c.ends) {
    EXPECT_FALSE(e.failed) << e.failure;
    ended.insert(e.task);
  }
  EXPECT_EQ(ended.size(), tasks.size());
  ASSERT_EQ(c.results.size(), tasks.size());
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    ASSERT_EQ(c.results[i].size(), 3u) << "task " << i;
    for (int k = 0; k < 3; ++k)  // through a pipe, up to 22 kB each: whole and in order
      EXPECT_EQ(c.results[i][k], tasks[i] + ":" + std::to_string(k) + ":" + std::string(i * 1000, 'x'));
  }
  ASSERT_EQ(s.tasks.size(), tasks.size());
  for (std::size_t i = 0; i < tasks.size(); ++i) EXPECT_EQ(s.tasks[i].task, i);
}

TEST_P(FarmModes, AThrowingTaskFailsAloneAndKeepsWhatItEmitted) {
  Farm farm;
  farm.work = [](const std::string& t, const std::function<void(const std::string&)>& emit) {
    emit("first of " + t);
    if (t == "3") throw std::runtime_error("log of task 3: line 7: not a number");
    emit("second of " + t);
  };
  Collected c;
  const FarmSummary s = run(numbered(6), farm, GetParam(), 2, c);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(s.tasks[i].failed, i == 3);
    EXPECT_EQ(c.results[i].size(), i == 3 ? 1u : 2u);
  }
  EXPECT_EQ(s.tasks[3].failure, "log of task 3: line 7: not a number");
  EXPECT_EQ(c.results[3][0], "first of 3");
}

// Also run on 2 MPI ranks (runtime.mpi_farm_stop, MPI builds): the coordinator hands out every
// task, its own workers' and the other ranks', so Farm::stop holds there too.
TEST_P(FarmModes, StopHandsOutNoFurtherTaskAndTheRestEndStopped) {
  const auto tasks = numbered(40);
  Farm farm;
  farm.work = [](const std::string& t, const std::function<void(const std::string&)>& emit) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    emit(t);
  };
  Collected c;
  int asked = 0;
  farm.stop = [&] {  // called one at a time with on_end, on the coordinator only
    ++asked;
    return c.ends.size() >= 4;
  };
  const FarmSummary s = run(tasks, farm, GetParam(), 2, c);
  if (!symoro::parallel::place().coordinator()) {
    EXPECT_EQ(asked, 0);
    return;
  }
  EXPECT_TRUE(s.stopped);
  ASSERT_EQ(s.tasks.size(), tasks.size());
  // The tasks handed out are a prefix of the list, each finished with its result; the others
  // end "stopped" without having run. At most the workers' tasks in flight (2 per rank) ran
  // after the fourth ended.
  std::size_t ran = 0;
  while (ran < tasks.size() && !s.tasks[ran].failed) ++ran;
  EXPECT_GE(ran, 4u);
  EXPECT_LE(ran, 4u + 2u * static_cast<std::size_t>(s.ranks));
  EXPECT_EQ(c.ends.size(), ran);
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (i < ran) {
      EXPECT_EQ(c.results[i], std::vector<std::string>{tasks[i]}) << i;
    } else {
      EXPECT_TRUE(s.tasks[i].failed && s.tasks[i].failure == "stopped") << i;
      EXPECT_EQ(c.results.count(i), 0u) << i;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(InProcessAndIsolated, FarmModes, ::testing::Values(false, true));

TEST(Farm, AnIsolatedTaskKilledBySignalFailsWithTheSignalNamedAndTheOthersFinish) {
  Farm farm;
  farm.work = [](const std::string& t, const std::function<void(const std::string&)>& emit) {
    emit("started " + t);
    if (t == "segv") std::raise(SIGSEGV);
    if (t == "kill") std::raise(SIGKILL);  // what the kernel's OOM killer sends
    if (t == "exit") std::_Exit(7);
    emit("done " + t);
  };
  Collected c;
  const FarmSummary s = run({"a", "segv", "b", "kill", "exit", "c"}, farm, true, 2, c);
  for (std::size_t i : {0u, 2u, 5u}) {
    EXPECT_FALSE(s.tasks[i].failed) << s.tasks[i].failure;
    EXPECT_EQ(c.results[i].size(), 2u);
  }
  EXPECT_TRUE(s.tasks[1].failed);
  EXPECT_NE(s.tasks[1].failure.find("killed by signal " + std::to_string(SIGSEGV)), std::string::npos)
      << s.tasks[1].failure;
  EXPECT_TRUE(s.tasks[3].failed);
  EXPECT_NE(s.tasks[3].failure.find("out of memory?"), std::string::npos) << s.tasks[3].failure;
  EXPECT_TRUE(s.tasks[4].failed);
  EXPECT_NE(s.tasks[4].failure.find("exited with code 7"), std::string::npos) << s.tasks[4].failure;
  for (std::size_t i : {1u, 3u, 4u}) ASSERT_EQ(c.results[i].size(), 1u);  // what it sent before it died
}

// What a solver keeps between calls stands for here: a process-wide counter.
int calls = 0;

TEST(Farm, IsolatedTasksStartFromTheSameStateInProcessOnesDoNot) {
  Farm farm;
  farm.work = [](const std::string&, const std::function<void(const std::string&)>& emit) {
    emit(std::to_string(++calls));
  };
  for (bool isolate : {true, false}) {
    calls = 0;
    Collected c;
    run(numbered(8), farm, isolate, 1, c);  // one worker: no race on the counter
    std::set<std::string> seen;
    for (auto& [i, r] : c.results) seen.insert(r.at(0));
    if (isolate) {
      EXPECT_EQ(seen, std::set<std::string>{"1"});  // every task saw the parent's state
      EXPECT_EQ(calls, 0);                          // and left it untouched
    } else {
      EXPECT_EQ(seen.size(), 8u);  // each saw the ones before it
      EXPECT_EQ(calls, 8);
    }
  }
}

TEST(Farm, AnIsolatedTasksPeakMemoryIsItsOwn) {
  Farm farm;
  farm.work = [](const std::string& t, const std::function<void(const std::string&)>& emit) {
    if (t == "big") {
      std::vector<char> block(300u << 20);
      std::memset(block.data(), 1, block.size());  // resident, not only reserved
      emit(std::to_string(static_cast<int>(block[block.size() / 2])));
    } else {
      emit("small");
    }
  };
  Collected c;
  const FarmSummary s = run({"big", "small"}, farm, true, 1, c);
  EXPECT_EQ(c.results[0].at(0), "1");
  EXPECT_GE(s.tasks[0].peak_memory_mb, 300);
  EXPECT_LT(s.tasks[1].peak_memory_mb, 200);  // the parent never held the 300 MB
}

TEST(Farm, ByDefaultAsManyWorkersAsCoresTheProcessMayUse) {
  Farm farm;
  farm.work = [](const std::string& t, const std::function<void(const std::string&)>& emit) { emit(t); };
  cpu_set_t all, one;
  ASSERT_EQ(sched_getaffinity(0, sizeof all, &all), 0);
  Collected c;
  const int cores = CPU_COUNT(&all);
  EXPECT_EQ(run(numbered(64), farm, false, 0, c).workers, std::min(cores, 64));
  // Bound to one core (as mpirun binds a rank when it starts two or fewer): one worker.
  CPU_ZERO(&one);
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &all)) {
      CPU_SET(cpu, &one);
      break;
    }
  ASSERT_EQ(sched_setaffinity(0, sizeof one, &one), 0);
  const int bound = run(numbered(64), farm, false, 0, c).workers;
  ASSERT_EQ(sched_setaffinity(0, sizeof all, &all), 0);
  EXPECT_EQ(bound, 1);
}

TEST(Farm, WithoutALauncherTheJobIsOneRank) {
  const auto p = symoro::parallel::place();
  EXPECT_EQ(p.rank, 0);
  EXPECT_EQ(p.ranks, 1);
  EXPECT_TRUE(p.coordinator());
}

}  // namespace
