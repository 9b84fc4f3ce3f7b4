#pragma once
// The sub-commands of procam-calibrate (usage and formats: README.md).
#include <string>

#include "arguments.hpp"
#include "core/error.hpp"

namespace procam::cli {

Result<void> runPatterns(const Arguments& args);
Result<void> runDecode(const Arguments& args);
Result<void> runCamera(const Arguments& args);
Result<void> runStereo(const Arguments& args);
Result<void> runSolve(const Arguments& args);
Result<void> runSolvePlanes(const Arguments& args);
Result<void> runSolveFiducials(const Arguments& args);
Result<void> runSolveWall(const Arguments& args);

// One progress line on stderr.
void progress(const std::string& line);

}  // namespace procam::cli
