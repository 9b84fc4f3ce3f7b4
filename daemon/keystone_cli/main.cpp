// procam-keystone: keystone correction from the command line (see kUsage).
#include <cstdio>
#include <string>
#include <vector>

#include "core/guarded_main.hpp"
#include "keystone_command.hpp"

static int run(int argc, char** argv) {
  using namespace procam;
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" ||
      (args.size() >= 2 && args[0] == "solve" && (args[1] == "--help" || args[1] == "-h"))) {
    std::fputs(keystone_cli::kUsage, args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  if (args[0] != "solve") {
    std::fprintf(stderr, "procam-keystone: unknown command '%s'\n%s", args[0].c_str(),
                 keystone_cli::kUsage);
    return 2;
  }
  args.erase(args.begin());
  auto parsed = keystone_cli::parseSolveArgs(args);
  if (!parsed) {
    std::fprintf(stderr, "procam-keystone: %s\n", parsed.error().message.c_str());
    return 2;
  }
  auto solution = keystone::solveKeystone(parsed->problem);
  if (!solution) {
    std::fprintf(stderr, "procam-keystone: %s: %s\n", toString(solution.error().code),
                 solution.error().message.c_str());
    return 1;
  }
  std::fputs(keystone_cli::formatSolution(*solution, parsed->json).c_str(), stdout);
  return 0;
}

int main(int argc, char** argv) {
  return procam::guardedMain("procam-keystone", [&] { return run(argc, argv); });
}
