#include "urdf_checks.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <tinyxml.h>

#include "symoro/codegen/modeling.hpp"
#include "symoro/codegen/robot_spec.hpp"

namespace symoro::codegen::modeling {

namespace {

// Magnitudes beyond any serial arm: a length in m, an angle in rad, a mass in kg, an inertia in
// kg m^2, a joint limit, effort or velocity.
constexpr double kLargestLength = 1e3;
constexpr double kLargestAngle = 1e3;
constexpr double kLargestMass = 1e6;
constexpr double kLargestInertia = 1e6;
constexpr double kLargestLimit = 1e9;

// A whole-text finite number, or the reason it is none.
std::string number_problem(const std::string& text, double& value) {
  const std::size_t b = text.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "is empty";
  const std::size_t e = text.find_last_not_of(" \t\r\n");
  const std::string t = text.substr(b, e - b + 1);
  char* end = nullptr;
  value = std::strtod(t.c_str(), &end);
  if (end != t.c_str() + t.size()) return "is not a number";
  if (!std::isfinite(value)) return "is not a finite number";
  return "";
}

class UrdfValueChecker {
 public:
  explicit UrdfValueChecker(std::string path) : path_(std::move(path)) {}

  void element(const TiXmlElement& el, const std::string& owner) {
    const std::string tag = el.Value();
    if (tag.rfind("xacro:", 0) == 0)
      fail(el,
           "<" + tag + "> is a xacro macro: expand the file with xacro first (xacro robot.urdf.xacro > robot.urdf)");
    for (const TiXmlAttribute* a = el.FirstAttribute(); a; a = a->Next()) {
      const std::string v = a->Value();
      if (v.find("${") != std::string::npos || v.find("$(") != std::string::npos)
        fail(el, "<" + tag + " " + a->Name() + "=\"" + v +
                     "\"> holds a xacro expression: expand the file with xacro first");
    }
    std::string inner = owner;
    if ((tag == "link" || tag == "joint") && el.Attribute("name"))
      inner = tag + " '" + std::string(el.Attribute("name")) + "'";
    if (tag == "mass") scalar(el, owner, "value", 0, kLargestMass, "kg");
    if (tag == "inertia")
      for (const char* k : {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"})
        scalar(el, owner, k, -kLargestInertia, kLargestInertia, "kg m^2", true);
    if (tag == "origin" && in_dynamics(el)) {
      vector3(el, owner, "xyz", kLargestLength, "m");
      vector3(el, owner, "rpy", kLargestAngle, "rad");
    }
    if (tag == "axis" && parent_is(el, "joint")) vector3(el, owner, "xyz", 1e3, "");
    if (tag == "limit" && parent_is(el, "joint")) limit(el, owner);
    for (const TiXmlElement* c = el.FirstChildElement(); c; c = c->NextSiblingElement()) element(*c, inner);
  }

 private:
  [[noreturn]] void fail(const TiXmlNode& at, const std::string& message) const {
    throw InputError(path_, at.Row(), at.Column(), message);
  }

  static bool parent_is(const TiXmlElement& el, const char* tag) {
    const TiXmlNode* p = el.Parent();
    return p && p->ToElement() && std::string(p->Value()) == tag;
  }
  // A joint's origin or an inertial's: what the model is made of (a visual's is not).
  static bool in_dynamics(const TiXmlElement& el) { return parent_is(el, "joint") || parent_is(el, "inertial"); }

  // The attribute `key` of `el`, a finite number within [lo, hi]; absent is fine unless `required`.
  bool scalar(const TiXmlElement& el, const std::string& owner, const char* key, double lo, double hi, const char* unit,
              bool required = false, double* out = nullptr) const {
    const char* text = el.Attribute(key);
    const std::string where = owner + ": <" + std::string(el.Value()) + " " + key + "=";
    if (!text) {
      if (required) fail(el, owner + ": <" + std::string(el.Value()) + "> has no " + key);
      return false;
    }
    double v = 0;
    if (const std::string why = number_problem(text, v); !why.empty()) fail(el, where + "\"" + text + "\"> " + why);
    if (v < lo || v > hi)
      fail(el, where + "\"" + text + "\"> is outside " + text_of(lo) + ".." + text_of(hi) +
                   (*unit ? std::string(" ") + unit : ""));
    if (out) *out = v;
    return true;
  }

  void vector3(const TiXmlElement& el, const std::string& owner, const char* key, double bound,
               const char* unit) const {
    const char* text = el.Attribute(key);
    if (!text) return;
    std::istringstream in(text);
    std::vector<std::string> parts;
    for (std::string p; in >> p;) parts.push_back(p);
    const std::string where = owner + ": <" + std::string(el.Value()) + " " + key + "=\"" + text + "\">";
    if (parts.size() != 3) fail(el, where + " needs three numbers");
    for (const auto& p : parts) {
      double v = 0;
      if (const std::string why = number_problem(p, v); !why.empty()) fail(el, where + ": '" + p + "' " + why);
      if (std::abs(v) > bound)
        fail(el, where + ": " + p + " is beyond +-" + text_of(bound) + (*unit ? std::string(" ") + unit : ""));
    }
  }

  void limit(const TiXmlElement& el, const std::string& owner) const {
    double lower = 0, upper = 0;
    const bool has_lower = scalar(el, owner, "lower", -kLargestLimit, kLargestLimit, "", false, &lower);
    const bool has_upper = scalar(el, owner, "upper", -kLargestLimit, kLargestLimit, "", false, &upper);
    scalar(el, owner, "effort", 0, kLargestLimit, "");
    scalar(el, owner, "velocity", 0, kLargestLimit, "");
    const TiXmlElement* joint = el.Parent()->ToElement();
    const char* type = joint ? joint->Attribute("type") : nullptr;
    const bool bounded = type && (std::string(type) == "revolute" || std::string(type) == "prismatic");
    if (bounded && has_lower && has_upper && lower > upper)
      fail(el, owner + ": <limit lower=\"" + el.Attribute("lower") + "\" upper=\"" + el.Attribute("upper") +
                   "\"> has its lower limit above its upper one");
  }

  static std::string text_of(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }

  std::string path_;
};

}  // namespace

void check_urdf_values(const TiXmlDocument& doc, const std::string& path) {
  UrdfValueChecker c(path);
  for (const TiXmlElement* el = doc.FirstChildElement(); el; el = el->NextSiblingElement()) c.element(*el, "the URDF");
}

}  // namespace symoro::codegen::modeling

namespace symoro::codegen {

void add_lock(ModelingOptions& options, const std::string& spec) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0) throw std::invalid_argument("--lock '" + spec + "': write joint=position");
  double q = 0;
  std::string why = modeling::number_problem(spec.substr(eq + 1), q);
  if (why.empty() && std::abs(q) > modeling::kLargestLength) why = "is beyond +-1000 (m or rad)";
  if (!why.empty())
    throw std::invalid_argument("--lock '" + spec + "': the position '" + spec.substr(eq + 1) + "' " + why);
  options.locked[spec.substr(0, eq)] = q;
}

}  // namespace symoro::codegen
