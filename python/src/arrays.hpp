// NumPy arguments of the model functions: checked (shape, dtype, finite values, each error
// naming the argument) and taken without a copy when already C-ordered float64.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

namespace symoro::python {

namespace py = pybind11;

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// One argument of `width` numbers per state: shape (width,) for one state, (N, width) for N.
struct StateArg {
  DoubleArray array;  // the caller's array itself when C-ordered float64, else a converted copy
  std::ptrdiff_t n = 1;
  bool batch = false;
  const double* data() const { return array.data(); }
};

// TypeError for a value that is not an array of real numbers (bool, complex, text, objects);
// ValueError for another shape or a NaN or infinite entry, with its index.
StateArg state_arg(py::handle value, const char* name, int width);

// The batch of several arguments: all single states, or all batches of the same N (ValueError
// naming the first that differs). `phi`-like arguments that may be one row for a whole batch
// are not passed here.
std::ptrdiff_t common_batch(std::initializer_list<std::pair<const char*, const StateArg*>> args, bool& batch);

// A phi for n states: one (np,) for all, or (n, np); its row stride (0 or np).
std::ptrdiff_t phi_stride(const StateArg& phi, const char* name, std::ptrdiff_t n, bool batch);

// A new float64 array of shape (n, dims...) for a batch, (dims...) otherwise.
py::array_t<double> output(bool batch, std::ptrdiff_t n, std::initializer_list<py::ssize_t> dims);  // up to 3 dims

}  // namespace symoro::python
