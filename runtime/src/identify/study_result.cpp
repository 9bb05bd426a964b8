#include "symoro/identify/study_result.hpp"

#include <cmath>

namespace symoro::identify {

std::string RunRecord::id() const {
  return trajectory + "@" + std::to_string(static_cast<long>(std::lround(interval * 1000))) + "ms";
}

}  // namespace symoro::identify
