#include "sim/renderer.hpp"

#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/background_rows.hpp"
#include "sim/camera_response.hpp"

namespace procam::sim {

namespace {

cv::Vec3f bgr(const Vec3& rgb) {
  return {static_cast<float>(rgb.z()), static_cast<float>(rgb.y()), static_cast<float>(rgb.x())};
}

// Mixes a name into a seed so that cameras get independent noise.
std::uint64_t mixSeed(std::uint64_t seed, std::string_view name) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a
  for (const char c : name) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  return seed ^ h;
}

}  // namespace

std::vector<Vec2> sampleOffsets(int supersamples) {
  const int n = std::max(1, static_cast<int>(std::lround(std::sqrt(supersamples))));
  std::vector<Vec2> offsets;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      // Stratum (i, j) of the n x n grid, sub-cell (j, n - 1 - i) of its own n x n
      // grid: every sample has its own column and row of the n^2 x n^2 grid.
      offsets.emplace_back((i + (j + 0.5) / n) / n - 0.5, (j + (n - 1 - i + 0.5) / n) / n - 0.5);
    }
  }
  return offsets;
}

void forEachRow(int rows, int threads, const std::function<void(int)>& body) {
  if (threads == 1) {
    for (int y = 0; y < rows; ++y) body(y);
    return;
  }
  if (backgroundRendering()) {
    forEachRowInBackground(rows, body);
    return;
  }
  cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& range) {
    for (int y = range.start; y < range.end; ++y) body(y);
  });
}

namespace {

// Inverse of the distortion by Newton's method started from `guess` (the previous
// sample's answer, a fraction of a pixel away, so one or two steps suffice); falls
// back to geom's robust solver when that does not converge.
std::optional<Vec2> undistortFrom(const geom::Distortion& d, const Vec2& distorted, Vec2 guess) {
  for (int it = 0; it < 8; ++it) {
    const Vec2 r = d.apply(guess) - distorted;
    if (r.squaredNorm() < 1e-26) return guess;
    const double x = guess.x(), y = guess.y(), r2 = x * x + y * y;
    const double radial = 1 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
    const double dradial = d.k1 + r2 * (2 * d.k2 + 3 * r2 * d.k3);  // d radial / d r2
    Eigen::Matrix2d J;
    J(0, 0) = radial + 2 * x * x * dradial + 2 * d.p1 * y + 6 * d.p2 * x;
    J(0, 1) = 2 * x * y * dradial + 2 * d.p1 * x + 2 * d.p2 * y;
    J(1, 0) = J(0, 1);
    J(1, 1) = radial + 2 * y * y * dradial + 6 * d.p1 * y + 2 * d.p2 * x;
    if (!(J.determinant() > 0)) break;  // outside the invertible region
    guess -= J.inverse() * r;
  }
  auto robust = d.remove(distorted);
  if (!robust) return std::nullopt;
  return *robust;
}

}  // namespace

std::optional<geom::Ray> pixelRay(const geom::CameraModel& view, double x, double y,
                                  Vec2* normalized) {
  const geom::Intrinsics& K = view.K;
  const double yn = (y - K.cy) / K.fy;
  Vec2 n((x - K.cx - K.skew * yn) / K.fx, yn);
  if (!view.dist.isZero()) {
    const bool warm = normalized && normalized->allFinite();
    const auto undistorted = undistortFrom(view.dist, n, warm ? *normalized : n);
    if (!undistorted) return std::nullopt;
    n = *undistorted;
  }
  if (normalized) *normalized = n;
  geom::Ray ray;
  ray.origin = view.pose.center();
  ray.dir = view.pose.R.transpose() * Vec3(n.x(), n.y(), 1.0).normalized();
  return ray;
}

Result<Renderer> Renderer::create(const Scene& scene, SceneState state, const Framebuffers& shown) {
  for (const auto& [name, image] : shown) {
    if (!state.projector(name))
      return fail(ErrorCode::kNotFound, "no projector named '" + name + "' in the scene");
  }
  Renderer r(scene, std::move(state));
  for (std::size_t i = 0; i < r.state_.projectors.size(); ++i) {
    const ProjectorState& p = r.state_.projectors[i];
    Lamp lamp;
    lamp.projector = i;
    lamp.P = p.model.projectionMatrix();
    lamp.center = p.model.pose.center();
    lamp.distorted = !p.model.dist.isZero();
    if (const auto it = shown.find(p.spec.name); it != shown.end()) {
      auto image = ProjectorImage::create(it->second, p.spec);
      if (!image) return tl::unexpected(image.error());
      lamp.image = std::move(*image);
    }
    r.lamps_.push_back(std::move(lamp));
  }
  for (const auto& s : scene.world().surfaces()) r.albedo_bgr_.push_back(bgr(s.albedo_rgb));
  r.ambient_bgr_ = bgr(scene.ambientRgb());
  return r;
}

