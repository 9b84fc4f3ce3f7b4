#include "shader_lamps/lamp_view.hpp"

#include <opencv2/core/utility.hpp>
#include <string>

namespace procam::lamps {

Result<LampView> castLampView(const geom::CameraModel& projector, const ObjectModel& object) {
  const int w = projector.width, h = projector.height;
  if (w < 2 || h < 2 || w > 16384 || h > 16384)
    return fail(ErrorCode::kInvalidInput, "projector size out of range");
  // 44 bytes a pixel here, about as much again for its weights and frame.
  if (static_cast<long>(w) * h > kMaxViewPixels)
    return fail(ErrorCode::kTooLarge, "projector of " + std::to_string(w) + "x" +
                                          std::to_string(h) + " pixels: over " +
                                          std::to_string(kMaxViewPixels) + " for shader lamps");
  if (!(projector.K.fx > 0 && projector.K.fy > 0) || !projector.pose.R.allFinite() ||
      !projector.pose.t.allFinite())
    return fail(ErrorCode::kInvalidInput, "projector intrinsics or pose are not valid");
  LampView v;
  v.size = cv::Size(w, h);
  v.face = cv::Mat(h, w, CV_32SC1, cv::Scalar(-1));
  v.point = cv::Mat(h, w, CV_32FC3, cv::Scalar::all(0));
  v.normal = cv::Mat(h, w, CV_32FC3, cv::Scalar::all(0));
  v.distance = cv::Mat(h, w, CV_32FC1, cv::Scalar(0));
  v.cosine = cv::Mat(h, w, CV_32FC1, cv::Scalar(0));
  v.texcoord = cv::Mat(h, w, CV_32FC2, cv::Scalar::all(0));
  const Vec3 centre = projector.pose.center();
  cv::parallel_for_(cv::Range(0, h), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      for (int x = 0; x < w; ++x) {
        const auto ray = projector.backproject(Vec2(x, y));
        if (!ray) continue;  // past the lens model's fold: the pixel lights nothing known
        const auto s = object.intersect(*ray);
        if (!s) continue;
        const Vec3 to_lamp = centre - s->point;
        const double d = to_lamp.norm();
        const double c = s->normal.dot(to_lamp) / d;
        v.face.at<int>(y, x) = static_cast<int>(s->face);
        v.point.at<cv::Vec3f>(y, x) =
            cv::Vec3f(static_cast<float>(s->point.x()), static_cast<float>(s->point.y()),
                      static_cast<float>(s->point.z()));
        v.normal.at<cv::Vec3f>(y, x) =
            cv::Vec3f(static_cast<float>(s->normal.x()), static_cast<float>(s->normal.y()),
                      static_cast<float>(s->normal.z()));
        v.distance.at<float>(y, x) = static_cast<float>(d);
        v.cosine.at<float>(y, x) = static_cast<float>(std::max(0.0, c));
        v.texcoord.at<cv::Vec2f>(y, x) =
            cv::Vec2f(static_cast<float>(s->texcoord.x()), static_cast<float>(s->texcoord.y()));
      }
    }
  });
  return v;
}

}  // namespace procam::lamps
