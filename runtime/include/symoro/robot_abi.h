/* The robot library's C ABI: what a compiled robot (symoroc build robots/<name>) exports, and the
 * only thing the runtime, dynid and the Python module know of a robot they were not compiled with.
 *
 * A robot library is a shared object made from the robot's generated headers, instantiated in
 * double inside it (fixed-size Eigen), exporting two C functions:
 *   unsigned symoro_robot_abi_version(void);      SYMORO_ROBOT_ABI_VERSION of the library
 *   const symoro_abi_robot* symoro_robot(void);   its description and kernels, static storage
 * A loader reads the version first and refuses any other (symoro/robot/robot_library.hpp).
 *
 * Arrays are column-major; every output is caller-owned and fully written. Plain C: any host
 * (C, C++, Python's ctypes) can load it. Bump the version on any change to these structs. */
#ifndef SYMORO_ROBOT_ABI_H
#define SYMORO_ROBOT_ABI_H

#define SYMORO_ROBOT_ABI_VERSION 1u

#ifdef __cplusplus
extern "C" {
#endif

/* A base parameter: a column of the regressor and an entry of phi (symoro/model_info.hpp). */
typedef struct symoro_abi_parameter {
  const char* name;   /* OpenSYMORO name, e.g. "MYR2" */
  const char* family; /* XX XY XZ YY YZ ZZ MX MY MZ M IA FV FS; effects: OFF FST FVA HS HC FC */
  int joint;          /* 1-based */
  const char* unit;   /* e.g. "kg*m^2" */
} symoro_abi_parameter;

typedef struct symoro_abi_standard_parameter {
  const char* name;
  const char* family;
  int joint;
} symoro_abi_standard_parameter;

typedef struct symoro_abi_effect_parameter {
  const char* name;
  const char* family;
  int joint;
  int order;       /* HS, HC: the harmonic order; else 0 */
  double velocity; /* FST, FC: the velocity scale; else 0 */
} symoro_abi_effect_parameter;

typedef struct symoro_abi_fixed_parameter {
  const char* name;
  double value;
} symoro_abi_fixed_parameter;

typedef struct symoro_abi_joint {
  const char* name;
  int type; /* 0 revolute, 1 prismatic */
  double lower, upper, velocity, effort, audit_lower, audit_upper;
} symoro_abi_joint;

typedef struct symoro_abi_frame {
  int ant, sigma, mu;
  double gamma, b, alpha, d, theta, r;
} symoro_abi_frame;

typedef struct symoro_abi_source_file {
  const char* name;   /* a file of the robot folder the code was generated from */
  const char* digest; /* its XXH3-128 content digest, 32 hex digits */
} symoro_abi_source_file;

/* One model of the robot (the full model, or a robot.yaml variant). Sizes: q, qd, qdd, tau nq;
 * phi np; s (standard parameters) ns; the full model's phi parent_np. */
typedef struct symoro_abi_model {
  const char* variant; /* "" for the full model */
  const char* description;
  int nq, np, ns, nf, ne, n_fixed, parent_np;
  const symoro_abi_parameter* parameters;        /* np */
  const symoro_abi_standard_parameter* standard; /* ns */
  const symoro_abi_effect_parameter* effects;    /* ne: the last ne entries of phi and of s */
  const symoro_abi_fixed_parameter* fixed;       /* n_fixed */
  const int* parent_index;                       /* np: entry of the full model's phi, -1 for an effect */
  const symoro_abi_joint* joints;                /* nq */
  const symoro_abi_frame* frames;                /* nf */
  double gravity[3];                             /* in frame 0, m/s^2 */

  /* The generated functions, in double. */
  void (*regressor)(const double* q, const double* qd, const double* qdd, double* W /* nq x np */);
  void (*fixed_torque)(const double* q, const double* qd, const double* qdd, double* tau);
  void (*inverse_dynamics)(const double* q, const double* qd, const double* qdd, const double* phi, double* tau);
  void (*inertia)(const double* q, const double* phi, double* M /* nq x nq */);
  /* M(q; phi) = constant + sum_i phi_i linear_i: constant nq x nq, linear np blocks of nq x nq */
  void (*inertia_basis)(const double* q, double* constant, double* linear);
  void (*nonlinear_effects)(const double* q, const double* qd, const double* phi, double* h);
  void (*forward_dynamics)(const double* q, const double* qd, const double* tau, const double* phi, double* qdd);
  void (*inverse_dynamics_derivatives)(const double* q, const double* qd, const double* qdd, const double* phi,
                                       double* tau, double* dq, double* dqd /* nq x nq each */);
  /* Returns 1, or 0 when M is not positive definite (min_pivot then says by how much). dtau
   * nq x nq, dphi nq x np. */
  int (*forward_dynamics_derivatives)(const double* q, const double* qd, const double* tau, const double* phi,
                                      double* qdd, double* dq, double* dqd, double* dtau, double* dphi,
                                      double* min_pivot);
  /* M and dM/dq_k (nq blocks of nq x nq) */
  void (*inertia_derivatives)(const double* q, const double* phi, double* M, double* dM);
  /* M, dM/dq_k and d2M/dq_k dq_l (block k * nq + l), from the generated derivatives in Jets */
  void (*inertia_second_derivatives)(const double* q, const double* phi, double* M, double* dM, double* d2M);
  void (*forward_kinematics)(const double* q, double* T /* 4 x 4 */);
  void (*jacobian)(const double* q, double* J /* 6 x nq */);
  void (*base_from_standard)(const double* s, double* phi);
  void (*to_parent)(const double* phi, double* parent_phi);
  void (*from_parent)(const double* parent_phi, double* phi);
} symoro_abi_model;

typedef struct symoro_abi_robot {
  unsigned abi_version;    /* SYMORO_ROBOT_ABI_VERSION */
  const char* robot;       /* the folder's name, e.g. "crane_x7" */
  const char* identified;  /* the variant robot.yaml names `identified` ("" for the full model) */
  const char* code_digest; /* XXH3-128 of the generated code the library was compiled from */
  const char* build;       /* the compiler and flags it was compiled with */
  int n_models;
  const symoro_abi_model* models; /* the full model first, then every variant */
  int n_sources;
  const symoro_abi_source_file* sources;
} symoro_abi_robot;

typedef unsigned (*symoro_robot_abi_version_fn)(void);
typedef const symoro_abi_robot* (*symoro_robot_fn)(void);

#ifdef __cplusplus
}
#endif

#endif /* SYMORO_ROBOT_ABI_H */
