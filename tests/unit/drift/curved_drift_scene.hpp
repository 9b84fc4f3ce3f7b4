#pragma once
// cylinder3 (three 1280x800 projectors inside a cylinder of radius 3 m) with its two
// cameras at 1600x1200 instead of 800x600, as TOML text: a drift check registers content
// to a fraction of the camera's pixel, and cylinder3's 100 deg cameras give one camera
// pixel to about six projector pixels of the centre projector's frame, where the pose
// corrected from the content came within 0.4 to 0.7 px of the truth (measured; the
// corrected rig must be within 0.5 px). At 1600x1200 it is three and 0.06 to 0.10 px.
#include <fstream>
#include <sstream>
#include <string>

namespace procam::testing_support {

inline std::string cylinderWithDriftCameras() {
  const char* src = std::getenv("PROCAM_SOURCE_DIR");
  std::ifstream in(std::string(src ? src : ".") + "/tests/scenes/cylinder3.toml");
  std::stringstream text;
  text << in.rdbuf();
  std::string t = text.str();
  const std::string from = "resolution = [800, 600]", to = "resolution = [1600, 1200]";
  for (std::size_t at = t.find(from); at != std::string::npos; at = t.find(from, at + to.size())) {
    t.replace(at, from.size(), to);
  }
  return t;
}

}  // namespace procam::testing_support
