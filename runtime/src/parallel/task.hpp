// One task of a farm, run in this thread or in a forked process of its own (farm.cpp), and the
// MPI farm (farm_mpi.cpp, MPI builds only).
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "symoro/parallel/farm.hpp"

namespace symoro::parallel::detail {

// Runs `task`, passing each result it emits to `result` (in the calling thread). The returned
// end has its failure, wall time and (isolated) peak memory; its task index and rank are the
// caller's to set.
TaskEnd run_task(const Farm& farm, const std::string& task, bool isolate,
                 const std::function<void(const std::string&)>& result);

// Worker threads per rank: the option, else the cores this process may run on (its affinity), or
// this machine's cores shared among the ranks on it when it is not bound.
int worker_count(const FarmOptions& options, int ranks_on_this_machine);

FarmSummary run_farm_mpi(const std::vector<std::string>& tasks, const Farm& farm, const FarmOptions& options);

}  // namespace symoro::parallel::detail
