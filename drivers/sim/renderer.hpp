#pragma once
// What the rig's cameras (and a viewer) see while the projectors show given
// framebuffers. Per camera pixel n*n stratified samples (sampleOffsets below):
// ray -> nearest surface -> every projector lighting that point with a clear line of
// sight -> its framebuffer (gamma, footprint, bilinear) -> albedo * (ambient +
// brightness * cos / d^2) -> the camera's signal chain (camera_response.hpp).
// Rows are rendered in parallel; results do not depend on the number of threads.
#include <cstdint>
#include <functional>
#include <map>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "sim/light_paths.hpp"
#include "sim/projector_image.hpp"
#include "sim/scene.hpp"

namespace procam::sim {

// Projector name -> framebuffer it shows. A projector without an entry is dark.
using Framebuffers = std::map<std::string, cv::Mat, std::less<>>;

struct RenderOptions {
  bool noise = true;
  std::uint64_t seed = 1;
  int threads = 0;  // 1: the calling thread only; otherwise all cores (forEachRow)
};

// What one camera pixel (its centre ray) sees.
struct PixelTruth {
  bool hit = false;
  int surface = -1;  // index into scene.world().surfaces()
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::Zero();  // facing the camera
  struct Light {
    bool in_front = false;      // point in front of the projector (pixel below is valid)
    bool lit = false;           // inside the frame, facing it, no shadow
    Vec2 pixel = Vec2::Zero();  // framebuffer coordinates of the point
    double cos_incidence = 0, distance = 0;
  };
  std::vector<Light> projectors;  // in SceneState::projectors order
};

// Per-pixel truth over a whole camera image (centre rays).
struct TruthMaps {
  cv::Mat point;                         // CV_64FC3 world point; zeros where nothing is hit
  cv::Mat surface;                       // CV_32S surface index, -1 where nothing is hit
  std::vector<cv::Mat> projector_pixel;  // per projector, CV_32FC2 framebuffer coordinates
  std::vector<cv::Mat> lit;              // per projector, CV_8U: 255 where lit
};

class Renderer {
 public:
  // The scene must outlive the renderer; `state` is usually scene.at(t).
  static Result<Renderer> create(const Scene& scene, SceneState state, const Framebuffers& shown);

  // Camera image: CV_8U (<= 8 bits) or CV_16U, 1 or 3 channels (BGR).
  Result<cv::Mat> renderCamera(std::string_view camera, const RenderOptions& options = {}) const;
  // Linear radiance the camera's pixels receive (mean over the supersamples, then
  // the lens blur), CV_32FC3, BGR.
  Result<cv::Mat> cameraRadiance(std::string_view camera, int threads = 0) const;
  // What the camera's samples see while nothing moves, whatever the projectors show
  // (light_paths.hpp): every projector of the scene, lit now or dark.
  Result<LightPaths> cameraLightPaths(std::string_view camera, int threads = 0) const;
  // cameraRadiance from `paths`, traced for this camera in the same geometry (poses,
  // surfaces, lenses): the same light, to float rounding, without a ray cast.
  Result<cv::Mat> cameraRadiance(std::string_view camera, const LightPaths& paths,
                                 int threads = 0) const;
  // The camera image of `radiance` (cameraRadiance's) through the camera's signal chain:
  // what renderCamera gives, for a caller that keeps the radiance of a still scene.
  static cv::Mat cameraImage(const CameraSpec& camera, const cv::Mat& radiance,
                             const RenderOptions& options = {});

  // Noise-free linear radiance (CV_32FC3, BGR) seen through any pinhole, e.g. the
  // viewer's eye: the image a person there perceives.
  cv::Mat renderView(const geom::CameraModel& view, int supersamples = 4, int threads = 0) const;
  cv::Mat renderViewer(int supersamples = 4, int threads = 0) const {
    return renderView(state_.viewer, supersamples, threads);
  }

  PixelTruth truthAt(const geom::CameraModel& view, const Vec2& pixel) const;
  Result<TruthMaps> cameraTruth(std::string_view camera, int threads = 0) const;

  // Radiance leaving along `ray` (BGR, linear); black when nothing is hit.
  cv::Vec3f radianceAlong(const geom::Ray& ray) const;

  const SceneState& state() const { return state_; }
  const Scene& scene() const { return *scene_; }

 private:
  struct Lamp {
    std::size_t projector = 0;  // index into state_.projectors
    std::optional<ProjectorImage> image;
    Mat34 P;  // K [R | t]
    Vec3 center;
    bool distorted = false;  // the lens bends the rays: project through the full model
  };

  Renderer(const Scene& scene, SceneState state) : scene_(&scene), state_(std::move(state)) {}
  PixelTruth::Light light(const Lamp& lamp, const Vec3& point, const Vec3& normal,
                          int surface) const;
  cv::Mat radianceImage(const geom::CameraModel& view, int supersamples, int threads) const;
  // The rays of row y's samples (width * offsets, pixel-major); nullopt where the
  // lens distortion cannot be inverted.
  static void rowRays(const geom::CameraModel& view, const std::vector<Vec2>& offsets, int y,
                      std::vector<std::optional<geom::Ray>>& rays);
  // The albedo (times the surface's print) where a ray hit.
  cv::Vec3f reflectance(const SurfaceHit& hit) const;
  // brightness * cos / d^2 of a lamp at a lit point.
  float irradianceScale(const Lamp& lamp, const PixelTruth::Light& l) const;
  // The lens point spread (CameraSpec::psf_sigma_px) over linear radiance.
  static cv::Mat blurredByLens(const CameraSpec& camera, cv::Mat radiance);

  // The surfaces as they stand at the state's time.
  const World& world() const { return state_.world ? *state_.world : scene_->world(); }
  const Scene* scene_;
  SceneState state_;
  std::vector<Lamp> lamps_;
  std::vector<cv::Vec3f> albedo_bgr_;
  cv::Vec3f ambient_bgr_;
};

// Pixel -> world ray through a (possibly distorted) pinhole; nullopt if the
// distortion cannot be inverted there. `normalized` (optional, in/out): in, a guess
// of the undistorted normalised point (ignored unless finite), e.g. extrapolated
// from neighbouring pixels; out, the undistorted normalised point.
std::optional<geom::Ray> pixelRay(const geom::CameraModel& view, double x, double y,
                                  Vec2* normalized = nullptr);

// Sample positions inside a pixel, relative to its centre, for n*n supersamples:
// stratified (one per cell of an n x n grid) and rotated-grid (no two samples share
// a row or column of the n^2 x n^2 sub-grid), symmetric under a half turn. For n = 2:
// (-3/8, -1/8), (1/8, -3/8), (-1/8, 3/8), (3/8, 1/8).
std::vector<Vec2> sampleOffsets(int supersamples);

// Runs body(row) for rows [0, rows): in the calling thread if threads == 1, else
// on OpenCV's thread pool, or on background threads when background rendering is on
// (background_rows.hpp).
void forEachRow(int rows, int threads, const std::function<void(int)>& body);

}  // namespace procam::sim
