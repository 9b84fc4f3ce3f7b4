#include "arguments.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace procam::cli {
namespace {

// Malformed command lines exit with 2 (main.cpp), every other error with 1.
tl::unexpected<Error> usage(const std::string& message) {
  return tl::unexpected(Error{ErrorCode::kInvalidInput, kCommandLine + message});
}

}  // namespace

bool isCommandLineError(const Error& e) {
  return e.message.rfind(kCommandLine, 0) == 0;
}

Result<Arguments> Arguments::parse(int argc, char** argv, int first) {
  Arguments a;
  std::string current;
  for (int i = first; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.rfind("--", 0) == 0 && word.size() > 2) {
      current = word.substr(2);
      if (a.values_.count(current)) return usage("option --" + current + " given twice");
      a.values_[current];
    } else if (current.empty()) {
      return usage("unexpected argument '" + word + "'");
    } else {
      a.values_[current].push_back(word);
    }
  }
  return a;
}

Result<Arguments> Arguments::parseGrouped(int argc, char** argv, int first,
                                          const std::string& starter,
                                          const std::vector<std::string>& members) {
  Arguments a;
  Arguments* into = &a;  // the group being filled, or the common options
  std::string current;
  for (int i = first; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.rfind("--", 0) == 0 && word.size() > 2) {
      current = word.substr(2);
      if (current == starter) {
        a.groups_.emplace_back();
        into = &a.groups_.back();
      } else if (std::find(members.begin(), members.end(), current) == members.end()) {
        into = &a;
      }
      if (into->values_.count(current)) {
        return usage("option --" + current + " given twice" +
                     (into == &a ? std::string() : " for one --" + starter));
      }
      into->values_[current];
    } else if (current.empty()) {
      return usage("unexpected argument '" + word + "'");
    } else {
      into->values_[current].push_back(word);
    }
  }
  return a;
}

Result<std::string> Arguments::one(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) return usage("missing --" + name);
  if (it->second.size() != 1) return usage("--" + name + " takes one value");
  return it->second[0];
}

std::optional<std::string> Arguments::optional(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end() || it->second.size() != 1) return std::nullopt;
  return it->second[0];
}

const std::vector<std::string>& Arguments::all(const std::string& name) const {
  static const std::vector<std::string> kNone;
  auto it = values_.find(name);
  return it == values_.end() ? kNone : it->second;
}

Result<void> Arguments::only(const std::vector<std::string>& known) const {
  for (const auto& [name, v] : values_) {
    bool ok = false;
    for (const auto& k : known) ok |= k == name;
    if (!ok) return usage("unknown option --" + name);
  }
  return {};
}

Result<int> toInt(const std::string& text, const std::string& what) {
  int v = 0;
  auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || p != text.data() + text.size())
    return usage(what + ": '" + text + "' is not an integer");
  return v;
}

Result<double> toDouble(const std::string& text, const std::string& what) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v))
    return usage(what + ": '" + text + "' is not a number");
  return v;
}

Result<std::pair<int, int>> toSize(const std::string& text, const std::string& what) {
  int w = 0, h = 0, n = 0;
  if (std::sscanf(text.c_str(), "%dx%d%n", &w, &h, &n) != 2 || n != static_cast<int>(text.size()) ||
      w < 1 || h < 1)
    return usage(what + ": expected WIDTHxHEIGHT, got '" + text + "'");
  if (w > 16384 || h > 16384) return usage(what + ": at most 16384 pixels a side");
  return std::pair{w, h};
}

bool isFileSafeName(const std::string& name) {
  return !name.empty() && name.size() <= 128 && name[0] != '.' &&
         name.find_first_not_of(
             "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789._-") ==
             std::string::npos;
}

Result<int> stepOption(const Arguments& a) {
  const auto s = a.optional("step");
  if (!s) return 8;
  auto v = toInt(*s, "--step");
  if (!v) return v;
  if (*v < 1 || *v > 1024)
    return fail(ErrorCode::kInvalidInput, kCommandLine + "--step takes 1 to 1024");
  return *v;
}

}  // namespace procam::cli
