// procam-render: a rig's framebuffers drawn offline (see kUsage).
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/guarded_main.hpp"
#include "render_command.hpp"

static int run(int argc, char** argv) {
  using namespace procam;
  std::vector<std::string> args(argv + 1, argv + argc);
  for (const std::string& a : args) {
    if (a == "--help" || a == "-h") {
      std::fputs(render_cli::kUsage, stdout);
      return 0;
    }
  }
  auto parsed = render_cli::parseRenderArgs(args);
  if (!parsed) {
    std::fprintf(stderr, "procam-render: %s\n%s", parsed.error().message.c_str(),
                 render_cli::kUsage);
    return 2;
  }
  auto done = render_cli::runRender(*parsed);
  if (!done) {
    std::fprintf(stderr, "procam-render: %s: %s\n", toString(done.error().code),
                 done.error().message.c_str());
    return 1;
  }
  if (!parsed->out.empty()) {
    for (const auto& p : (*done)["projectors"]) {
      std::printf("%s: %s\n", p["name"].get<std::string>().c_str(),
                  (parsed->out / p["file"].get<std::string>()).c_str());
    }
  }
  const auto& display = (*done)["display"];
  const char* sep = parsed->out.empty() ? "" : ", ";
  const std::string json_file = parsed->out.empty() ? "" : (parsed->out / "display.json").string();
  if (display.value("surface", "") == "object") {
    const auto& c = display["coverage"];
    std::printf(
        "object: white %.6g (%s); lit %.4f m2, unlit %.4f m2 (projectors off), no "
        "projector reaches %.4f m2%s%s\n",
        display["white"].get<double>(), display["units"].get<std::string>().c_str(),
        c["lit_m2"].get<double>(), c["unlit_m2"].get<double>(), c["never_lit_m2"].get<double>(),
        sep, json_file.c_str());
  } else if (display.value("surface", "") == "mesh") {
    // A curved display: its field of view as the viewer sees it (the rectangle on the
    // eye's plane z = 1, possibly off its axis).
    const auto& rect = display["rect_tan"];
    const double cx = rect["centre"][0].get<double>(), cy = rect["centre"][1].get<double>();
    const double hw = 0.5 * rect["size"][0].get<double>(), hh = 0.5 * rect["size"][1].get<double>();
    const double to_deg = 180 / 3.141592653589793;
    std::printf("display: %.2f x %.2f deg seen from (%.3f, %.3f, %.3f)%s%s\n",
                to_deg * (std::atan(cx + hw) - std::atan(cx - hw)),
                to_deg * (std::atan(cy + hh) - std::atan(cy - hh)),
                display["viewer"]["position"][0].get<double>(),
                display["viewer"]["position"][1].get<double>(),
                display["viewer"]["position"][2].get<double>(), sep, json_file.c_str());
  } else {
    const auto& size = display["size_m"];
    std::printf("display: %.4f m x %.4f m (%s)%s%s\n", size[0].get<double>(), size[1].get<double>(),
                display["rect_source"].get<std::string>().c_str(), sep, json_file.c_str());
  }
  if (!parsed->mpcdi.empty()) std::printf("MPCDI: %s\n", parsed->mpcdi.c_str());
  return 0;
}

int main(int argc, char** argv) {
  return procam::guardedMain("procam-render", [&] { return run(argc, argv); });
}
