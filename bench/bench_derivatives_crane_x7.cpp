// bench_derivatives (bench_derivatives.hpp) for the full CRANE-X7 model.
#include <symoro/crane_x7/all.hpp>

#include "bench_derivatives.hpp"

namespace {

SYMORO_BENCH_MODEL("crane_x7", symoro::crane_x7::Model)

}  // namespace
