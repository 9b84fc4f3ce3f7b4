#pragma once
// The wall seen by a camera fixed to the projector, from one projected frame of dots
// ([Raskar02] §6.2.2: the rigid camera gives the azimuth a tilt sensor cannot; §6.3 the
// self-correcting projector). The projector shows a sparse grid of small Gaussian dots,
// the camera's frames of it are averaged, the dots are found in the mean and each is
// identified by predicting it through the calibrated camera-from-projector pose (first at
// a nominal wall distance, then through the first plane fit); the identified pairs give
// the plane (wall_normal.hpp).
//
// The dots are small on purpose: an intensity centroid moves towards the brighter side by
// (the dot's second moment) x (gradient of ln illumination), and the 1/d^2 and cosine
// fall-off across the image turn that into a scale error that tilts the fitted wall
// (7 px dots at 1920 px: ~0.8 mrad; 3 px dots: ~0.1 mrad).
#include <opencv2/core/mat.hpp>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "keystone/wall_normal.hpp"

namespace procam::keystone {

struct DotGrid {
  cv::Mat image;              // CV_8UC1, the framebuffer to show
  std::vector<Vec2> centres;  // framebuffer pixels
  double sigma_px = 0;
};

// Dots 45 px apart with sigma 3 px on a 1920 px wide framebuffer, scaled with the
// width, the grid centred with an inset of at least 105 and 90 of those pixels on the
// sides and at the top and bottom, so that the dots stay inside a camera beside the
// lens at steep poses. kInvalidInput
// for a framebuffer under 64 x 64 or over 16384 on a side.
Result<DotGrid> makeDotGrid(int width, int height);

struct DotDetectOptions {
  // A dot is where the image rises above its median (the background) by `noise_sigmas`
  // times the background's noise (from its median absolute deviation: dots cover a few
  // per cent of the image), and by at least `min_rise` of the camera's full scale.
  double noise_sigmas = 6;
  double min_rise = 2.0 / 255.0;
  double full_scale = 255.0;
};

// Dot centres (camera pixels, as imaged) in `grey` (CV_32F, the mean of the frames):
// blobs above the background (3 pixels at least), each found by intensity moments over
// a 7 x 7 window less the median of its border, then refined to the Gaussian-weighted
// centroid (sigma 1.5 px, 9 x 9 window), whose noise and pixel-phase bias are several
// times smaller. Weights are not clipped at zero, so noise does not pull a centroid
// towards its window's centre.
std::vector<Vec2> detectDots(const cv::Mat& grey, const DotDetectOptions& options = {});

struct DotMatches {
  std::vector<Vec2> projector;  // framebuffer pixels
  std::vector<Vec2> camera;     // undistorted camera pixels
};

// Each projector dot predicted through the plane m.X = 1 (projector frame) into the
// camera (`camera_in_projector`: pose = camera from projector) and paired with the
// nearest detected dot within `gate` pixels.
DotMatches matchDots(const std::vector<Vec2>& centres, const std::vector<Vec2>& detected,
                     const geom::Intrinsics& projector,
                     const geom::CameraModel& camera_in_projector, const Vec3& m, double gate);

struct WallFromDots {
  WallPlane plane;
  std::size_t detected = 0;  // dots found in the camera's image
  std::size_t matched = 0;   // of them, identified and used in the fit
  std::size_t shown = 0;     // dots of the grid
};

struct WallFromDotsOptions {
  double nominal_distance = 3.0;  // m along the axis, for the first identification
  // Identification gates (camera pixels): under half the dots' spacing in the camera at
  // the nominal distance, then tight once the plane is known.
  double first_gate = 5.0, gate = 2.0;
  std::size_t min_matches = 20;
  DotDetectOptions detect;
};

// The wall plane (projector frame) from the mean camera image of `grid`: the dots
// identified at the nominal distance, the plane most of them agree with (RANSAC; dots on
// another surface, a floor, are left out), then identified again through that plane
// with the tight gate until their number settles, pairs off the plane by over 3 x the
// fit's RMS left out. kTooFewPoints when fewer than `min_matches` dots
// are identified; wallFromCorrespondences's errors.
Result<WallFromDots> wallFromDots(const DotGrid& grid, const cv::Mat& grey,
                                  const geom::Intrinsics& projector,
                                  const geom::CameraModel& camera_in_projector,
                                  const WallFromDotsOptions& options = {});

}  // namespace procam::keystone
