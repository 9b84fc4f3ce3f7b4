// patterns and decode.
#include <cstdio>

#include "cli_files.hpp"
#include "commands.hpp"

namespace procam::cli {

void progress(const std::string& line) {
  std::fprintf(stderr, "procam-calibrate: %s\n", line.c_str());
}

Result<void> runPatterns(const Arguments& a) {
  if (auto ok =
          a.only({"projector", "mode", "step", "phase-steps", "phase-period", "gamma", "out"});
      !ok)
    return ok;
  auto size =
      a.one("projector").and_then([](const std::string& s) { return toSize(s, "--projector"); });
  if (!size) return tl::unexpected(size.error());
  auto out = a.one("out");
  if (!out) return tl::unexpected(out.error());
  sl::PatternOptions o;
  o.width = size->first;
  o.height = size->second;
  if (auto m = a.optional("mode")) {
    auto mode = sl::parseMode(*m);
    if (!mode) return tl::unexpected(mode.error());
    o.mode = *mode;
  }
  for (auto [name, field] : {std::pair{"step", &o.step}, std::pair{"phase-steps", &o.phase_steps},
                             std::pair{"phase-period", &o.phase_period}})
    if (auto v = a.optional(name)) {
      auto n = toInt(*v, std::string("--") + name);
      if (!n) return tl::unexpected(n.error());
      *field = *n;
    }
  if (auto g = a.optional("gamma")) {
    auto v = toDouble(*g, "--gamma");
    if (!v) return tl::unexpected(v.error());
    o.projector_gamma = *v;
  }
  auto set = sl::makePatternSet(o);
  if (!set) return tl::unexpected(set.error());
  progress("writing " + std::to_string(set->frames.size()) + " frames (" + sl::toString(o.mode) +
           ") to " + *out);
  return writePatterns(*set, *out);
}

Result<void> runDecode(const Arguments& a) {
  if (auto ok = a.only({"patterns", "captures", "out"}); !ok) return ok;
  auto patterns = a.one("patterns");
  auto captures = a.one("captures");
  auto out = a.one("out");
  for (const auto* r : {&patterns, &captures, &out})
    if (!*r) return tl::unexpected(r->error());
  auto set = readSequence(*patterns);
  if (!set) return tl::unexpected(set.error());
  progress("reading " + std::to_string(set->frames.size()) + " captures from " + *captures);
  auto frames = readCaptures(*set, *captures);
  if (!frames) return tl::unexpected(frames.error());
  auto decoded = sl::decode(*set, *frames);
  if (!decoded) return tl::unexpected(decoded.error());
  progress("decoded " + std::to_string(decoded->decoded) + " of " +
           std::to_string(decoded->u.total()) + " camera pixels");
  if (decoded->decoded == 0)
    return fail(ErrorCode::kTooFewPoints,
                "no camera pixel could be decoded (projector not visible, "
                "or captures in the wrong order?)");
  return writeCorrespondencePfm(*decoded, *out);
}

}  // namespace procam::cli
