#pragma once
// What the drift check compares the camera's view with: the light of the frame an output
// shows, not its code values. The camera sees each channel through the projector's
// response (light ~ code^gamma) and adds them; a tile's fitted gain and offset
// (misregistration.hpp) take the camera's exposure and the ambient light, not a
// non-linear response, which moves a blurred edge towards its dark side. Pure.
#include <opencv2/core.hpp>

#include "core/error.hpp"
#include "projector_camera_map.hpp"

namespace procam::drift {

// `frame`: CV_8UC1 (grey) or CV_8UC4 (RGBA) of the grid's framebuffer size; the
// luminance of its light (BT.601 weights), 0..255 for full white, area-averaged onto the
// work grid (CV_32F). kInvalidInput for another type or size, or gamma outside [1, 4].
Result<cv::Mat> shownLight(const cv::Mat& frame, double gamma, const WorkGrid& grid);

}  // namespace procam::drift
