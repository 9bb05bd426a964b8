#include "symoro/study/result.hpp"

#include <cmath>

namespace symoro::study {

std::string RunRecord::id() const {
  return trajectory + "@" + std::to_string(static_cast<long>(std::lround(interval * 1000))) + "ms";
}

}  // namespace symoro::study
