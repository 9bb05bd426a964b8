// dynid identify's options: the study on any model of any robot (--model), over its
// IdentificationModel.
#pragma once

#include <string>
#include <vector>

#include "dynid_common.hpp"
#include "symoro/study/request.hpp"

namespace symoro::dynid {

// The study's options are the library's request (symoro.identify takes the same), and the
// command's own.
struct IdentifyOptions : study::StudyRequest {
  std::string model;
  bool no_report = false;
};

void run_identify(const Common& common, const IdentifyOptions& options);

}  // namespace symoro::dynid