PixelTruth::Light Renderer::light(const Lamp& lamp, const Vec3& point, const Vec3& normal,
                                  int surface) const {
  PixelTruth::Light out;
  const Vec3 h = lamp.P * point.homogeneous();
  if (!(h.z() > 0)) return out;
  out.in_front = true;
  const geom::CameraModel& m = state_.projectors[lamp.projector].model;
  if (lamp.distorted) {
    const auto pixel = m.project(point);
    if (!pixel) return out;
    out.pixel = *pixel;
  } else {
    out.pixel = h.head<2>() / h.z();
  }
  const Vec3 to_lamp = lamp.center - point;
  out.distance = to_lamp.norm();
  out.cos_incidence = normal.dot(to_lamp) / out.distance;
  const bool in_frame = out.pixel.x() >= -0.5 && out.pixel.x() < m.width - 0.5 &&
                        out.pixel.y() >= -0.5 && out.pixel.y() < m.height - 0.5;
  if (!in_frame || out.cos_incidence <= 0) return out;
  // Projector shadow: anything between the projector centre and the point.
  geom::Ray shadow;
  shadow.origin = lamp.center;
  shadow.dir = -to_lamp / out.distance;
  out.lit = !world().occluded(shadow, out.distance * (1.0 - 1e-7), surface);
  return out;
}

cv::Vec3f Renderer::reflectance(const SurfaceHit& hit) const {
  const auto surface = static_cast<std::size_t>(hit.surface);
  const cv::Vec3f albedo = albedo_bgr_[surface];
  const Surface& moved = world().surfaces()[surface];
  return moved.print ? albedo * moved.print->at(hit.hit.point - moved.offset) : albedo;
}

float Renderer::irradianceScale(const Lamp& lamp, const PixelTruth::Light& l) const {
  // Irradiance from a point source: I * cos(theta) / d^2 ([Raskar02] §5.2.4).
  return static_cast<float>(state_.projectors[lamp.projector].spec.brightness * l.cos_incidence /
                            (l.distance * l.distance));
}

cv::Vec3f Renderer::radianceAlong(const geom::Ray& ray) const {
  const auto hit = world().intersect(ray);
  if (!hit) return {0.f, 0.f, 0.f};
  cv::Vec3f irradiance = ambient_bgr_;
  for (const Lamp& lamp : lamps_) {
    if (!lamp.image) continue;
    const PixelTruth::Light l = light(lamp, hit->hit.point, hit->hit.normal, hit->surface);
    if (!l.lit) continue;
    irradiance += lamp.image->sample(l.pixel.x(), l.pixel.y()) * irradianceScale(lamp, l);
  }
  return irradiance.mul(reflectance(*hit));
}

void Renderer::rowRays(const geom::CameraModel& view, const std::vector<Vec2>& offsets, int y,
                       std::vector<std::optional<geom::Ray>>& rays) {
  rays.assign(static_cast<std::size_t>(view.width) * offsets.size(), std::nullopt);
  // Undistorted positions of each sample in the previous two pixels: their linear
  // extrapolation starts the inversion for this pixel (one Newton step suffices).
  const Vec2 none = Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
  std::vector<Vec2> last(offsets.size(), none), before(offsets.size(), none);
  std::size_t i = 0;
  for (int x = 0; x < view.width; ++x) {
    for (std::size_t k = 0; k < offsets.size(); ++k, ++i) {
      Vec2 n = before[k].allFinite() ? Vec2(2 * last[k] - before[k]) : last[k];
      rays[i] = pixelRay(view, x + offsets[k].x(), y + offsets[k].y(), &n);
      before[k] = last[k];
      last[k] = rays[i] ? n : none;
    }
  }
}

