// A generated model in the robot library's C ABI (symoro/robot_abi.h), declared only: the
// definitions are in robot_abi_export-inl.hpp and robot_abi_second_derivatives-inl.hpp, and
// symoroc build's units instantiate them once per model (codegen/src/robot_library.cpp). Those
// objects make both the robot's shared library and the kernels a program links statically
// (symoro::<robot>_identification, `symoroc build --objects`), so that a robot's kernels are
// compiled once whichever way they are called.
#pragma once

#include "symoro/robot_abi.h"

namespace symoro::abi_export {

// The C description and kernels of one generated Model (static storage).
template <class Model>
symoro_abi_model model_abi();

// M, dM/dq and d2M/dq2 of a model: Jets, compiled in a unit of their own so that a model's two
// halves compile in parallel.
template <class Model>
void inertia_second_derivatives(const double* q, const double* phi, double* m, double* dm, double* d2m);

}  // namespace symoro::abi_export
