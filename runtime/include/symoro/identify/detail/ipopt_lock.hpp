// Ipopt's linear solver here (MUMPS, Ipopt 3.11) keeps global state and is not thread-safe:
// every Ipopt solve of the library (the PD audit's local searches, excitation designs) holds
// this one lock.
#pragma once

#include <mutex>

namespace symoro::identify::detail {

std::mutex& ipopt_mutex();

}  // namespace symoro::identify::detail
