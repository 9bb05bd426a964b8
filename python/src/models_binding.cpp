// symoro._symoro.Model: one robot model's functions on NumPy arrays (docs/python.md): a compiled
// one (model_list) or one of a robot library loaded at run time (load_models).
// A state is (nq,) or a batch (N, nq); results come back with the same leading N. Batches run
// with the GIL released; one state keeps it (releasing costs more than the call).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "symoro/robot/load_robot.hpp"

#include "arrays.hpp"
#include "model_kernels.hpp"

namespace symoro::python {

namespace {

struct Model {
  ModelKernels k;
  std::shared_ptr<const identify::IdentificationModel> id;
  std::shared_ptr<const diagnose::DiagnosisModel> diagnosis;
  std::filesystem::path folder;  // a loaded model's robot folder (symoro.load); empty for a compiled one
  const identify::ModelDescription& d() const { return id->description(); }
  std::string variant() const { return d().variant.empty() ? "full" : d().variant; }
};

// Runs f with the GIL released for a batch.
template <class F>
void run(bool batch, F&& f) {
  if (batch) {
    py::gil_scoped_release release;
    f();
  } else {
    f();
  }
}

py::array_t<double> doubles(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

// The arguments of a function of (q, qd, x) and phi, x being qdd or tau: each checked (in
// that order), their common batch, and phi's row stride.
struct StatePhiArgs {
  StateArg q, qd, x, phi;
  bool batch = false;
  std::ptrdiff_t n = 1, ps = 0;
};

StatePhiArgs state_phi_args(const Model& m, py::handle q, py::handle qd, py::handle x, const char* x_name,
                            py::handle phi) {
  StatePhiArgs a{state_arg(q, "q", m.k.nq), state_arg(qd, "qd", m.k.nq), state_arg(x, x_name, m.k.nq),
                 state_arg(phi, "phi", m.k.np)};
  a.n = common_batch({{"q", &a.q}, {"qd", &a.qd}, {x_name, &a.x}}, a.batch);
  a.ps = phi_stride(a.phi, "phi", a.n, a.batch);
  return a;
}

template <class Info, class Get>
std::vector<std::string> names(const std::vector<Info>& v, Get get) {
  std::vector<std::string> out;
  for (const Info& i : v) out.push_back(get(i));
  return out;
}

template <class Get>
py::array_t<double> joint_values(const Model& m, Get get) {
  std::vector<double> v;
  for (const JointInfo& j : m.d().joints) v.push_back(get(j));
  return doubles(v);
}

}  // namespace

void bind_models(py::module_& m) {
  py::class_<Model, std::shared_ptr<Model>> model(m, "Model", "A compiled robot model (symoro.models.<robot>.<model>)");
  model.def_property_readonly("robot", [](const Model& x) { return x.d().robot; })
      .def_property_readonly("name", &Model::variant, "the model's name: 'full' or a robot.yaml variant")
      .def_property_readonly(
          "folder",
          [](const Model& x) -> py::object {
            return x.folder.empty() ? py::object(py::none()) : py::str(x.folder.string());
          },
          "a loaded model's robot folder (symoro.load), the workflow's default robot_dir; None for a compiled one")
      .def_property_readonly(
          "nq", [](const Model& x) { return x.k.nq; }, "joints")
      .def_property_readonly(
          "np", [](const Model& x) { return x.k.np; }, "identified base parameters (phi's size)")
      .def_property_readonly(
          "ns", [](const Model& x) { return x.k.ns; }, "standard parameters (base_from_standard's input)")
      .def_property_readonly("parameter_names",
                             [](const Model& x) {
                               return names(x.d().parameters,
                                            [](const ParameterInfo& p) { return std::string(p.name); });
                             })
      .def_property_readonly("parameter_units",
                             [](const Model& x) {
                               return names(x.d().parameters,
                                            [](const ParameterInfo& p) { return std::string(p.unit); });
                             })
      .def_property_readonly("parameter_families",
                             [](const Model& x) {
                               return names(x.d().parameters,
                                            [](const ParameterInfo& p) { return std::string(p.family); });
                             })
      .def_property_readonly(
          "parameter_joints",
          [](const Model& x) {
            std::vector<int> v;
            for (const ParameterInfo& p : x.d().parameters) v.push_back(p.joint);
            return v;
          },
          "1-based joint (link) of each parameter")
      .def_property_readonly("standard_names",
                             [](const Model& x) {
                               return names(x.d().standard,
                                            [](const StandardParameterInfo& p) { return std::string(p.name); });
                             })
      .def_property_readonly(
          "joint_names",
          [](const Model& x) { return names(x.d().joints, [](const JointInfo& j) { return std::string(j.name); }); })
      .def_property_readonly("joint_types",
                             [](const Model& x) {
                               return names(x.d().joints, [](const JointInfo& j) {
                                 return std::string(j.type == JointType::Prismatic ? "prismatic" : "revolute");
                               });
                             })
      .def_property_readonly(
          "lower", [](const Model& x) { return joint_values(x, [](const JointInfo& j) { return j.lower; }); },
          "position limits (rad or m)")
      .def_property_readonly("upper",
                             [](const Model& x) { return joint_values(x, [](const JointInfo& j) { return j.upper; }); })
      .def_property_readonly(
          "velocity_limits",
          [](const Model& x) { return joint_values(x, [](const JointInfo& j) { return j.velocity; }); })
      .def_property_readonly(
          "effort_limits", [](const Model& x) { return joint_values(x, [](const JointInfo& j) { return j.effort; }); })
      .def_property_readonly(
          "gravity",
          [](const Model& x) {
            const auto& g = x.d().gravity;
            return doubles({g[0], g[1], g[2]});
          },
          "gravity acceleration in frame 0 (m/s^2)")
      .def("__repr__", [](const Model& x) {
        return fmt::format("<symoro model {}.{}: {} joints, {} base parameters>", x.d().robot, x.variant(), x.k.nq,
                           x.k.np);
      });

  model.def(
      "regressor",
      [](const Model& x, py::handle q, py::handle qd, py::handle qdd) {
        const StateArg a = state_arg(q, "q", x.k.nq), b = state_arg(qd, "qd", x.k.nq),
                       c = state_arg(qdd, "qdd", x.k.nq);
        bool batch = false;
        const std::ptrdiff_t n = common_batch({{"q", &a}, {"qd", &b}, {"qdd", &c}}, batch);
        auto w = output(batch, n, {x.k.nq, x.k.np});
        double* out = w.mutable_data();
        run(batch, [&] { x.k.regressor(a.data(), b.data(), c.data(), out, {n, 0}); });
        return w;
      },
      py::arg("q"), py::arg("qd"), py::arg("qdd"),
      "W(q, qd, qdd): (nq, np), or (N, nq, np) for a batch; tau = W @ phi");

  model.def(
      "inverse_dynamics",
      [](const Model& x, py::handle q, py::handle qd, py::handle qdd, py::handle phi) {
        const StatePhiArgs s = state_phi_args(x, q, qd, qdd, "qdd", phi);
        const bool batch = s.batch;
        const std::ptrdiff_t n = s.n, ps = s.ps;
        const StateArg &a = s.q, &b = s.qd, &c = s.x, &p = s.phi;
        auto tau = output(batch, n, {x.k.nq});
        double* out = tau.mutable_data();
        run(batch, [&] { x.k.inverse_dynamics(a.data(), b.data(), c.data(), p.data(), out, {n, ps}); });
        return tau;
      },
      py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("phi"), "tau = ID(q, qd, qdd; phi): (nq,) or (N, nq)");

  model.def(
      "inertia",
      [](const Model& x, py::handle q, py::handle phi) {
        const StateArg a = state_arg(q, "q", x.k.nq), p = state_arg(phi, "phi", x.k.np);
        const bool batch = a.batch;
        const std::ptrdiff_t ps = phi_stride(p, "phi", a.n, batch);
        auto mm = output(batch, a.n, {x.k.nq, x.k.nq});
        double* out = mm.mutable_data();
        run(batch, [&] { x.k.inertia(a.data(), p.data(), out, {a.n, ps}); });
        return mm;
      },
      py::arg("q"), py::arg("phi"), "M(q; phi): (nq, nq) or (N, nq, nq)");

  model.def(
      "nonlinear_effects",
      [](const Model& x, py::handle q, py::handle qd, py::handle phi) {
        const StateArg a = state_arg(q, "q", x.k.nq), b = state_arg(qd, "qd", x.k.nq),
                       p = state_arg(phi, "phi", x.k.np);
        bool batch = false;
        const std::ptrdiff_t n = common_batch({{"q", &a}, {"qd", &b}}, batch);
        const std::ptrdiff_t ps = phi_stride(p, "phi", n, batch);
        auto h = output(batch, n, {x.k.nq});
        double* out = h.mutable_data();
        run(batch, [&] { x.k.nonlinear_effects(a.data(), b.data(), p.data(), out, {n, ps}); });
        return h;
      },
      py::arg("q"), py::arg("qd"), py::arg("phi"),
      "h = ID(q, qd, 0; phi): Coriolis, centrifugal, gravity and friction");

  model.def(
      "forward_dynamics",
      [](const Model& x, py::handle q, py::handle qd, py::handle tau, py::handle phi) {
        const StatePhiArgs s = state_phi_args(x, q, qd, tau, "tau", phi);
        const bool batch = s.batch;
        const std::ptrdiff_t n = s.n, ps = s.ps;
        const StateArg &a = s.q, &b = s.qd, &c = s.x, &p = s.phi;
        auto qdd = output(batch, n, {x.k.nq});
        double* out = qdd.mutable_data();
        run(batch, [&] { x.k.forward_dynamics(a.data(), b.data(), c.data(), p.data(), out, {n, ps}); });
        return qdd;
      },
      py::arg("q"), py::arg("qd"), py::arg("tau"), py::arg("phi"), "qdd = M^-1 (tau - h): (nq,) or (N, nq)");

  model.def(
      "inverse_dynamics_derivatives",
      [](const Model& x, py::handle q, py::handle qd, py::handle qdd, py::handle phi) {
        const StatePhiArgs s = state_phi_args(x, q, qd, qdd, "qdd", phi);
        const bool batch = s.batch;
        const std::ptrdiff_t n = s.n, ps = s.ps;
        const StateArg &a = s.q, &b = s.qd, &c = s.x, &p = s.phi;
        auto tau = output(batch, n, {x.k.nq}), dq = output(batch, n, {x.k.nq, x.k.nq}),
             dqd = output(batch, n, {x.k.nq, x.k.nq});
        double *t = tau.mutable_data(), *o1 = dq.mutable_data(), *o2 = dqd.mutable_data();
        run(batch, [&] {
          x.k.inverse_dynamics_derivatives(a.data(), b.data(), c.data(), p.data(), t, o1, o2, {n, ps});
        });
        py::dict out;
        out["tau"] = tau;
        out["dq"] = dq;
        out["dqd"] = dqd;
        return out;
      },
      py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("phi"),
      "{'tau', 'dq': d tau / d q, 'dqd': d tau / d qd}; d tau / d qdd is inertia(q, phi), d tau / d phi the regressor");

  model.def(
      "forward_dynamics_derivatives",
      [](const Model& x, py::handle q, py::handle qd, py::handle tau, py::handle phi) {
        const StatePhiArgs s = state_phi_args(x, q, qd, tau, "tau", phi);
        const bool batch = s.batch;
        const std::ptrdiff_t n = s.n, ps = s.ps;
        const StateArg &a = s.q, &b = s.qd, &c = s.x, &p = s.phi;
        const int nq = x.k.nq;
        auto qdd = output(batch, n, {nq}), dq = output(batch, n, {nq, nq}), dqd = output(batch, n, {nq, nq}),
             dtau = output(batch, n, {nq, nq}), dphi = output(batch, n, {nq, x.k.np});
        py::array_t<double> pivot = batch ? py::array_t<double>(n) : py::array_t<double>(std::vector<py::ssize_t>{});
        double *o0 = qdd.mutable_data(), *o1 = dq.mutable_data(), *o2 = dqd.mutable_data(), *o3 = dtau.mutable_data(),
               *o4 = dphi.mutable_data(), *o5 = pivot.mutable_data();
        run(batch, [&] {
          x.k.forward_dynamics_derivatives(a.data(), b.data(), c.data(), p.data(), o0, o1, o2, o3, o4, o5, {n, ps});
        });
        py::dict out;
        out["qdd"] = qdd;
        out["dq"] = dq;
        out["dqd"] = dqd;
        out["dtau"] = dtau;
        out["dphi"] = dphi;
        out["min_pivot"] = batch ? py::object(pivot) : py::object(py::float_(o5[0]));
        return out;
      },
      py::arg("q"), py::arg("qd"), py::arg("tau"), py::arg("phi"),
      "{'qdd', 'dq', 'dqd', 'dtau', 'dphi', 'min_pivot'}: d qdd / d(q, qd, tau, phi) in one pass; NaN where M(q; phi) "
      "is not "
      "positive definite (min_pivot <= 0)");

  model.def(
      "forward_kinematics",
      [](const Model& x, py::handle q) {
        const StateArg a = state_arg(q, "q", x.k.nq);
        auto pose = output(a.batch, a.n, {4, 4});
        double* out = pose.mutable_data();
        run(a.batch, [&] { x.k.forward_kinematics(a.data(), out, {a.n, 0}); });
        return pose;
      },
      py::arg("q"), "the last arm frame in frame 0: (4, 4) homogeneous, or (N, 4, 4)");

  model.def(
      "jacobian",
      [](const Model& x, py::handle q) {
        const StateArg a = state_arg(q, "q", x.k.nq);
        auto j = output(a.batch, a.n, {6, x.k.nq});
        double* out = j.mutable_data();
        run(a.batch, [&] { x.k.jacobian(a.data(), out, {a.n, 0}); });
        return j;
      },
      py::arg("q"), "the last frame's Jacobian (6, nq), or (N, 6, nq), as the generated jacobian() gives it");

  model.def(
      "base_from_standard",
      [](const Model& x, py::handle s) {
        const StateArg a = state_arg(s, "s", x.k.ns);
        auto phi = output(a.batch, a.n, {x.k.np});
        double* out = phi.mutable_data();
        run(a.batch, [&] { x.k.base_from_standard(a.data(), out, {a.n, 0}); });
        return phi;
      },
      py::arg("s"), "the base parameters phi (np,) of standard parameters s (ns,) in standard_names' order");

  m.def(
      "load_models",
      [](const std::filesystem::path& folder, const std::optional<std::filesystem::path>& cache_dir) {
        robot::LoadOptions o;
        if (cache_dir) o.cache_dir = *cache_dir;
        std::shared_ptr<const robot::RobotLibrary> lib;
        {
          py::gil_scoped_release release;  // a first use compiles the library: seconds
          lib = robot::load_robot(folder, o);
        }
        std::vector<std::shared_ptr<Model>> out;
        for (int i = 0; i < lib->model_count(); ++i) {
          const ModelKernels k = loaded_kernels(lib->model(i), lib->model(0));
          out.push_back(
              std::make_shared<Model>(Model{k, k.identification(), k.diagnosis(), std::filesystem::absolute(folder)}));
        }
        return py::make_tuple(lib->robot(), lib->model("").label(), out);
      },
      py::arg("folder"), py::arg("cache_dir") = py::none(),
      "a robot folder's models through its robot library, built on first use: (robot, identified model, models)");

  m.def(
      "model_list",
      [] {
        std::vector<std::shared_ptr<Model>> out;
        for (const ModelKernels& k : all_model_kernels())
          out.push_back(std::make_shared<Model>(Model{k, k.identification(), k.diagnosis()}));
        return out;
      },
      "every compiled robot model, the full model of each robot first");
}

// The identification interface of a Model (for the workflow's functions).
std::shared_ptr<const identify::IdentificationModel> identification_of(py::handle model) {
  return model.cast<const Model&>().id;
}

// Its robot handle (symoro.MomentumObserver).
const robot::ModelHandle& handle_of(py::handle model) { return *model.cast<const Model&>().k.handle; }

// robot_dir as given, else a loaded model's own folder: the workflow then reads its robot.yaml
// (the nominal prior, the controller description) as dynid does from --robot.
std::optional<std::filesystem::path> robot_dir_of(py::handle model, const std::optional<std::filesystem::path>& given) {
  if (given) return given;
  const Model& m = model.cast<const Model&>();
  if (m.folder.empty()) return std::nullopt;
  return m.folder;
}

// Its diagnosis interface (symoro.diagnose).
std::shared_ptr<const diagnose::DiagnosisModel> diagnosis_of(py::handle model) {
  return model.cast<const Model&>().diagnosis;
}

}  // namespace symoro::python
