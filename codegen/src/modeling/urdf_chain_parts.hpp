// The pieces of reading a URDF's serial chain (urdf_chain.hpp) that its two files share:
// urdf_chain.cpp reads, checks and places the chain; urdf_chain_text.cpp writes it as .par and
// robot.yaml text. Internal to the compiler.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <urdf_parser/urdf_parser.h>

#include "symoro/codegen/modeling.hpp"

namespace symoro::codegen::modeling::urdf_parts {

using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;

inline bool moving(const urdf::Joint& j) { return j.type != urdf::Joint::FIXED; }

// A name as a C++ identifier: other characters as '_', a leading digit prefixed.
std::string identifier(const std::string& s);

// One joint's modified DH parameters (Khalil-Kleinfinger, with gamma and b).
struct Dh {
  int sigma = 0;
  double gamma = 0, b = 0, alpha = 0, d = 0, theta = 0, r = 0;
};

// The URDF's text and urdfdom's model of it.
struct UrdfSource {
  std::string path, text;
  urdf::ModelInterfaceSharedPtr model;

  // The line of an element, for messages: the first `name="..."` after `<tag` (0: none).
  int line_of(const std::string& tag, const std::string& name) const {
    std::size_t at = 0;
    while ((at = text.find("<" + tag, at)) != std::string::npos) {
      const std::size_t end = text.find('>', at);
      const std::size_t n = text.find("name=\"" + name + "\"", at);
      if (n != std::string::npos && n < end)
        return static_cast<int>(std::count(text.begin(), text.begin() + at, '\n')) + 1;
      at += 1;
    }
    return 0;
  }
  urdf::LinkConstSharedPtr link(const std::string& name, const char* what) const {
    urdf::LinkConstSharedPtr l = model->getLink(name);
    if (!l) throw InputError(path, 0, 0, std::string(what) + " '" + name + "' is not a link of the URDF");
    return l;
  }
};

// The serial chain from the base link to the tip link: its moving joints, base to tip.
struct Chain {
  urdf::LinkConstSharedPtr base, tip;
  std::vector<urdf::JointConstSharedPtr> joints;
  std::set<std::string> names;  // the joints'
};

// Every link under the base at q = 0 (off-chain moving joints at their locked positions), and
// the chain link (body) each is rigidly part of.
struct LinkPlacement {
  std::map<std::string, Isometry3d> T;  // in base-link coordinates
  std::map<std::string, int> body;      // 0: the base
  std::vector<std::string> locked;      // "<joint> = <q>" of every off-chain moving joint
};

// The chain's modified DH parameters, and its frames 0..n at q = 0 in base-link coordinates,
// from the rounded parameters.
struct DhChain {
  std::vector<Dh> dh;
  std::vector<Isometry3d> F;  // frame 0 .. n
};

// A chain link's standard parameters: every URDF link's inertial merged into it, about the DH
// frame's origin, in the DH frame; the URDF links it merges.
struct Body {
  double m = 0;
  Vector3d ms = Vector3d::Zero();
  Matrix3d J = Matrix3d::Zero();
  std::vector<std::string> links;
};

// The chain as OpenSYMORO's .par: its MDH parameters, the standard parameters by name, gravity
// along -z of the URDF's base link.
std::string par_text(const std::string& name, const std::string& path, const Chain& chain, const DhChain& frames,
                     const ModelingOptions& options);

// robot.yaml: the joints' limits, the URDF's inertials as the nominal parameters, and where the
// model's frames and links are in the URDF. Warnings about the joints go into `notes`.
std::string robot_yaml_text(const std::string& name, const UrdfSource& src, const Chain& chain,
                            const LinkPlacement& placed, const DhChain& frames, const std::vector<Body>& bodies,
                            const ModelingOptions& options, std::vector<std::string>& notes);

}  // namespace symoro::codegen::modeling::urdf_parts
