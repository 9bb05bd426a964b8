// bench_derivatives (bench_derivatives.hpp) for CRANE-X7's reduced variant.
#include <symoro/crane_x7/reduced/all.hpp>

#include "bench_derivatives.hpp"

namespace {

SYMORO_BENCH_MODEL("crane_x7::reduced", symoro::crane_x7::reduced::Model)

}  // namespace
