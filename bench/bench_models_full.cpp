// bench_models (bench_models.hpp) for the full 65-parameter CRANE-X7 model (crane_x7::Model).
#include <symoro/crane_x7/all.hpp>

#include "bench_models.hpp"

namespace {

using Full = symoro::crane_x7::Model;
SYMORO_BENCH_ALL(Full);

}  // namespace
