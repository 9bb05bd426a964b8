// bench_derivatives (bench_derivatives.hpp) for the smaller robots: RX90, Stanford RRP, planar 2R.
#include <symoro/planar2r.hpp>
#include <symoro/rx90.hpp>
#include <symoro/stanford_rrp.hpp>

#include "bench_derivatives.hpp"

namespace {

SYMORO_BENCH_MODEL("rx90", symoro::rx90::Model)
SYMORO_BENCH_MODEL("stanford_rrp", symoro::stanford_rrp::Model)
SYMORO_BENCH_MODEL("planar2r", symoro::planar2r::Model)

}  // namespace
