#pragma once
// The object as one projector sees it: its render view ([Raskar02] §5.2.4, the
// projector's own K, R, t and lens). Per framebuffer pixel, the surface point its centre's
// ray meets first, with the shading normal there, the distance d(x) and cos θ_P of
// eq. 5.4, and the texture coordinate: the depth buffer and shading inputs that every
// frame reuses while the rig and the object stand still.
#include <opencv2/core.hpp>

#include "core/error.hpp"
#include "geometry/camera_model.hpp"
#include "shader_lamps/object_model.hpp"

namespace procam::lamps {

struct LampView {
  cv::Size size;
  cv::Mat face;      // CV_32SC1: the face met, -1 where the ray misses the object
  cv::Mat point;     // CV_32FC3: world point (metres)
  cv::Mat normal;    // CV_32FC3: unit shading normal, facing the projector
  cv::Mat distance;  // CV_32FC1: d(x), from the projector's centre (metres); 0 on a miss
  cv::Mat cosine;    // CV_32FC1: cos θ_P between the normal and the way to the projector
  cv::Mat texcoord;  // CV_32FC2: texture coordinate (zeros for an untextured model)

  bool hit(int x, int y) const { return face.at<int>(y, x) >= 0; }
};

// Up to 4096 x 4096 pixels (a view is 44 bytes a pixel).
constexpr long kMaxViewPixels = 4096L * 4096;

// kInvalidInput for a projector without a valid size (2..16384 per side) or intrinsics;
// kTooLarge over kMaxViewPixels.
Result<LampView> castLampView(const geom::CameraModel& projector, const ObjectModel& object);

}  // namespace procam::lamps
