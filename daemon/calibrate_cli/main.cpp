// procam-calibrate: structured-light patterns, decoding and projector-camera
// calibration from files. Usage and file formats: README.md beside this file.
#include <cstdio>
#include <cstring>
#include <string>

#include "commands.hpp"
#include "core/guarded_main.hpp"

namespace {

constexpr const char* kUsage = R"(usage: procam-calibrate COMMAND [options]

  patterns --projector WxH [--mode gray|gray+phase] [--step K]
           [--phase-steps N] [--phase-period P] [--gamma G] --out DIR
  decode   --patterns DIR --captures CAPDIR --out corr.pfm
  camera   --images DIR --board checker:COLSxROWS:SQUARE_M --out camera.json [--name NAME]
  stereo   --images DIR_A DIR_B --board SPEC --out cameras.json [--names A B]
  solve    --patterns DIR --captures CAPDIR CAPDIR2 --cameras cameras.json --out rig.json
           [--surface-out surface.ply] [--step K] [--name NAME]          (route a)
  solve    --cameras cameras.json --out rig.json [--step K]              (route a, several)
           --projector NAME --patterns DIR --captures CAPDIR CAPDIR2 [--projector ...]
  solve-planes --patterns DIR --captures CAPDIR1 CAPDIR2 [...] --cameras cameras.json
           [--camera NAME] [--plane-distance M] [--principal-x PX] --out rig.json (route b)
  solve-fiducials --fiducials points.json --projector WxH --out rig.json
           [--cameras cameras.json] [--name NAME]                          (route c)
  solve-wall --cameras cameras.json --plane A,B,C,D --out rig.json [--reference CAMERA]
           [--step K] --projector NAME --patterns DIR --captures CAPDIR|- [...]
           [--projector ...]                 (route b', cameras at several positions)

Boards: checker:COLSxROWS:SQUARE_M (inner corners), charuco:COLSxROWS:SQUARE_M:MARKER_M,
aprilgrid:COLSxROWS:TAG_M[:GAP_M]. See README.md for the file formats.
)";

}  // namespace

static int run(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "-h") || !std::strcmp(argv[1], "--help")) {
    std::fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  using Command = procam::Result<void> (*)(const procam::cli::Arguments&);
  const struct {
    const char* name;
    Command run;
  } commands[] = {{"patterns", procam::cli::runPatterns},
                  {"decode", procam::cli::runDecode},
                  {"camera", procam::cli::runCamera},
                  {"stereo", procam::cli::runStereo},
                  {"solve", procam::cli::runSolve},
                  {"solve-planes", procam::cli::runSolvePlanes},
                  {"solve-fiducials", procam::cli::runSolveFiducials},
                  {"solve-wall", procam::cli::runSolveWall}};
  for (const auto& c : commands) {
    if (std::strcmp(argv[1], c.name) != 0) continue;
    // solve and solve-wall take one --projector NAME --patterns DIR --captures ... group
    // per projector.
    auto args = std::strcmp(c.name, "solve") == 0 || std::strcmp(c.name, "solve-wall") == 0
                    ? procam::cli::Arguments::parseGrouped(argc, argv, 2, "projector",
                                                           {"patterns", "captures"})
                    : procam::cli::Arguments::parse(argc, argv, 2);
    if (!args) {
      std::fprintf(stderr, "procam-calibrate %s: %s\n%s", c.name, args.error().message.c_str(),
                   kUsage);
      return 2;
    }
    auto r = c.run(*args);
    if (!r && procam::cli::isCommandLineError(r.error())) {
      std::fprintf(stderr, "procam-calibrate %s: %s\n%s", c.name, r.error().message.c_str(),
                   kUsage);
      return 2;
    }
    if (!r) {
      std::fprintf(stderr, "procam-calibrate %s: error (%s): %s\n", c.name,
                   procam::toString(r.error().code), r.error().message.c_str());
      return 1;
    }
    return 0;
  }
  std::fprintf(stderr, "procam-calibrate: unknown command '%s'\n%s", argv[1], kUsage);
  return 2;
}

int main(int argc, char** argv) {
  return procam::guardedMain("procam-calibrate", [&] { return run(argc, argv); });
}
