#pragma once
// "--option value [value...]" command-line arguments of procam-calibrate.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace procam::cli {

class Arguments {
 public:
  // argv[first..argc): every "--name" takes the words up to the next "--name".
  static Result<Arguments> parse(int argc, char** argv, int first);
  // The same, with groups: "--<starter> NAME" opens a group that takes the options in
  // `members` following it (each once per group); any other option closes it. Each group
  // holds its starter's value under `starter` and its members.
  static Result<Arguments> parseGrouped(int argc, char** argv, int first,
                                        const std::string& starter,
                                        const std::vector<std::string>& members);
  const std::vector<Arguments>& groups() const { return groups_; }

  bool has(const std::string& name) const { return values_.count(name) > 0; }
  // Exactly one value; kInvalidInput names the option when missing.
  Result<std::string> one(const std::string& name) const;
  std::optional<std::string> optional(const std::string& name) const;
  const std::vector<std::string>& all(const std::string& name) const;
  // Fails on options not in `known`.
  Result<void> only(const std::vector<std::string>& known) const;

 private:
  std::map<std::string, std::vector<std::string>> values_;
  std::vector<Arguments> groups_;
};

// Errors of the helpers here start with this: a malformed command line (exit 2).
inline const std::string kCommandLine = "command line: ";
bool isCommandLineError(const Error& e);

Result<int> toInt(const std::string& text, const std::string& what);
// --step: projector pixels between grid nodes, 1 to 1024 (default 8).
Result<int> stepOption(const Arguments& a);
Result<double> toDouble(const std::string& text, const std::string& what);
// "WxH"
Result<std::pair<int, int>> toSize(const std::string& text, const std::string& what);

// A projector name that becomes part of a file name beside rig.json: 1-128 of
// A-Z a-z 0-9 . _ -, not starting with a dot.
bool isFileSafeName(const std::string& name);

}  // namespace procam::cli
