// The twin's truth in the model's own terms: CAD inertials (URDF link frames) mapped into the
// model's modified-DH link frames, then into the model's standard parameter vector (the order
// of Model::standard_parameters) and, through Model::base_from_standard, its base parameters.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/error.hpp"
#include "symoro/model_info.hpp"
#include "symoro/twin/config.hpp"

namespace symoro::twin {

// Inertial parameters of one model link, in its modified-DH frame: inertia tensor about the
// frame origin (XX XY XZ / XY YY YZ / XZ YZ ZZ), first moments (MX MY MZ) and mass.
struct LinkInertial {
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  Eigen::Vector3d ms = Eigen::Vector3d::Zero();
  double m = 0;
};

// Maps every inertial of the chain into the model frame of the model joint that carries it
// (the last movable URDF joint at or before its `on` joint). The URDF and model chains must
// describe the same motion: the constant transform between each URDF link and its model frame
// is taken at q = 0 and checked at random poses; a mismatch (wrong base_in_urdf, axis
// direction, offset) throws DataError naming the link. Returns one entry per model frame.
std::vector<LinkInertial> model_link_inertials(const UrdfChain& chain, const std::vector<FrameInfo>& frames,
                                               const std::string& file);

// Adds a point mass at `com` (in the link's model frame) to a link.
void add_point_mass(LinkInertial& link, double mass, const Eigen::Vector3d& com);

// Fills a standard parameter vector by name (XX2, MY4, IA3, FV1, FS8 ...). Entries the model
// does not have (zero in its .par) must be zero in the truth, else DataError: the model could
// not represent the twin. Drive values are per joint (size = joints). A variant's effect
// parameters (OFF, FST, FVA, HS, HC) are 0: the twin applies its own effects.
Eigen::VectorXd standard_vector(const std::vector<StandardParameterInfo>& names, const std::vector<LinkInertial>& links,
                                const Eigen::VectorXd& rotor_inertia, const Eigen::VectorXd& viscous,
                                const Eigen::VectorXd& coulomb, const std::string& file);

}  // namespace symoro::twin
