#pragma once
// The shipped scenes under the reference capture conditions of the accuracy tests:
// 8-bit captures, read noise 1 DN, no shot noise, linear response, projector gamma 2.2,
// exposure and ambient set for white ~75% of full scale and ambient 10% of white. Reduced
// resolutions (intrinsics scaled) keep the rendering to seconds. Empty text when
// the shipped scene no longer has the lines edited here.
#include <cmath>
#include <cstdio>
#include <string>

#include "rig_capture.hpp"

namespace procam::testing {

// corner_stereo, by default at half resolution: projector 640x400, cameras 512x384.
inline std::string issueCornerStereo(double projector_scale = 0.5, double camera_scale = 0.5) {
  std::string t = sceneText("corner_stereo");
  const bool ok = scaleDevice(t, 1280, 800, projector_scale) &&
                  scaleDevice(t, 1024, 768, camera_scale) &&  // left
                  scaleDevice(t, 1024, 768, camera_scale) &&  // right
                  edit(t, "bit_depth = 10", "bit_depth = 8") &&
                  edit(t, "read_noise_dn = 2.0", "read_noise_dn = 1.0") &&
                  edit(t, "full_well_e = 10000.0\n", "");
  return ok ? withIssueLighting(t, "cam_left", "0.02", "bit_depth = 8") : std::string();
}

// wall_oblique (projector 960x540, camera 320x240) plus a second camera "cam2"
// (route a needs a pair); `wall_yaw_deg` turns the wall about the vertical through
// its centre.
inline std::string issueWallOblique(double wall_yaw_deg) {
  std::string t = sceneText("wall_oblique");
  const double a = wall_yaw_deg * M_PI / 180;
  char normal[96];
  std::snprintf(normal, sizeof normal, "normal = [%.6f, %.6f, 0.0]\nsize = [8.0, 4.0]", std::sin(a),
                -std::cos(a));
  const bool ok = scaleDevice(t, 1920, 1080, 0.5) && scaleDevice(t, 1280, 960, 0.25) &&
                  edit(t, "exposure = 1.0\n", "") &&
                  edit(t, "read_noise_dn = 0.8", "read_noise_dn = 1.0") &&
                  edit(t, "full_well_e = 12000.0\n", "") &&
                  edit(t, "normal = [0.0, -1.0, 0.0]\nsize = [8.0, 4.0]", normal);
  if (!ok) return {};
  t += R"(
[[cameras]]
name = "cam2"
resolution = [320, 240]
intrinsics = { fx = 287.5, fy = 287.5, cx = 159.5, cy = 119.5 }
pose = { position = [0.6, 0.3, 1.2], look_at = [-0.3, 3.0, 1.5] }
bit_depth = 8
read_noise_dn = 1.0
supersamples = 4
)";
  return withIssueLighting(t, "cam", "0.02", "bit_depth = 8");
}

}  // namespace procam::testing
