#include "reference.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <mutex>
#include <regex>
#include <set>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "symoro/grammar/parser.hpp"

namespace symoro::test {
namespace {

using grammar::Bindings;
using grammar::Expr;
using grammar::ModelFile;
using grammar::Table;

const Table& find_table(const std::vector<Table>& tables, const std::string& title, const std::string& path) {
  for (const auto& t : tables)
    if (t.title.find(title) != std::string::npos) return t;
  throw std::runtime_error(path + ": no table '" + title + "'");
}

int column_index(const Table& table, const std::string& name) {
  const auto it = std::find(table.columns.begin(), table.columns.end(), name);
  if (it == table.columns.end()) throw std::runtime_error("table '" + table.title + "' has no column '" + name + "'");
  return static_cast<int>(it - table.columns.begin());
}

const Expr& cell(const Table& table, const Table::Row& row, const std::string& column) {
  return row.cells.at(column_index(table, column));
}

void collect_symbols(const Expr& e, std::set<std::string>& out) {
  if (e.kind == Expr::Kind::Symbol) out.insert(e.name);
  for (const auto& a : e.args) collect_symbols(a, out);
}

// Constants of robot.yaml: `constants: {NAME: value}`, a value being a number in SI units or
// "<number> deg".
Bindings read_constants(const std::string& dir) {
  const std::string path = dir + "/robot.yaml";
  const YAML::Node node = YAML::LoadFile(path)["constants"];
  Bindings constants;
  if (!node) return constants;
  if (!node.IsMap()) throw std::runtime_error(path + ": `constants` is not a map");
  const std::regex degrees(R"(\s*(.*\S)\s*deg\s*)");
  for (const auto& entry : node) {
    std::string text = entry.second.as<std::string>();
    std::smatch m;
    const bool in_degrees = std::regex_match(text, m, degrees);
    if (in_degrees) text = m[1];
    const double v = grammar::evaluate(grammar::parse_expression(text, path), {});
    constants[entry.first.as<std::string>()] = in_degrees ? v * M_PI / 180.0 : v;
  }
  return constants;
}

// The variable of a joint cell ("th2", or "th2 + pi/2" for an offset): its one symbol that is
// not a constant.
std::string joint_variable(const Expr& e, const Bindings& constants) {
  std::set<std::string> symbols;
  collect_symbols(e, symbols);
  std::vector<std::string> free;
  for (const auto& s : symbols)
    if (s != "pi" && !constants.count(s)) free.push_back(s);
  if (free.size() != 1)
    throw std::runtime_error("a joint cell must hold exactly one variable (found " + std::to_string(free.size()) + ")");
  return free.front();
}

double get(const Bindings& values, const std::string& name) {
  const auto it = values.find(name);
  return it == values.end() ? 0.0 : it->second;
}

std::string index_name(const std::string& prefix, int a, int b) {
  return prefix + std::to_string(a) + std::to_string(b);
}

}  // namespace

Reference::Reference(const std::string& robot_dir) : dir_(robot_dir) {
  constants_ = read_constants(dir_);
  const auto read = [&](const char* name) { return grammar::read_model_file(dir_ + "/" + name); };
  dim_ = read("dim.txt");
  idm_ = read("idm.txt");
  inm_ = read("inm.txt");
  ccg_ = read("ccg.txt");
  ddm_ = read("ddm.txt");
  fgm_ = read("fgm.txt");
  jac_ = read("jac.txt");

  geometry_ = find_table(dim_.tables, "Geometric parameters", dim_.path);
  for (const auto& row : geometry_.rows) {
    const int sigma = static_cast<int>(grammar::evaluate(cell(geometry_, row, "sigma"), {}));
    if (sigma == 2) continue;  // a fixed frame has no joint variable
    const int frame = static_cast<int>(grammar::evaluate(cell(geometry_, row, "j"), {}));
    joints_.push_back({frame, joint_variable(cell(geometry_, row, sigma == 0 ? "theta" : "r"), constants_)});
  }

  const Table& inertia = find_table(dim_.tables, "Dynamic inertia parameters", dim_.path);
  const Table& joint = find_table(dim_.tables, "External forces and joint parameters", dim_.path);
  const auto add_symbols = [&](const Table& table, const std::vector<std::string>& columns) {
    for (const auto& row : table.rows)
      for (const auto& c : columns) {
        const Expr& e = cell(table, row, c);
        if (e.kind == Expr::Kind::Symbol) parameters_.push_back(e.name);
      }
  };
  add_symbols(inertia, {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M", "IA"});
  add_symbols(joint, {"FS", "FV"});
}

std::vector<std::string> Reference::regressor_columns() const {
  std::set<std::string> columns;
  const std::regex dg("DG[0-9]+([A-Za-z_].*)");
  std::smatch m;
  for (const auto& eq : dim_.equations)
    if (std::regex_match(eq.name, m, dg)) columns.insert(m[1]);
  return {columns.begin(), columns.end()};
}

Bindings Reference::inputs(const Eigen::VectorXd* q, const Eigen::VectorXd* qd, const Eigen::VectorXd* qdd,
                           const Eigen::VectorXd* tau, const ParameterValues* phi) const {
  Bindings b = constants_;
  for (int k = 0; k < nq(); ++k) {
    const std::string j = std::to_string(joints_[k].frame);
    if (q) b[joints_[k].variable] = (*q)(k);
    if (qd) b["QP" + j] = (*qd)(k);
    if (qdd) b["QDP" + j] = (*qdd)(k);
    if (tau) b["GAM" + j] = (*tau)(k);
  }
  if (phi) {
    for (const auto& p : parameters_) b[p] = 0.0;
    for (const auto& [name, value] : *phi) {
      if (std::find(parameters_.begin(), parameters_.end(), name) == parameters_.end())
        throw std::runtime_error(dir_ + ": '" + name + "' is not a parameter of the model files");
      b[name] = value;
    }
  }
  return b;
}

Eigen::MatrixXd Reference::regressor(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
                                     const std::vector<std::string>& columns) const {
  const Bindings v = grammar::run_equations(dim_.equations, inputs(&q, &qd, &qdd, nullptr, nullptr));
  Eigen::MatrixXd W(nq(), columns.size());
  for (int k = 0; k < nq(); ++k)
    for (std::size_t c = 0; c < columns.size(); ++c)
      W(k, c) = get(v, "DG" + std::to_string(joints_[k].frame) + columns[c]);
  return W;
}

namespace {
Eigen::VectorXd joint_outputs(const Bindings& v, const std::vector<JointSymbol>& joints, const std::string& prefix) {
  Eigen::VectorXd out(joints.size());
  for (std::size_t k = 0; k < joints.size(); ++k) {
    const std::string name = prefix + std::to_string(joints[k].frame);
    if (!v.count(name)) throw std::runtime_error("no equation for " + name);
    out(k) = v.at(name);
  }
  return out;
}
}  // namespace

Eigen::VectorXd Reference::inverse_dynamics(const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                            const Eigen::VectorXd& qdd, const ParameterValues& phi) const {
  return joint_outputs(grammar::run_equations(idm_.equations, inputs(&q, &qd, &qdd, nullptr, &phi)), joints_, "GAM");
}

Eigen::MatrixXd Reference::inertia(const Eigen::VectorXd& q, const ParameterValues& phi) const {
  const Bindings v = grammar::run_equations(inm_.equations, inputs(&q, nullptr, nullptr, nullptr, &phi));
  Eigen::MatrixXd M(nq(), nq());
  for (int i = 0; i < nq(); ++i)
    for (int j = 0; j <= i; ++j) M(i, j) = M(j, i) = get(v, index_name("A", joints_[i].frame, joints_[j].frame));
  return M;
}

Eigen::VectorXd Reference::nonlinear_effects(const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                             const ParameterValues& phi) const {
  return joint_outputs(grammar::run_equations(ccg_.equations, inputs(&q, &qd, nullptr, nullptr, &phi)), joints_, "GAM");
}

Eigen::VectorXd Reference::forward_dynamics(const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                            const Eigen::VectorXd& tau, const ParameterValues& phi) const {
  return joint_outputs(grammar::run_equations(ddm_.equations, inputs(&q, &qd, nullptr, &tau, &phi)), joints_, "QDP");
}

Eigen::Matrix4d Reference::forward_kinematics(const Eigen::VectorXd& q) const {
  const Bindings v = grammar::run_equations(fgm_.equations, inputs(&q, nullptr, nullptr, nullptr, nullptr));
  // T0T{f}{r}{c}: r and c are one digit each, so the greedy frame number takes the rest.
  const std::regex name("T0T([0-9]+)[1-4][1-4]");
  int last = -1;
  std::smatch m;
  for (const auto& eq : fgm_.equations)
    if (std::regex_match(eq.name, m, name)) last = std::max(last, std::stoi(m[1]));
  if (last < 0) throw std::runtime_error(fgm_.path + ": no T0T equation");
  Eigen::Matrix4d T = Eigen::Matrix4d::Zero();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      T(r, c) = get(v, "T0T" + std::to_string(last) + std::to_string(r + 1) + std::to_string(c + 1));
  T(3, 3) = 1.0;
  return T;
}

Eigen::MatrixXd Reference::jacobian(const Eigen::VectorXd& q) const {
  const Bindings v = grammar::run_equations(jac_.equations, inputs(&q, nullptr, nullptr, nullptr, nullptr));
  Eigen::MatrixXd J(6, nq());
  for (int r = 0; r < 6; ++r)
    for (int k = 0; k < nq(); ++k) J(r, k) = get(v, index_name("J", r + 1, joints_[k].frame));
  return J;
}

double Reference::constant_value(const Expr& e) const {
  Bindings b = constants_;
  for (const auto& j : joints_) b[j.variable] = 0.0;
  return grammar::evaluate(e, b);
}

const Reference& reference(const std::string& robot_dir) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<Reference>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[robot_dir];
  if (!slot) slot = std::make_unique<Reference>(robot_dir);
  return *slot;
}

std::string par_file_path(const std::string& robot_dir) {
  std::vector<std::string> found;
  for (const auto& entry : std::filesystem::directory_iterator(robot_dir)) {
    const std::string name = entry.path().filename().string();
    const auto ends_with = [&](const std::string& s) {
      return name.size() >= s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0;
    };
    if (ends_with(".par") && !ends_with("_base.par")) found.push_back(entry.path().string());
  }
  if (found.size() != 1)
    throw std::runtime_error(robot_dir + ": expected one robot .par file, found " + std::to_string(found.size()));
  return found.front();
}

}  // namespace symoro::test
