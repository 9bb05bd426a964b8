#include "symoro/identify/detail/ipopt_lock.hpp"

namespace symoro::identify::detail {

std::mutex& ipopt_mutex() {
  static std::mutex mutex;
  return mutex;
}

}  // namespace symoro::identify::detail
