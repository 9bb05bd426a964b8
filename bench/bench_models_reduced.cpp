// bench_models (bench_models.hpp) for CRANE-X7's 39-parameter variant of the paper (crane_x7::reduced).
#include <symoro/crane_x7/reduced/all.hpp>

#include "bench_models.hpp"

namespace {

using Reduced = symoro::crane_x7::reduced::Model;
SYMORO_BENCH_ALL(Reduced);

}  // namespace
