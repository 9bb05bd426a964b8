// The identification study (paper Algorithm 1 and Sec. VI) over a dataset: for every
// identification trajectory and sampling interval, OLS -> all-pose audit -> conditional SDP
// projection -> CLIE -> audit of the CLIE vector; then the PCA clouds, the representative by
// centrality, the post-CLIE rescue (eps = 0) when the representative is not PD, a final
// all-pose audit, and validation on the held-out trajectories. One run's chain is study/detail/run.hpp.
// StudyOptions::consistency physical also checks every run for a physically consistent set of
// link inertials, rescues onto such vectors and requires one for acceptance.
//
// A chain of stages: OLS / WLS, the audit and the SDP run for any robot with only its robots/
// folder. CLIE and closed-loop validation need the experiment's controller (a ClosedLoopSetup,
// from the robot's controller description) and each run's reference: the log's reference
// columns, else the trajectory design's trajectory of that name. Where either is missing CLIE
// is skipped (the run's record and StudyResult::stages say why), the representative is chosen
// among the SDP vectors and validation is open loop. A run that fails (a log too short for an
// interval, a solver's exception) is recorded with its reason and the study goes on.
//
// Runs go to a farm (symoro/parallel/farm.hpp: threads here, or MPI ranks under mpirun), one
// trajectory (its log read once, every interval) per task, longest first, each in a process of
// its own by default (StudyOptions::isolate). Each run's record is saved atomically under
// <out>/runs/ by the coordinator (rank 0) as soon as it arrives; a rerun, with any rank count,
// skips the runs whose saved fingerprint matches (same data, model and options).
#pragma once

#include <memory>
#include <stdexcept>
#include <optional>
#include <string>
#include <utility>

#include "symoro/identify/closed_loop.hpp"
// identification_model<Model>() of a generated model: link symoro::<robot>_identification.
#include "symoro/identify/identification_model.hpp"
#include "symoro/study/options.hpp"
#include "symoro/study/result.hpp"
#include "symoro/trajectory/design.hpp"

namespace symoro::study {

// What switches on the closed-loop stages: the experiment's controller (from the robot's
// controller description) and, optionally, the trajectory design (references for logs without
// reference columns). Without a controller, `why` says what is missing, for the report.
struct ClosedLoopSource {
  std::optional<identify::ClosedLoopSetup> setup;
  std::optional<trajectory::TrajectoryDesign> design;
  std::string why;  // e.g. "no controller description (robots/x/controller.yaml not found)"
};

// Study::run when StudyOptions::stop said so: the finished runs are saved; a rerun resumes.
struct StudyStopped : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A study without a model is a failure (after its records and report are written: `identify &&
// export` must not carry on as if there were parameters): std::runtime_error when no run
// succeeded or none was selected.
void require_identified(const StudyResult& result);

// The study of one model (any robot: its IdentificationModel; identification_model<Model>() for
// a generated one). Compiled once for every robot (study.cpp).
class Study {
 public:
  Study(std::shared_ptr<const identify::IdentificationModel> model, StudyOptions options, ClosedLoopSource closed_loop);
  Study(std::shared_ptr<const identify::IdentificationModel> model, StudyOptions options,
        trajectory::TrajectoryDesign design, identify::ClosedLoopSetup setup)
      : Study(std::move(model), std::move(options), ClosedLoopSource{std::move(setup), std::move(design), ""}) {}

  StudyResult run();

 private:
  std::shared_ptr<const identify::IdentificationModel> model_;
  StudyOptions o_;
  ClosedLoopSource loop_;
};

}  // namespace symoro::study
