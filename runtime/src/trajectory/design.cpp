// TrajectoryDesign: the read design, and trajectories built from it on request.
#include "symoro/trajectory/design.hpp"

#include "design_data.hpp"
#include "symoro/error.hpp"

namespace symoro::trajectory {

TrajectoryDesign::TrajectoryDesign() = default;
TrajectoryDesign::~TrajectoryDesign() = default;
TrajectoryDesign::TrajectoryDesign(TrajectoryDesign&&) noexcept = default;
TrajectoryDesign& TrajectoryDesign::operator=(TrajectoryDesign&&) noexcept = default;

TrajectoryDesign TrajectoryDesign::read(const std::filesystem::path& yaml, const std::vector<JointInfo>& joints) {
  TrajectoryDesign design;
  design.d_ = std::make_unique<Design>(read_design(yaml, joints));
  return design;
}

std::vector<std::string> TrajectoryDesign::names() const {
  std::vector<std::string> out;
  for (const auto& t : d_->trajectories) out.push_back(t.name);
  return out;
}

Trajectory TrajectoryDesign::build(const std::string& name) const {
  for (const auto& spec : d_->trajectories) {
    if (spec.name != name) continue;
    Trajectory t = assemble(*d_, spec);
    check_limits(*d_, spec, t);
    return t;
  }
  throw DataError(d_->path.string(), 0, "no trajectory named '" + name + "' in the design");
}

std::vector<Trajectory> TrajectoryDesign::build_all() const {
  std::vector<Trajectory> out;
  for (const auto& spec : d_->trajectories) out.push_back(build(spec.name));
  return out;
}

const std::filesystem::path& TrajectoryDesign::path() const { return d_->path; }

}  // namespace symoro::trajectory
