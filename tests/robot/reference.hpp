// The reference a generated model is tested against: OpenSYMORO's own model files of a robot
// folder, parsed and run by the grammar's interpreter (symoro::grammar::run_equations), which
// shares no code with the compiler. Nothing here is specific to one robot: joint variables,
// parameter symbols and output names all come from the files and from robot.yaml.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/grammar/ast.hpp"
#include "symoro/grammar/evaluate.hpp"

namespace symoro::test {

// Base parameter values by OpenSYMORO name. A parameter symbol of the files that is not listed
// is 0; a listed name that is not a parameter symbol of the files is an error.
using ParameterValues = std::map<std::string, double>;

// One movable joint of the geometry table: its frame number j (the suffix of QP{j}, GAM{j}, ...)
// and the symbol of its variable (the theta cell of a revolute joint, the r cell of a prismatic).
struct JointSymbol {
  int frame;
  std::string variable;
};

class Reference {
 public:
  // Reads robot.yaml (constants) and the model files dim, idm, inm, ccg, ddm, fgm and jac of
  // `robot_dir`. Throws on a missing or malformed file.
  explicit Reference(const std::string& robot_dir);

  const std::string& dir() const { return dir_; }
  const grammar::Bindings& constants() const { return constants_; }
  const std::vector<JointSymbol>& joints() const { return joints_; }
  int nq() const { return static_cast<int>(joints_.size()); }
  // The base parameter symbols of the files: symbol cells of the "Dynamic inertia parameters"
  // table and of the FS and FV columns, in table order (as dim.txt lists them).
  const std::vector<std::string>& parameter_symbols() const { return parameters_; }
  // The parameters P with at least one DG{j}{P} equation in dim.txt, sorted.
  std::vector<std::string> regressor_columns() const;
  // The movable frames' geometry table of dim.txt (for checks of Model::frames).
  const grammar::Table& geometry() const { return geometry_; }

  // dim.txt: the regressor columns named by `columns` (DG{j}{P}; absent entries are 0).
  Eigen::MatrixXd regressor(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
                            const std::vector<std::string>& columns) const;
  // idm.txt: GAM{j}.
  Eigen::VectorXd inverse_dynamics(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
                                   const ParameterValues& phi) const;
  // inm.txt: A{i}{j} for i >= j, mirrored.
  Eigen::MatrixXd inertia(const Eigen::VectorXd& q, const ParameterValues& phi) const;
  // ccg.txt: GAM{j} with zero accelerations.
  Eigen::VectorXd nonlinear_effects(const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                    const ParameterValues& phi) const;
  // ddm.txt: QDP{j} from GAM{j}.
  Eigen::VectorXd forward_dynamics(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& tau,
                                   const ParameterValues& phi) const;
  // fgm.txt: T0T{f}{r}{c} of the highest frame f it computes; rows 1..3, last row 0 0 0 1.
  Eigen::Matrix4d forward_kinematics(const Eigen::VectorXd& q) const;
  // jac.txt: J{r}{c}, 6 x nq; columns it does not list are 0.
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& q) const;

  // The value of a .par or table cell with the constants of robot.yaml and the joint variables
  // at 0 (to compare the numeric geometry of a generated model with its files).
  double constant_value(const grammar::Expr& e) const;

 private:
  grammar::Bindings inputs(const Eigen::VectorXd* q, const Eigen::VectorXd* qd, const Eigen::VectorXd* qdd,
                           const Eigen::VectorXd* tau, const ParameterValues* phi) const;

  std::string dir_;
  grammar::Bindings constants_;
  grammar::Table geometry_;
  std::vector<JointSymbol> joints_;
  std::vector<std::string> parameters_;
  grammar::ModelFile dim_, idm_, inm_, ccg_, ddm_, fgm_, jac_;
};

// The parsed reference of a robot folder, read once per process.
const Reference& reference(const std::string& robot_dir);

// The robot description of a folder: its one `.par` file that is not `*_base.par`.
std::string par_file_path(const std::string& robot_dir);

}  // namespace symoro::test
