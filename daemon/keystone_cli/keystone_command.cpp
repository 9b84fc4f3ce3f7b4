#include "keystone_command.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "core/units.hpp"
#include "keystone/orientation.hpp"

namespace procam::keystone_cli {

const char* const kUsage = R"(usage: procam-keystone solve --size WxH --intrinsics fx,fy,cx,cy
         (--pitch DEG --roll DEG [--yaw DEG] | [--down X,Y,Z] [--wall-normal X,Y,Z])
         [--aspect W:H | --content WxH] [--anchor centre|top] [--json]

Keystone correction of a projector aimed at a vertical wall: the content is shown in the
largest upright rectangle of its aspect ratio inside the projector's image on the wall.

  --size WxH            framebuffer size in pixels
  --intrinsics f,f,c,c  projector focal lengths and principal point, pixels (pixel centres
                        at integer coordinates, y down)
  --pitch --roll --yaw  orientation in degrees relative to the wall. Reference (all zero):
                        optical axis square to the wall, image upright. Applied in the
                        order yaw, pitch, roll about the projector's own axes:
                          yaw   > 0  turns the optical axis to the right (seen from above)
                          pitch > 0  tilts it up
                          roll  > 0  turns the image clockwise as seen from behind the
                                     projector
                        --yaw defaults to 0.
  --down X,Y,Z          direction of gravity in the projector frame (x right, y down,
                        z forward); alone: tilt sensor only, yaw assumed 0
  --wall-normal X,Y,Z   the wall's normal in the projector frame, either sign; alone:
                        camera only, roll assumed 0; with --down: fused (gravity gives
                        pitch and roll, the normal's horizontal part gives yaw)
  --aspect W:H          content aspect ratio; the content is the largest W:H pixel grid
                        inside the framebuffer (default: the framebuffer's own aspect)
  --content WxH         content size in pixels (instead of --aspect)
  --anchor centre|top   where the rectangle goes when several largest ones exist
  --json                print {"homography": [9 numbers, row-major, content pixels ->
                        framebuffer pixels], "corners": [[x, y] x 4], "scale": s};
                        corners are the framebuffer positions of the content's outer
                        corners (pixel edges) in the order top-left, top-right,
                        bottom-right, bottom-left; scale is the linear size of the
                        corrected image relative to the uncorrected one
)";

namespace {

Result<double> number(const std::string& text, const std::string& what) {
  double v = 0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (ec != std::errc() || ptr != end || !std::isfinite(v))
    return fail(ErrorCode::kParse, what + ": not a number: '" + text + "'");
  return v;
}

Result<std::vector<double>> numbers(const std::string& text, char sep, std::size_t count,
                                    const std::string& what) {
  std::vector<double> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t pos = text.find(sep, start);
    auto v = number(text.substr(start, pos == std::string::npos ? pos : pos - start), what);
    if (!v) return tl::unexpected(v.error());
    out.push_back(*v);
    if (pos == std::string::npos) break;
    start = pos + 1;
  }
  if (out.size() != count)
    return fail(ErrorCode::kParse, what + ": expected " + std::to_string(count) + " values");
  return out;
}

Result<std::pair<int, int>> size(const std::string& text, const std::string& what) {
  auto v = numbers(text, 'x', 2, what);
  if (!v) return tl::unexpected(v.error());
  const double w = (*v)[0], h = (*v)[1];
  if (w < 1 || h < 1 || w != std::floor(w) || h != std::floor(h) || w > 1e6 || h > 1e6)
    return fail(ErrorCode::kParse, what + ": expected positive integers WxH");
  return std::pair<int, int>(int(w), int(h));
}

}  // namespace

Result<SolveArgs> parseSolveArgs(const std::vector<std::string>& args) {
  SolveArgs out;
  std::optional<std::pair<int, int>> fb, content;
  std::optional<std::vector<double>> intrinsics, down, normal;
  std::optional<double> pitch, roll, yaw, aspect;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--json") {
      out.json = true;
      continue;
    }
    if (i + 1 >= args.size()) return fail(ErrorCode::kParse, a + ": missing value");
    const std::string& v = args[++i];
    Result<void> ok;
    auto take = [&](auto result, auto& slot) {
      if (!result)
        ok = tl::unexpected(result.error());
      else
        slot = *result;
    };
    if (a == "--size")
      take(size(v, a), fb);
    else if (a == "--content")
      take(size(v, a), content);
    else if (a == "--intrinsics")
      take(numbers(v, ',', 4, a), intrinsics);
    else if (a == "--down")
      take(numbers(v, ',', 3, a), down);
    else if (a == "--wall-normal")
      take(numbers(v, ',', 3, a), normal);
    else if (a == "--pitch")
      take(number(v, a), pitch);
    else if (a == "--roll")
      take(number(v, a), roll);
    else if (a == "--yaw")
      take(number(v, a), yaw);
    else if (a == "--aspect") {
      auto r =
          v.find(':') != std::string::npos ? numbers(v, ':', 2, a) : numbers(v + ":1", ':', 2, a);
      if (!r) return tl::unexpected(r.error());
      if ((*r)[0] <= 0 || (*r)[1] <= 0) return fail(ErrorCode::kParse, "--aspect must be > 0");
      aspect = (*r)[0] / (*r)[1];
    } else if (a == "--anchor") {
      if (v == "centre" || v == "center")
        out.problem.inscribe.anchor = keystone::Anchor::kCentre;
      else if (v == "top")
        out.problem.inscribe.anchor = keystone::Anchor::kTop;
      else
        return fail(ErrorCode::kParse, "--anchor: expected centre or top");
    } else {
      return fail(ErrorCode::kParse, "unknown option '" + a + "'");
    }
    if (!ok) return tl::unexpected(ok.error());
  }
  if (!fb || !intrinsics) return fail(ErrorCode::kParse, "--size and --intrinsics are required");
  const bool angles = pitch || roll || yaw;
  if (angles && (down || normal))
    return fail(ErrorCode::kParse, "give either angles or --down/--wall-normal, not both");
  if (!angles && !down && !normal)
    return fail(ErrorCode::kParse, "orientation missing: --pitch/--roll or --down/--wall-normal");
  if (angles && (!pitch || !roll))
    return fail(ErrorCode::kParse, "--pitch and --roll are required");
  if (aspect && content) return fail(ErrorCode::kParse, "give --aspect or --content, not both");

  auto& p = out.problem;
  p.width = fb->first;
  p.height = fb->second;
  p.K = {(*intrinsics)[0], (*intrinsics)[1], (*intrinsics)[2], (*intrinsics)[3], 0};
  if (content) {
    p.content_width = content->first;
    p.content_height = content->second;
  } else {
    const double a = aspect.value_or(double(p.width) / p.height);
    if (a >= double(p.width) / p.height) {
      p.content_width = p.width;
      p.content_height = std::max(1, int(std::lround(p.width / a)));
    } else {
      p.content_height = p.height;
      p.content_width = std::max(1, int(std::lround(p.height * a)));
    }
  }
  auto vec = [](const std::vector<double>& v) { return Vec3(v[0], v[1], v[2]); };
  Result<Mat3> R;
  if (angles) {
    R = keystone::rotationFromAngles(
        {degToRad(*pitch), degToRad(*roll), degToRad(yaw.value_or(0))});
  } else if (down && normal) {
    auto fused = keystone::fuseOrientation(vec(*down), vec(*normal));
    if (fused)
      R = fused->R;
    else
      R = tl::unexpected(fused.error());
  } else if (down) {
    R = keystone::rotationFromDown(vec(*down));
  } else {
    R = keystone::rotationFromWallNormal(vec(*normal));
  }
  if (!R) return tl::unexpected(R.error());
  p.R = *R;
  return out;
}

std::string formatSolution(const keystone::KeystoneSolution& s, bool json) {
  if (json) {
    nlohmann::ordered_json j;  // keys in the documented order
    j["homography"] = nlohmann::ordered_json::array();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) j["homography"].push_back(s.H(r, c));
    j["corners"] = nlohmann::ordered_json::array();
    for (const Vec2& c : s.corners) j["corners"].push_back({c.x(), c.y()});
    j["scale"] = s.scale;
    return j.dump() + "\n";
  }
  std::ostringstream out;
  out.precision(6);
  out << std::fixed << "homography (content -> framebuffer):\n";
  for (int r = 0; r < 3; ++r)
    out << "  " << s.H(r, 0) << " " << s.H(r, 1) << " " << s.H(r, 2) << "\n";
  const char* names[4] = {"top-left", "top-right", "bottom-right", "bottom-left"};
  for (int i = 0; i < 4; ++i)
    out << names[i] << ": " << s.corners[i].x() << ", " << s.corners[i].y() << "\n";
  out << "scale: " << s.scale << "\n";
  return out.str();
}

}  // namespace procam::keystone_cli
