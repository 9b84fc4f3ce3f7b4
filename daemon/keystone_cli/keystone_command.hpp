#pragma once
// `procam-keystone solve`: argument parsing and the solve itself, kept apart from
// main() so tests call them directly.
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "keystone/keystone_solver.hpp"

namespace procam::keystone_cli {

struct SolveArgs {
  keystone::KeystoneProblem problem;
  bool json = false;
};

extern const char* const kUsage;

// argv without the program name and without "solve". kParse with a readable message.
Result<SolveArgs> parseSolveArgs(const std::vector<std::string>& args);

// {"homography": [...9], "corners": [[x, y] x 4], "scale": s}, or a text summary.
std::string formatSolution(const keystone::KeystoneSolution& s, bool json);

}  // namespace procam::keystone_cli
