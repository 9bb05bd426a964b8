#include "arrays.hpp"

#include <cmath>

#include <fmt/format.h>

namespace symoro::python {

namespace {

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += fmt::format("{}{}", i ? ", " : "", a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// A C-ordered, aligned array of native float64: read through NumPy's structs directly (the
// per-call cost of one state is mostly such checks).
bool native_doubles(py::handle value) {
  const auto& api = py::detail::npy_api::get();
  if (!api.PyArray_Check_(value.ptr())) return false;
  const auto* a = py::detail::array_proxy(value.ptr());
  const auto* d = py::detail::array_descriptor_proxy(a->descr);
  constexpr int needed = py::detail::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | py::detail::npy_api::NPY_ARRAY_ALIGNED_;
  return d->type_num == py::detail::npy_api::NPY_DOUBLE_ && d->byteorder != '>' && (a->flags & needed) == needed;
}

// Any other value: an array of real numbers (bool, complex, text and objects refused), converted
// to C-ordered float64.
DoubleArray converted(py::handle value, const char* name, int width) {
  if (value.is_none()) throw py::type_error(fmt::format("{}: expected an array of {} numbers, got None", name, width));
  py::array any = py::array::ensure(value);
  if (!any) {
    PyErr_Clear();
    throw py::type_error(
        fmt::format("{}: expected an array of numbers, got {}", name, py::str(value.get_type()).cast<std::string>()));
  }
  const char kind = any.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::type_error(fmt::format("{}: expected real numbers, got an array of dtype {}", name,
                                     py::str(any.dtype()).cast<std::string>()));
  DoubleArray a = DoubleArray::ensure(any);
  if (!a) throw py::error_already_set();
  return a;
}

}  // namespace

StateArg state_arg(py::handle value, const char* name, int width) {
  StateArg arg;
  if (native_doubles(value)) {  // C-ordered float64 already: no conversion at all
    arg.array = py::reinterpret_borrow<DoubleArray>(value);
  } else {
    arg.array = converted(value, name, width);
  }
  const py::ssize_t nd = arg.array.ndim();
  if (!((nd == 1 && arg.array.shape(0) == width) || (nd == 2 && arg.array.shape(1) == width)))
    throw py::value_error(
        fmt::format("{}: expected shape ({},) or (N, {}), got {}", name, width, width, shape_text(arg.array)));
  arg.batch = nd == 2;
  arg.n = arg.batch ? arg.array.shape(0) : 1;
  const double* p = arg.array.data();
  const std::ptrdiff_t size = arg.n * width;
  for (std::ptrdiff_t i = 0; i < size; ++i)
    if (!std::isfinite(p[i])) {
      const std::string where = arg.batch ? fmt::format("[{}, {}]", i / width, i % width) : fmt::format("[{}]", i);
      throw py::value_error(fmt::format("{}: {} at {} (every entry must be finite)", name, p[i], where));
    }
  return arg;
}

std::ptrdiff_t common_batch(std::initializer_list<std::pair<const char*, const StateArg*>> args, bool& batch) {
  const auto& [first_name, first] = *args.begin();
  for (const auto& [name, a] : args)
    if (a->batch != first->batch || a->n != first->n)
      throw py::value_error(
          fmt::format("{}: {} where {} is {} (the same number of states for every argument)", name,
                      a->batch ? fmt::format("a batch of {}", a->n) : std::string("one state"), first_name,
                      first->batch ? fmt::format("a batch of {}", first->n) : std::string("one state")));
  batch = first->batch;
  return first->n;
}

std::ptrdiff_t phi_stride(const StateArg& phi, const char* name, std::ptrdiff_t n, bool batch) {
  if (!phi.batch) return 0;
  if (!batch || phi.n != n)
    throw py::value_error(fmt::format("{}: a batch of {} parameter vectors for {} (give one vector, or one per state)",
                                      name, phi.n, batch ? fmt::format("{} states", n) : std::string("one state")));
  return phi.array.shape(1);
}

py::array_t<double> output(bool batch, std::ptrdiff_t n, std::initializer_list<py::ssize_t> dims) {
  py::ssize_t shape[4];
  int nd = 0;
  if (batch) shape[nd++] = n;
  for (py::ssize_t d : dims) shape[nd++] = d;
  const auto& api = py::detail::npy_api::get();
  // NumPy's own constructor, without the shape and stride vectors pybind11's would allocate.
  PyObject* a = api.PyArray_NewFromDescr_(api.PyArray_Type_, py::dtype::of<double>().release().ptr(), nd, shape,
                                          nullptr, nullptr, 0, nullptr);
  if (!a) throw py::error_already_set();
  return py::reinterpret_steal<py::array_t<double>>(a);
}

}  // namespace symoro::python
