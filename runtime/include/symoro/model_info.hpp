// Plain descriptions of a generated robot model: its joints, parameters and geometry. Every
// generated model publishes these as constexpr arrays (see generated/<robot>/.../model.hpp).
#pragma once

namespace symoro {

enum class JointType { Revolute = 0, Prismatic = 1 };

struct JointInfo {
  const char* name;
  JointType type;
  double lower;  // position limits (rad or m)
  double upper;
  double velocity;     // |qd| limit (rad/s or m/s)
  double effort;       // |tau| limit (N m or N)
  double audit_lower;  // the all-pose PD audit domain for this joint (rad or m)
  double audit_upper;
};

// A base parameter: a column of the regressor and an entry of phi.
struct ParameterInfo {
  const char* name;    // OpenSYMORO name, e.g. "MYR2"
  const char* family;  // XX XY XZ YY YZ ZZ MX MY MZ M IA FV FS; effects: OFF FST FVA HS HC FC
  int joint;           // 1-based link or joint number
  const char* unit;    // e.g. "kg*m^2"
};

// A parameter a variant's model-gap effects add (robot.yaml `effects`, docs/generated-api.md):
// identified, after the base parameters (the last `ne` entries of phi and of the standard
// vector s, where it maps to itself). It adds phi * term to joint `joint`'s torque, the term by
// family: OFF 1, FST sign(qd) exp(-(qd / velocity)^2), FVA |qd|, HS sin(order q),
// HC cos(order q), FC tanh(qd / velocity).
struct EffectParameterInfo {
  const char* name;    // e.g. "FST2", "HS1_2"
  const char* family;  // OFF FST FVA HS HC FC
  int joint;           // 1-based
  int order;           // HS, HC: the harmonic order; else 0
  double velocity;     // FST: the Stribeck velocity, FC: the tanh scale (rad/s or m/s); else 0
};

// A standard (per-link, physical) parameter of the robot description (.par).
struct StandardParameterInfo {
  const char* name;  // e.g. "XX2"
  const char* family;
  int joint;
};

// A base parameter a variant fixes to a constant at generation time.
struct FixedParameter {
  const char* name;
  double value;
};

// One frame of the modified Denavit-Hartenberg (Khalil-Kleinfinger) description, numeric.
// The joint variable (theta for sigma = 0, r for sigma = 1) is added to `theta` or `r`.
struct FrameInfo {
  int ant;    // antecedent frame
  int sigma;  // 0 revolute, 1 prismatic, 2 fixed
  int mu;     // 1 actuated
  double gamma, b, alpha, d, theta, r;
};

}  // namespace symoro