cv::Mat Renderer::radianceImage(const geom::CameraModel& view, int supersamples,
                                int threads) const {
  const std::vector<Vec2> offsets = sampleOffsets(supersamples);
  const float weight = 1.f / static_cast<float>(offsets.size());
  cv::Mat out(view.height, view.width, CV_32FC3);
  forEachRow(view.height, threads, [&](int y) {
    cv::Vec3f* row = out.ptr<cv::Vec3f>(y);
    std::vector<std::optional<geom::Ray>> rays;
    rowRays(view, offsets, y, rays);
    std::size_t i = 0;
    for (int x = 0; x < view.width; ++x) {
      cv::Vec3f sum(0.f, 0.f, 0.f);
      for (std::size_t k = 0; k < offsets.size(); ++k, ++i) {
        if (rays[i]) sum += radianceAlong(*rays[i]);
      }
      row[x] = sum * weight;
    }
  });
  return out;
}

Result<LightPaths> Renderer::cameraLightPaths(std::string_view camera, int threads) const {
  const CameraState* cam = state_.camera(camera);
  if (!cam) return fail(ErrorCode::kNotFound, "no camera named '" + std::string(camera) + "'");
  const geom::CameraModel& view = cam->model;
  const std::vector<Vec2> offsets = sampleOffsets(cam->spec.supersamples);
  const float weight = 1.f / static_cast<float>(offsets.size());
  LightPaths paths;
  paths.ambient = cv::Mat(view.height, view.width, CV_32FC3);
  paths.rows.resize(static_cast<std::size_t>(view.height));
  std::atomic<std::size_t> traced{0};
  forEachRow(view.height, threads, [&](int y) {
    if (traced.load() > LightPaths::kMaxPaths) return;
    LightPaths::Row& row = paths.rows[static_cast<std::size_t>(y)];
    row.end.reserve(static_cast<std::size_t>(view.width));
    cv::Vec3f* ambient = paths.ambient.ptr<cv::Vec3f>(y);
    std::vector<std::optional<geom::Ray>> rays;
    rowRays(view, offsets, y, rays);
    std::size_t i = 0;
    for (int x = 0; x < view.width; ++x) {
      ambient[x] = cv::Vec3f(0.f, 0.f, 0.f);
      for (std::size_t k = 0; k < offsets.size(); ++k, ++i) {
        if (!rays[i]) continue;
        const auto hit = world().intersect(*rays[i]);
        if (!hit) continue;
        const cv::Vec3f seen = reflectance(*hit) * weight;
        ambient[x] += ambient_bgr_.mul(seen);
        for (const Lamp& lamp : lamps_) {
          const PixelTruth::Light l = light(lamp, hit->hit.point, hit->hit.normal, hit->surface);
          if (!l.lit) continue;
          row.paths.push_back({static_cast<float>(l.pixel.x()), static_cast<float>(l.pixel.y()),
                               seen * irradianceScale(lamp, l),
                               static_cast<std::uint32_t>(lamp.projector)});
        }
      }
      row.end.push_back(static_cast<std::uint32_t>(row.paths.size()));
    }
    row.paths.shrink_to_fit();  // kMaxPaths bounds the memory kept, not only the count
    traced += row.paths.size();
  });
  if (traced.load() > LightPaths::kMaxPaths) {
    return fail(ErrorCode::kTooLarge, "camera '" + std::string(camera) + "' sees more than " +
                                          std::to_string(LightPaths::kMaxPaths) +
                                          " lit samples: too many light paths to keep");
  }
  return paths;
}

Result<cv::Mat> Renderer::cameraRadiance(std::string_view camera, int threads) const {
  const CameraState* cam = state_.camera(camera);
  if (!cam) return fail(ErrorCode::kNotFound, "no camera named '" + std::string(camera) + "'");
  return blurredByLens(cam->spec, radianceImage(cam->model, cam->spec.supersamples, threads));
}

