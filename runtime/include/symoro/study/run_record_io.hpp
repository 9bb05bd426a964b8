// One run's result on disk (<study>/runs/<TRAJ>@<ms>ms.yaml), written atomically when the run
// ends so that an interrupted study loses only the runs in flight; a rerun skips every run
// whose file carries the same input fingerprint (data, model and options).
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "symoro/study/result.hpp"

namespace symoro::study {

// The record as the file holds it (YAML, doubles to 17 digits: read back bit for bit), and back;
// the second throws std::runtime_error on a text that does not parse. Records travel this way
// from a run's process or rank to the one that saves them.
std::string run_record_text(const RunRecord& run, const std::string& fingerprint);
RunRecord run_record_from_text(const std::string& text);

void save_run(const RunRecord& run, const std::string& fingerprint, const std::filesystem::path& file);

// The record, or nothing when the file is missing, unreadable or made from other inputs.
std::optional<RunRecord> load_run(const std::filesystem::path& file, const std::string& fingerprint);

// A short stable hash (hex) of a text: input fingerprints.
std::string fingerprint_of(const std::string& text);

}  // namespace symoro::study
