#include "symoro/twin/standard_parameters.hpp"

#include <random>

#include <fmt/format.h>

#include "symoro/effect_table.hpp"
#include "symoro/twin/kinematics.hpp"

namespace symoro::twin {

namespace {

// Model frame of each model joint (frames are 1-based; movable frames in order take q).
std::vector<int> frame_of_joint(const std::vector<FrameInfo>& frames) {
  std::vector<int> f;
  for (int j = 0; j < static_cast<int>(frames.size()); ++j)
    if (frames[j].sigma != 2) f.push_back(j);
  return f;
}

// The URDF link pose relative to the model's frame 0.
std::vector<Eigen::Isometry3d> urdf_in_model(const UrdfChain& chain, const Eigen::VectorXd& q) {
  auto T = urdf_poses(chain, q);
  const Eigen::Isometry3d inv = chain.base_in_urdf.inverse();
  for (auto& t : T) t = inv * t;
  return T;
}

}  // namespace

std::vector<LinkInertial> model_link_inertials(const UrdfChain& chain, const std::vector<FrameInfo>& frames,
                                               const std::string& file) {
  const std::vector<int> frame = frame_of_joint(frames);
  const int nq = static_cast<int>(frame.size());
  const int nu = static_cast<int>(chain.joints.size());
  for (const auto& j : chain.joints)
    if (!j.fixed && j.model_joint > nq)
      throw DataError(
          file, 0,
          fmt::format("urdf joint {} drives model joint {}, but the model has {} joints", j.name, j.model_joint, nq));

  // The model joint that carries each URDF link: the last movable URDF joint up to it.
  std::vector<int> carrier(nu, 0);
  for (int i = 0, c = 0; i < nu; ++i) {
    if (!chain.joints[i].fixed) c = chain.joints[i].model_joint;
    carrier[i] = c;
  }

  // X_i = (URDF link i in frame 0)^-1 (model frame of its carrier in frame 0), at q = 0.
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(nq);
  const auto U0 = urdf_in_model(chain, zero);
  const auto M0 = mdh_poses(frames, zero);
  std::vector<Eigen::Isometry3d> X(nu, Eigen::Isometry3d::Identity());
  for (int i = 0; i < nu; ++i)
    if (carrier[i] > 0) X[i] = U0[i].inverse() * M0[frame[carrier[i] - 1]];

  // The same mapping must hold at any pose, else the two chains describe different robots.
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> angle(-2.0, 2.0);
  for (int trial = 0; trial < 8; ++trial) {
    Eigen::VectorXd q(nq);
    for (int k = 0; k < nq; ++k) q(k) = angle(rng);
    const auto U = urdf_in_model(chain, q);
    const auto M = mdh_poses(frames, q);
    for (int i = 0; i < nu; ++i) {
      if (carrier[i] == 0) continue;
      const Eigen::Isometry3d Xi = U[i].inverse() * M[frame[carrier[i] - 1]];
      const double dr = (Xi.linear() - X[i].linear()).cwiseAbs().maxCoeff();
      const double dp = (Xi.translation() - X[i].translation()).norm();
      if (dr > 1e-9 || dp > 1e-9)
        throw DataError(
            file, 0,
            fmt::format(
                "the child link of urdf joint {} does not move with model frame {} (rotation differs by {:.3g}, "
                "position by {:.3g} m at some pose): check base_in_urdf, the joint axes and that joint angles have the "
                "same zero and direction in both descriptions",
                chain.joints[i].name, frame[carrier[i] - 1] + 1, dr, dp));
    }
  }

  std::vector<LinkInertial> links(frames.size());
  for (const UrdfInertial& b : chain.inertials) {
    int i = 0;
    while (chain.joints[i].name != b.on) ++i;
    if (carrier[i] == 0) continue;  // fixed to the base: it never moves
    LinkInertial& L = links[frame[carrier[i] - 1]];
    const Eigen::Isometry3d Xinv = X[i].inverse();
    const Eigen::Vector3d c = Xinv * (b.origin + b.com);                 // CoM in the model frame
    const Eigen::Matrix3d R = Xinv.linear() * rotation_from_rpy(b.rpy);  // inertia axes in it
    const Eigen::Matrix3d Ic = R * b.inertia * R.transpose();
    L.J += Ic + b.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
    L.ms += b.mass * c;
    L.m += b.mass;
  }
  return links;
}

void add_point_mass(LinkInertial& link, double mass, const Eigen::Vector3d& c) {
  link.J += mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  link.ms += mass * c;
  link.m += mass;
}

Eigen::VectorXd standard_vector(const std::vector<StandardParameterInfo>& names, const std::vector<LinkInertial>& links,
                                const Eigen::VectorXd& rotor_inertia, const Eigen::VectorXd& viscous,
                                const Eigen::VectorXd& coulomb, const std::string& file) {
  auto value = [&](const std::string& family, int j) -> double {  // j is 1-based
    if (family == "IA") return rotor_inertia(j - 1);
    if (family == "FV") return viscous(j - 1);
    if (family == "FS") return coulomb(j - 1);
    // A variant's model-gap effect parameters (robot.yaml `effects`): like Coulomb friction, the
    // twin applies its own effects, so they are 0 in the truth.
    if (variant_adds_family(family)) return 0.0;
    const LinkInertial& L = links.at(j - 1);
    if (family == "XX") return L.J(0, 0);
    if (family == "XY") return L.J(0, 1);
    if (family == "XZ") return L.J(0, 2);
    if (family == "YY") return L.J(1, 1);
    if (family == "YZ") return L.J(1, 2);
    if (family == "ZZ") return L.J(2, 2);
    if (family == "MX") return L.ms(0);
    if (family == "MY") return L.ms(1);
    if (family == "MZ") return L.ms(2);
    if (family == "M") return L.m;
    throw DataError(file, 0, "unknown standard parameter family " + family);
  };
  Eigen::VectorXd s(names.size());
  for (size_t k = 0; k < names.size(); ++k) s(k) = value(names[k].family, names[k].joint);

  // Anything the truth has that the model's standard parameters cannot hold is lost: refuse.
  auto present = [&](const std::string& family, int j) {
    for (const auto& n : names)
      if (n.family == family && n.joint == j) return true;
    return false;
  };
  const char* families[] = {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M", "IA", "FV", "FS"};
  const int joints = static_cast<int>(rotor_inertia.size());
  for (int j = 1; j <= static_cast<int>(links.size()); ++j)
    for (const char* f : families) {
      if (j > joints && (std::string(f) == "IA" || std::string(f) == "FV" || std::string(f) == "FS")) continue;
      const double v = value(f, j);
      if (v != 0 && !present(f, j))
        throw DataError(file, 0,
                        fmt::format("the twin has {}{} = {:.6g} but the model has no such parameter "
                                    "(it is 0 in the robot's .par): the model cannot represent this robot",
                                    f, j, v));
    }
  return s;
}

}  // namespace symoro::twin
