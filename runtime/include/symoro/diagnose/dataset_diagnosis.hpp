// The diagnosis of a dataset (what dynid diagnose and symoro.diagnose run): which effects a
// model misses, on a dataset's fitting and held-out runs. It stacks the runs by parallel
// filtering, selects the missing effects stepwise, scores the gap against the raw torque,
// judges backlash on the robot's twin (when the robot folder has one and the log references),
// and writes the report and the robot.yaml variant that compiles the effects in. A stage that
// fails after the selection is said in the report; what the selection found stands.
#pragma once

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "symoro/diagnose/diagnosis.hpp"
#include "symoro/diagnose/diagnosis_model.hpp"
#include "symoro/io/dataset.hpp"

namespace symoro::diagnose {

struct DatasetDiagnosisOptions {
  std::filesystem::path data;               // the dataset folder (dataset.yaml and logs)
  std::filesystem::path out;                // the report folder
  std::filesystem::path robot_dir;          // twin.yaml, controller.yaml; empty: none (no backlash stage)
  std::vector<std::string> train, heldout;  // empty: the dataset's (held out: heldout_family)
  std::string heldout_family = io::kHeldOutFamily;
  int trial = 1;
  double interval = 0.01;         // s, the diagnosis grid
  double cutoff = 5;              // Hz, the low-pass on every column and the torque
  std::vector<std::string> only;  // effect names (effects.hpp); empty: every candidate
  // The selection's thresholds, with SelectionOptions' defaults (selection.hpp says what each is).
  double alpha = SelectionOptions{}.alpha;
  double min_heldout_gain = SelectionOptions{}.min_heldout_gain;
  double min_effect_torque = SelectionOptions{}.min_effect_torque;
  bool backlash = true;                         // the closed-loop high-band stage
  std::filesystem::path params;                 // an earlier identification's parameters, held (empty: refit)
  std::string variant;                          // the variant's name (empty: <model>_diagnosed, or diagnosed)
  std::function<void(const std::string&)> say;  // a line of progress, as each stage ends
  std::function<bool()> stop;                   // asked between stages: true stops (DiagnosisStopped)
};

// Options that cannot be met by this dataset (no fitting or held-out run, a run it lacks), or a
// variant that cannot be added: dynid's usage errors, Python's ValueError.
struct DiagnosisRequestError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// Stopped by DatasetDiagnosisOptions::stop: nothing of this diagnosis is written.
struct DiagnosisStopped : std::runtime_error {
  DiagnosisStopped() : std::runtime_error("the diagnosis was stopped") {}
};

struct DatasetDiagnosis {
  Diagnosis diagnosis;
  std::vector<std::filesystem::path> files;  // the report's
  std::filesystem::path report;              // <out>/diagnosis.md
  std::string variant_name, variant_yaml;    // the variant (empty yaml: no effect to compile)
  std::filesystem::path variant_file;        // <out>/variant.yaml, when written
};

// The options' own rules, before any work: the variant's name (symoroc's rule), the effects
// named in `only` (std::invalid_argument for an unknown one), a payload only against held
// parameters. diagnose_dataset checks them too.
void check_request(const DatasetDiagnosisOptions& options);

// The fitting and held-out runs of `o.trial`: as named, else the dataset's.
std::pair<std::vector<std::string>, std::vector<std::string>> diagnosis_runs(const io::Dataset& data,
                                                                             const DatasetDiagnosisOptions& options);

DatasetDiagnosis diagnose_dataset(const DiagnosisModel& model, const DatasetDiagnosisOptions& options);

// Adds a variant (variant_yaml's text) at the end of a robot.yaml's `variants:` section, which
// must be its last; the file is replaced atomically. DiagnosisRequestError when it cannot.
void add_variant_to_robot_yaml(const std::filesystem::path& robot_yaml, const std::string& name,
                               const std::string& variant_yaml);

}  // namespace symoro::diagnose
