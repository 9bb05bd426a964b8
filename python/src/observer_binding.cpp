// symoro.MomentumObserver, symoro.observer_thresholds and symoro.collision_events
// (docs/observer.md): the C++ observer (symoro/observer/) over a Python model, on NumPy arrays
// (results through pybind11's Eigen conversion, as the workflow's records).
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "symoro/observer/collision_detection.hpp"
#include "symoro/observer/momentum_observer.hpp"

namespace symoro::python {

const robot::ModelHandle& handle_of(py::handle model);

namespace {

Eigen::VectorXd vector_of(py::handle value, const char* name, int width) {
  const StateArg a = state_arg(value, name, width);
  if (a.batch) throw py::value_error(std::string(name) + " must be one vector of " + std::to_string(width));
  return Eigen::Map<const Eigen::VectorXd>(a.data(), width);
}

// A (N, n) C-ordered array as an Eigen matrix.
Eigen::MatrixXd matrix_of(py::handle value, const char* name, int width) {
  const StateArg a = state_arg(value, name, width);
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  return Eigen::Map<const RowMajor>(a.data(), a.batch ? a.n : 1, width);
}

// A (N,) array of time stamps (s), finite.
Eigen::VectorXd times_of(py::handle value, const std::string& name) {
  const DoubleArray a = DoubleArray::ensure(value);
  if (!a || a.ndim() != 1) throw py::value_error(name + " must be an (N,) array of time stamps");
  Eigen::VectorXd t = Eigen::Map<const Eigen::VectorXd>(a.data(), a.shape(0));
  if (!t.allFinite()) throw py::value_error(name + " has a NaN or infinite stamp");
  return t;
}

// The width of an (N, width) array argument.
int columns_of(py::handle value, const char* name) {
  const DoubleArray a = DoubleArray::ensure(value);
  if (!a || a.ndim() != 2) throw py::value_error(std::string(name) + " must be an (N, nq) array");
  return static_cast<int>(a.shape(1));
}

py::dict thresholds_dict(const observer::ObserverThresholds& t) {
  py::dict d;
  d["center"] = t.center;
  d["spread"] = t.spread;
  d["tail"] = t.tail;
  d["peak"] = t.peak;
  d["threshold"] = t.threshold;
  d["window"] = t.window;
  d["windows"] = t.windows;
  d["false_alarms_per_hour"] = t.false_alarms_per_hour;
  d["peak_margin"] = t.peak_margin;
  d["seconds"] = t.seconds;
  d["samples"] = t.samples;
  d["tail_alarms"] = t.tail_alarms;
  return d;
}

observer::ObserverThresholds thresholds_from(const py::dict& d, int n) {
  observer::ObserverThresholds t;
  for (const char* key : {"center", "threshold"})
    if (!d.contains(key))
      throw py::value_error(std::string("thresholds: no '") + key + "' (observer_thresholds gives it)");
  t.center = vector_of(d["center"], "thresholds['center']", n);
  t.threshold = vector_of(d["threshold"], "thresholds['threshold']", n);
  return t;
}

}  // namespace

void bind_observer(py::module_& m) {
  using observer::MomentumObserver;
  py::class_<MomentumObserver>(m, "MomentumObserver",
                               "The generalized-momentum observer of a model and its parameters (docs/observer.md): "
                               "r, the external torque per joint through a first-order lag of corner gain (1/s)")
      .def(py::init([](py::handle model, py::handle phi, py::object gain, const std::string& inertia_rate) {
             const robot::ModelHandle& h = handle_of(model);
             observer::MomentumObserverOptions o;
             if (py::isinstance<py::float_>(gain) || py::isinstance<py::int_>(gain))
               o.default_gain = gain.cast<double>();
             else
               o.gain = vector_of(gain, "gain", h.nq());
             if (inertia_rate == "derivatives")
               o.inertia_rate = observer::InertiaRate::derivatives;
             else if (inertia_rate != "difference")
               throw py::value_error("inertia_rate: 'difference' or 'derivatives', not '" + inertia_rate + "'");
             try {
               return MomentumObserver(h, vector_of(phi, "phi", h.np()), o);
             } catch (const std::invalid_argument& e) {
               throw py::value_error(e.what());
             }
           }),
           py::arg("model"), py::arg("phi"), py::arg("gain") = 50.0, py::arg("inertia_rate") = "difference")
      .def_property_readonly("nq", &MomentumObserver::nq)
      .def_property_readonly("gain", [](const MomentumObserver& o) { return o.gain(); })
      .def_property_readonly("residual", [](const MomentumObserver& o) { return o.residual(); })
      .def(
          "reset",
          [](MomentumObserver& o, py::handle q, py::handle qd, py::handle tau) {
            const Eigen::VectorXd a = vector_of(q, "q", o.nq()), b = vector_of(qd, "qd", o.nq()),
                                  c = vector_of(tau, "tau", o.nq());
            o.reset(a.data(), b.data(), c.data());
          },
          py::arg("q"), py::arg("qd"), py::arg("tau"), "start (again) at this sample: r = 0")
      .def(
          "update",
          [](MomentumObserver& o, py::handle q, py::handle qd, py::handle tau, double dt) {
            const Eigen::VectorXd a = vector_of(q, "q", o.nq()), b = vector_of(qd, "qd", o.nq()),
                                  c = vector_of(tau, "tau", o.nq());
            try {
              return Eigen::VectorXd(o.update(a.data(), b.data(), c.data(), dt));
            } catch (const std::invalid_argument& e) {
              throw py::value_error(e.what());
            }
          },
          py::arg("q"), py::arg("qd"), py::arg("tau"), py::arg("dt"), "the next sample, dt s later: r (nq,)")
      .def(
          "observe",
          [](MomentumObserver& o, py::handle time, py::handle q, py::handle qd, py::handle tau) {
            const int n = o.nq();
            io::Log log;
            log.q = matrix_of(q, "q", n);
            log.qd = matrix_of(qd, "qd", n);
            log.tau = matrix_of(tau, "tau", n);
            log.time = times_of(time, "time");
            if (log.qd.rows() != log.q.rows() || log.tau.rows() != log.q.rows() || log.time.size() != log.q.rows())
              throw py::value_error("observe: time (N,), q, qd and tau (N, nq) must have the same N");
            for (Eigen::Index k = 1; k < log.time.size(); ++k)
              if (!(log.time(k) > log.time(k - 1)))
                throw py::value_error("observe: time must increase (row " + std::to_string(k) + ")");
            Eigen::MatrixXd r;
            {
              py::gil_scoped_release release;
              r = observer::observe_log(o, log);
            }
            return r;
          },
          py::arg("time"), py::arg("q"), py::arg("qd"), py::arg("tau"),
          "r at every sample of a log, (N, nq): reset at the first, stepped by the time stamps; a row repeating the "
          "one before holds r");

  m.def(
      "observer_thresholds",
      [](const std::vector<py::object>& residuals, const std::vector<py::object>& times, py::handle gain,
         double false_alarms_per_hour, double peak_margin) {
        if (residuals.empty() || residuals.size() != times.size())
          throw py::value_error("observer_thresholds: as many residuals as times, at least one");
        const int n = columns_of(residuals.front(), "residuals[0]");
        std::vector<Eigen::MatrixXd> r;
        std::vector<Eigen::VectorXd> t;
        for (std::size_t i = 0; i < residuals.size(); ++i) {
          r.push_back(matrix_of(residuals[i], "residuals[i]", n));
          t.push_back(times_of(times[i], "times[" + std::to_string(i) + "]"));
        }
        observer::ThresholdOptions o;
        o.false_alarms_per_hour = false_alarms_per_hour;
        o.peak_margin = peak_margin;
        try {
          return thresholds_dict(observer::observer_thresholds(r, t, vector_of(gain, "gain", n), o));
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("residuals"), py::arg("times"), py::arg("gain"),
      py::arg("false_alarms_per_hour") = observer::ThresholdOptions{}.false_alarms_per_hour,
      py::arg("peak_margin") = observer::ThresholdOptions{}.peak_margin,
      "each joint's band from residuals without contact (lists of (N, nq) and (N,)): {'center', 'threshold', "
      "'spread', 'tail', 'peak', 'window', ...}");

  m.def(
      "collision_events",
      [](py::handle time, py::handle residual, const py::dict& thresholds, double merge_within) {
        const int n = columns_of(residual, "residual");
        const Eigen::MatrixXd r = matrix_of(residual, "residual", n);
        const Eigen::VectorXd t = times_of(time, "time");
        if (t.size() != r.rows()) throw py::value_error("collision_events: time and residual differ in length");
        py::list out;
        for (const auto& e : observer::collision_events(t, r, thresholds_from(thresholds, n), merge_within)) {
          py::dict d;
          d["joint"] = e.joint;
          d["start"] = e.start;
          d["end"] = e.end;
          d["peak"] = e.peak;
          d["peak_time"] = e.peak_time;
          out.append(d);
        }
        return out;
      },
      py::arg("time"), py::arg("residual"), py::arg("thresholds"), py::arg("merge_within") = observer::kMergeWithin,
      "where a joint's |r - center| exceeds its threshold: [{'joint' (0-based), 'start', 'end', 'peak', "
      "'peak_time'}], in order of start; a span within merge_within s of the last on its joint continues it");
}

}  // namespace symoro::python