Result<cv::Mat> Renderer::cameraRadiance(std::string_view camera, const LightPaths& paths,
                                         int threads) const {
  const CameraState* cam = state_.camera(camera);
  if (!cam) return fail(ErrorCode::kNotFound, "no camera named '" + std::string(camera) + "'");
  if (paths.ambient.rows != cam->model.height || paths.ambient.cols != cam->model.width)
    return fail(ErrorCode::kInvalidInput,
                "light paths traced for another camera than '" + std::string(camera) + "'");
  if (!paths.consistent())
    return fail(ErrorCode::kInvalidInput,
                "the light paths of camera '" + std::string(camera) + "' are malformed");
  std::vector<const ProjectorImage*> images(state_.projectors.size(), nullptr);
  for (const Lamp& lamp : lamps_) {
    if (lamp.image) images[lamp.projector] = &*lamp.image;
  }
  return blurredByLens(cam->spec, paths.light(images, threads));
}

cv::Mat Renderer::blurredByLens(const CameraSpec& camera, cv::Mat radiance) {
  if (camera.psf_sigma_px > 0) {
    // Lens point spread, applied to light (linear) before the sensor.
    cv::GaussianBlur(radiance, radiance, cv::Size(0, 0), camera.psf_sigma_px, camera.psf_sigma_px,
                     cv::BORDER_REPLICATE);
  }
  return radiance;
}

Result<cv::Mat> Renderer::renderCamera(std::string_view camera,
                                       const RenderOptions& options) const {
  const CameraState* cam = state_.camera(camera);
  if (!cam) return fail(ErrorCode::kNotFound, "no camera named '" + std::string(camera) + "'");
  auto radiance = cameraRadiance(camera, options.threads);
  if (!radiance) return tl::unexpected(radiance.error());
  return cameraImage(cam->spec, *radiance, options);
}

cv::Mat Renderer::cameraImage(const CameraSpec& camera, const cv::Mat& radiance,
                              const RenderOptions& options) {
  const CameraResponse response(camera, options.noise);
  cv::Mat out(radiance.rows, radiance.cols, response.outputType());
  const std::uint64_t seed = mixSeed(options.seed, camera.name);
  forEachRow(out.rows, options.threads,
             [&](int y) { response.convertRow(radiance.ptr<cv::Vec3f>(y), y, seed, out); });
  return out;
}

cv::Mat Renderer::renderView(const geom::CameraModel& view, int supersamples, int threads) const {
  return radianceImage(view, supersamples, threads);
}

PixelTruth Renderer::truthAt(const geom::CameraModel& view, const Vec2& pixel) const {
  PixelTruth truth;
  const auto ray = pixelRay(view, pixel.x(), pixel.y());
  if (!ray) return truth;
  const auto hit = world().intersect(*ray);
  if (!hit) return truth;
  truth.hit = true;
  truth.surface = hit->surface;
  truth.point = hit->hit.point;
  truth.normal = hit->hit.normal;
  for (const Lamp& lamp : lamps_)
    truth.projectors.push_back(light(lamp, truth.point, truth.normal, truth.surface));
  return truth;
}

Result<TruthMaps> Renderer::cameraTruth(std::string_view camera, int threads) const {
  const CameraState* cam = state_.camera(camera);
  if (!cam) return fail(ErrorCode::kNotFound, "no camera named '" + std::string(camera) + "'");
  const int w = cam->model.width, h = cam->model.height;
  TruthMaps maps;
  maps.point = cv::Mat(h, w, CV_64FC3, cv::Scalar::all(0));
  maps.surface = cv::Mat(h, w, CV_32S, cv::Scalar(-1));
  for (std::size_t i = 0; i < lamps_.size(); ++i) {
    maps.projector_pixel.emplace_back(h, w, CV_32FC2, cv::Scalar::all(0));
    maps.lit.emplace_back(h, w, CV_8U, cv::Scalar(0));
  }
  forEachRow(h, threads, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const PixelTruth t = truthAt(cam->model, Vec2(x, y));
      if (!t.hit) continue;
      maps.point.at<cv::Vec3d>(y, x) = cv::Vec3d(t.point.x(), t.point.y(), t.point.z());
      maps.surface.at<int>(y, x) = t.surface;
      for (std::size_t i = 0; i < t.projectors.size(); ++i) {
        const auto& l = t.projectors[i];
        if (l.in_front)
          maps.projector_pixel[i].at<cv::Vec2f>(y, x) =
              cv::Vec2f(static_cast<float>(l.pixel.x()), static_cast<float>(l.pixel.y()));
        if (l.lit) maps.lit[i].at<std::uint8_t>(y, x) = 255;
      }
    }
  });
  return maps;
}

}  // namespace procam::sim
