// procam-render: a rig's framebuffers drawn offline (see kUsage).
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
  const auto& size = (*done)["display"]["size_m"];
  std::printf("display: %.4f m x %.4f m (%s)%s%s\n", size[0].get<double>(), size[1].get<double>(),
              (*done)["display"]["rect_source"].get<std::string>().c_str(),
              parsed->out.empty() ? "" : ", ",
              parsed->out.empty() ? "" : (parsed->out / "display.json").c_str());
  if (!parsed->mpcdi.empty()) std::printf("MPCDI: %s\n", parsed->mpcdi.c_str());
  return 0;
}

int main(int argc, char** argv) {
  return procam::guardedMain("procam-render", [&] { return run(argc, argv); });
}
