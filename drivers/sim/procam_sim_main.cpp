// procam-sim: the virtual rig on the command line.
//   procam-sim render --scene S --show PROJ=IMAGE.png ... --camera NAME --out OUT.png
//                     [--time T] [--seed N] [--no-noise] [--threads N]
//   procam-sim truth --scene S [--json] [--time T]
//   procam-sim scenes
// Exit codes: 0 success, 1 failure while running, 2 bad command line.
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_json.hpp"
#include "sim/truth_rig.hpp"

namespace {

constexpr const char* kUsage = R"(usage:
  procam-sim render --scene S --show PROJ=IMAGE.png [--show ...] --camera NAME --out OUT.png
                    [--time T] [--seed N] [--no-noise] [--threads N]
      Render what camera NAME sees at time T (seconds, default 0) while each named
      projector shows its image (8/16-bit PNG, gray or colour, at the projector's
      resolution); projectors not listed are dark. Writes an 8-bit PNG for cameras of
      <= 8 bits, else 16-bit with codes 0..2^bits-1. --seed picks the noise,
      --no-noise turns it off, --threads 1 renders on one core (default: all).
  procam-sim truth --scene S [--json] [--time T] [--rig-json OUT]
      Print the true K, R, t (world -> device), distortion and resolution of every
      device, the tilt-sensor mounts, trackers, viewer and surfaces as JSON.
      --rig-json OUT writes the truth as a rig model (rig.json, version 2) for
      `procamd --rig OUT` instead: a known rig a test hands procamd explicitly.
  procam-sim scenes
      List the built-in scenes.
  procam-sim --help

S is a scene file path or the name of a built-in scene (see `procam-sim scenes`).
Exit status: 0 success, 1 failure while running, 2 bad command line.
)";

struct UsageError {
  std::string message;
};

struct Args {
  std::string command, scene, camera, out, rig_json;
  std::vector<std::pair<std::string, std::string>> shows;
  double time = 0;
  std::uint64_t seed = 1;
  int threads = 0;
  bool noise = true;
  bool json = false;
};

template <class T>
T parseNumber(std::string_view flag, std::string_view text) {
  T value{};
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || ptr != text.data() + text.size())
    throw UsageError{std::string(flag) + ": not a valid number: '" + std::string(text) + "'"};
  return value;
}

Args parseArgs(int argc, char** argv) {
  Args a;
  std::vector<std::string_view> rest(argv + 1, argv + argc);
  if (rest.empty()) throw UsageError{"missing command"};
  a.command = rest[0];
  for (std::size_t i = 1; i < rest.size(); ++i) {
    const std::string_view flag = rest[i];
    auto value = [&]() -> std::string_view {
      if (i + 1 >= rest.size()) throw UsageError{std::string(flag) + " needs a value"};
      return rest[++i];
    };
    if (flag == "--scene") {
      a.scene = value();
    } else if (flag == "--camera") {
      a.camera = value();
    } else if (flag == "--out") {
      a.out = value();
    } else if (flag == "--show") {
      const std::string_view v = value();
      const auto eq = v.find('=');
      if (eq == std::string_view::npos || eq == 0 || eq + 1 == v.size())
        throw UsageError{"--show wants PROJECTOR=IMAGE, got '" + std::string(v) + "'"};
      a.shows.emplace_back(std::string(v.substr(0, eq)), std::string(v.substr(eq + 1)));
    } else if (flag == "--time") {
      a.time = parseNumber<double>(flag, value());
    } else if (flag == "--seed") {
      a.seed = parseNumber<std::uint64_t>(flag, value());
    } else if (flag == "--threads") {
      a.threads = parseNumber<int>(flag, value());
      if (a.threads < 0) throw UsageError{"--threads must be >= 0"};
    } else if (flag == "--no-noise") {
      a.noise = false;
    } else if (flag == "--rig-json") {
      a.rig_json = value();
    } else if (flag == "--json") {
      a.json = true;
    } else {
      throw UsageError{"unknown option '" + std::string(flag) + "'"};
    }
  }
  return a;
}

int fail(const std::string& message) {
  std::cerr << "procam-sim: error: " << message << "\n";
  return 1;
}

int render(const Args& a) {
  if (a.scene.empty() || a.camera.empty() || a.out.empty())
    throw UsageError{"render needs --scene, --camera and --out"};
  auto scene = procam::sim::resolveScene(a.scene);
  if (!scene) return fail(scene.error().message);
  procam::sim::Framebuffers shown;
  for (const auto& [projector, file] : a.shows) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) return fail("no image file '" + file + "'");
    cv::Mat image = cv::imread(file, cv::IMREAD_UNCHANGED);
    if (image.empty()) return fail("cannot read image '" + file + "'");
    if (!shown.emplace(projector, image).second)
      throw UsageError{"projector '" + projector + "' is shown twice"};
  }
  auto renderer = procam::sim::Renderer::create(*scene, scene->at(a.time), shown);
  if (!renderer) return fail(renderer.error().message);
  procam::sim::RenderOptions options;
  options.noise = a.noise;
  options.seed = a.seed;
  options.threads = a.threads;
  auto image = renderer->renderCamera(a.camera, options);
  if (!image) return fail(image.error().message);
  try {
    if (!cv::imwrite(a.out, *image)) return fail("cannot write '" + a.out + "'");
  } catch (const cv::Exception& e) {
    return fail("cannot write '" + a.out + "': " + e.what());
  }
  return 0;
}

int truth(const Args& a) {
  if (a.scene.empty()) throw UsageError{"truth needs --scene"};
  if (!a.shows.empty() || !a.camera.empty() || !a.out.empty())
    throw UsageError{"truth takes only --scene, --json, --time and --rig-json"};
  auto scene = procam::sim::resolveScene(a.scene);
  if (!scene) return fail(scene.error().message);
  if (!a.rig_json.empty()) {
    auto rig = procam::sim::truthRig(*scene, a.time);
    if (!rig) return fail(rig.error().message);
    // Written whole to a temporary file and renamed: a reader never sees half a rig.
    const std::string tmp = a.rig_json + ".tmp";
    {
      std::ofstream f(tmp, std::ios::trunc);
      f << procam::rig::rigToJson(*rig).dump(2) << "\n";
      if (!f.flush()) return fail("cannot write '" + tmp + "'");
    }
    std::error_code ec;
    std::filesystem::rename(tmp, a.rig_json, ec);
    if (ec) return fail("cannot write '" + a.rig_json + "': " + ec.message());
    return 0;
  }
  std::cout << procam::sim::truthJson(*scene, scene->at(a.time)).dump(2) << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc == 2 && (std::string_view(argv[1]) == "--help" || std::string_view(argv[1]) == "-h" ||
                      std::string_view(argv[1]) == "help")) {
      std::cout << kUsage;
      return 0;
    }
    const Args args = parseArgs(argc, argv);
    if (args.command == "render") return render(args);
    if (args.command == "truth") return truth(args);
    if (args.command == "scenes") {
      for (const auto& name : procam::sim::builtinSceneNames()) std::cout << name << "\n";
      return 0;
    }
    throw UsageError{"unknown command '" + args.command + "'"};
  } catch (const UsageError& e) {
    std::cerr << "procam-sim: " << e.message << "\nTry 'procam-sim --help'.\n";
    return 2;
  } catch (const std::exception& e) {
    return fail(e.what());
  }
}
