// The compiled part of the Python package: symoro._symoro (docs/python.md). The models, the
// workflow's functions, and the project's errors as Python exceptions with the same text.
#include <pybind11/pybind11.h>

#include "symoro/error.hpp"
#include "symoro/study/study.hpp"

namespace symoro::python {

namespace py = pybind11;

void bind_models(py::module_& m);
void bind_workflow(py::module_& m);
void bind_results(py::module_& m);
void bind_export(py::module_& m);
void bind_diagnose(py::module_& m);
void bind_observer(py::module_& m);
void bind_payload(py::module_& m);

}  // namespace symoro::python

PYBIND11_MODULE(_symoro, m) {
  namespace py = pybind11;
  m.doc() = "symoro's compiled core: robot models and the identification workflow";
  // A file's problem (file:line: error: message): a ValueError, with .file and .line.
  static py::exception<symoro::DataError> data_error(m, "DataError", PyExc_ValueError);
  static py::exception<symoro::study::StudyStopped> stopped(m, "StudyStopped", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const symoro::DataError& e) {
      py::object err = py::reinterpret_borrow<py::object>(data_error.ptr())(e.what());
      err.attr("file") = e.file();
      err.attr("line") = e.line();
      PyErr_SetObject(data_error.ptr(), err.ptr());
    } catch (const symoro::study::StudyStopped& e) {
      stopped(e.what());
    }
  });
  symoro::python::bind_models(m);
  symoro::python::bind_workflow(m);
  symoro::python::bind_results(m);
  symoro::python::bind_export(m);
  symoro::python::bind_diagnose(m);
  symoro::python::bind_observer(m);
  symoro::python::bind_payload(m);
}
