// What a recording says about its run (the "fahr_run" Metadata record):
// fahr and vendor versions, the recorder's vendor, host, start time, the
// scene's text when given, and the clock offset when chrony reports one.
#pragma once

#include <map>
#include <string>

#include "fahr/common/participant.h"

namespace fahr::logger_service {

std::map<std::string, std::string> run_metadata(const common::Participant& participant,
                                                const std::string& scene_path);

}  // namespace fahr::logger_service
