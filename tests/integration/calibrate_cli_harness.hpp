#pragma once
// Runs the built procam-sim and procam-calibrate as a user would, on files in a
// temporary directory: patterns written by procam-calibrate are shown on the virtual
// rig (the first frame by `procam-sim render`, the rest by the same renderer in this
// process), and the captures go back into procam-calibrate.
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "daemon_harness.hpp"
#include "sim/scene_library.hpp"
#include "sim/still_camera.hpp"

namespace procam::testing {

namespace fs = std::filesystem;
using itest::RunResult;
using itest::TempDir;

inline RunResult calibrate(std::vector<std::string> args) {
  args.insert(args.begin(), PROCAM_CALIBRATE_BIN);
  return itest::runProgram(args);
}
inline RunResult simulate(std::vector<std::string> args) {
  args.insert(args.begin(), PROCAM_SIM_BIN);
  return itest::runProgram(args);
}

inline nlohmann::json readJsonFile(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in, nullptr, false);
}

inline void writeTextFile(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

// Shows every frame of DIR/sequence.json on projector `projector` and captures it
// with `camera` into `out` under the pattern's file name. The first frame is rendered
// by `procam-sim render`, as a user would; the camera then films the rest in this
// process from light paths traced once (sim/still_camera.hpp: the same images, without
// a ray cast per frame). Empty on success, else the failing command's output.
inline std::string renderCaptures(const std::string& scene, const fs::path& patterns,
                                  const std::string& projector, const std::string& camera,
                                  const fs::path& out, int seed) {
  fs::create_directories(out);
  const nlohmann::json seq = readJsonFile(patterns / "sequence.json");
  if (seq.is_discarded() || !seq.contains("frames") || seq["frames"].empty())
    return "no sequence.json in " + patterns.string();
  auto parsed = sim::resolveScene(scene);
  if (!parsed) return parsed.error().message;
  auto still = sim::StillCamera::create(*parsed, parsed->at(0), camera);
  if (!still) return still.error().message;
  int i = 0;
  for (const auto& f : seq["frames"]) {
    const std::string file = f.at("file").get<std::string>();
    const std::uint64_t frame_seed = static_cast<std::uint64_t>(seed) * 1000 + i++;
    if (i == 1) {
      auto r = simulate({"render", "--scene", scene, "--show",
                         projector + "=" + (patterns / file).string(), "--camera", camera, "--out",
                         (out / file).string(), "--seed", std::to_string(frame_seed)});
      if (r.status != 0) return file + ": " + r.err;
      continue;
    }
    const cv::Mat frame = cv::imread((patterns / file).string(), cv::IMREAD_UNCHANGED);
    if (frame.empty()) return "cannot read " + (patterns / file).string();
    auto image = still->capture({{projector, frame}}, {.noise = true, .seed = frame_seed});
    if (!image) return file + ": " + image.error().message;
    if (!cv::imwrite((out / file).string(), *image)) return "cannot write " + file;
  }
  return {};
}

// `procam-sim truth` of a scene.
inline nlohmann::json sceneTruth(const std::string& scene) {
  auto r = simulate({"truth", "--scene", scene, "--json"});
  if (r.status != 0) return nlohmann::json();
  return nlohmann::json::parse(r.out, nullptr, false);
}

// A device of procam-sim's truth in cameras.json / rig.json form (K, R row-major).
inline nlohmann::json deviceJson(const nlohmann::json& d) {
  nlohmann::json K = nlohmann::json::array(), R = nlohmann::json::array();
  for (const auto& row : d.at("K_matrix"))
    for (const auto& v : row) K.push_back(v);
  for (const auto& row : d.at("R"))
    for (const auto& v : row) R.push_back(v);
  nlohmann::json j = {{"name", d.at("name")},
                      {"width", d.at("resolution")[0]},
                      {"height", d.at("resolution")[1]},
                      {"K", K},
                      {"R", R},
                      {"t", d.at("t")}};
  if (d.contains("distortion")) {
    const auto& k = d["distortion"];
    j["dist"] = {k.at("k1"), k.at("k2"), k.at("p1"), k.at("p2"), k.at("k3")};
  }
  return j;
}

// The named cameras of a truth as cameras.json text.
inline std::string camerasJson(const nlohmann::json& truth, const std::vector<std::string>& names) {
  nlohmann::json cams = nlohmann::json::array();
  for (const auto& name : names)
    for (const auto& c : truth.at("cameras"))
      if (c.at("name") == name) cams.push_back(deviceJson(c));
  return nlohmann::json({{"cameras", cams}}).dump(2);
}

}  // namespace procam::testing
