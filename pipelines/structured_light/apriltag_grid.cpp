#include "structured_light/apriltag_grid.hpp"

#include <apriltag/apriltag.h>
#include <apriltag/common/image_u8.h>
#include <apriltag/common/zarray.h>
#include <apriltag/tag36h11.h>

#include <memory>
#include <opencv2/imgproc.hpp>

namespace procam::sl {
namespace {

constexpr int kTotalModules = 10;  // tag36h11 with its one-module white border
constexpr int kBorderStart = 1;    // first black module
constexpr int kBorderEnd = 9;      // one past the last black module

struct FamilyDeleter {
  void operator()(apriltag_family_t* f) const { tag36h11_destroy(f); }
};
struct DetectorDeleter {
  void operator()(apriltag_detector_t* d) const { apriltag_detector_destroy(d); }
};
struct ImageDeleter {
  void operator()(image_u8_t* im) const { image_u8_destroy(im); }
};
struct DetectionsDeleter {
  void operator()(zarray_t* z) const { apriltag_detections_destroy(z); }
};
using Family = std::unique_ptr<apriltag_family_t, FamilyDeleter>;

}  // namespace

Result<TagGrid> makeTagGrid(const TagGridOptions& o) {
  if (o.width < 1 || o.height < 1 || o.module_px < 0 || o.gap_modules < 0)
    return fail(ErrorCode::kInvalidInput, "tag grid: invalid size, module or gap");
  const int pitch_modules = kTotalModules + o.gap_modules;
  int module = o.module_px;
  if (module == 0) module = std::max(1, o.width / (8 * pitch_modules));
  const int pitch = pitch_modules * module;
  const int cols = (o.width - kTotalModules * module) / pitch + 1;
  const int rows = (o.height - kTotalModules * module) / pitch + 1;
  if (o.width < kTotalModules * module || o.height < kTotalModules * module || cols < 2 || rows < 2)
    return fail(ErrorCode::kInvalidInput, "tag grid: not even 2x2 tags fit the image");
  Family family(tag36h11_create());
  if (cols * rows > static_cast<int>(family->ncodes))
    return fail(ErrorCode::kInvalidInput, "tag grid: more tags than tag36h11 has codes");
  TagGrid grid;
  grid.options = o;
  grid.module_px = module;
  // Centre the grid in the image.
  const int used_w = (cols - 1) * pitch + kTotalModules * module;
  const int used_h = (rows - 1) * pitch + kTotalModules * module;
  const int x_origin = (o.width - used_w) / 2, y_origin = (o.height - used_h) / 2;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      TagPlacement t;
      t.id = r * cols + c;
      // A module edge at pixel-edge coordinate e is at e - 0.5 in pixel-centre terms.
      const double left = x_origin + c * pitch + kBorderStart * module - 0.5;
      const double right = x_origin + c * pitch + kBorderEnd * module - 0.5;
      const double top = y_origin + r * pitch + kBorderStart * module - 0.5;
      const double bottom = y_origin + r * pitch + kBorderEnd * module - 0.5;
      t.corners = {Vec2(left, bottom), Vec2(right, bottom), Vec2(right, top), Vec2(left, top)};
      grid.tags.push_back(t);
    }
  return grid;
}

Result<cv::Mat> renderTagGrid(const TagGrid& grid) {
  cv::Mat image(grid.options.height, grid.options.width, CV_8UC1, cv::Scalar(255));
  Family family(tag36h11_create());
  const int m = grid.module_px;
  for (const TagPlacement& t : grid.tags) {
    std::unique_ptr<image_u8_t, ImageDeleter> tag(apriltag_to_image(family.get(), t.id));
    if (!tag || tag->width != kTotalModules)
      return fail(ErrorCode::kInvalidInput, "tag grid: libapriltag returned no tag image");
    const cv::Mat modules(tag->height, tag->width, CV_8UC1, tag->buf,
                          static_cast<std::size_t>(tag->stride));
    const int x0 = static_cast<int>(t.corners[3].x() + 0.5) - kBorderStart * m;
    const int y0 = static_cast<int>(t.corners[3].y() + 0.5) - kBorderStart * m;
    cv::Mat roi = image(cv::Rect(x0, y0, kTotalModules * m, kTotalModules * m));
    cv::resize(modules, roi, roi.size(), 0, 0, cv::INTER_NEAREST);
  }
  return image;
}

Result<std::vector<TagCorrespondence>> detectTagGrid(const TagGrid& grid, const cv::Mat& image,
                                                     const TagDetectOptions& o) {
  if (image.empty() || image.type() != CV_8UC1)
    return fail(ErrorCode::kInvalidInput, "tag detection needs an 8-bit single-channel image");
  // Declared before the detector, so destroyed after it (the detector does not own it).
  Family family(tag36h11_create());
  std::unique_ptr<apriltag_detector_t, DetectorDeleter> detector(apriltag_detector_create());
  apriltag_detector_add_family(detector.get(), family.get());
  detector->quad_decimate = o.decimate;
  // One thread: libapriltag's worker pool up to 3.3 (Debian 12's) can run a task from a
  // task list that is being reallocated, and its worker then jumps to a freed address
  // (AprilRobotics/apriltag pull request 339, "Fix spurious wake-ups ... in workerpool").
  // Seen here as a segfault in 1 of about 40 detections on a loaded 2-core machine.
  detector->nthreads = 1;
  detector->refine_edges = 1;
  // libapriltag reads the buffer but its API takes a non-const pointer.
  cv::Mat contiguous = image.isContinuous() ? image : image.clone();
  image_u8_t view{contiguous.cols, contiguous.rows, static_cast<int32_t>(contiguous.step[0]),
                  contiguous.data};
  std::unique_ptr<zarray_t, DetectionsDeleter> detections(
      apriltag_detector_detect(detector.get(), &view));
  std::vector<TagCorrespondence> out;
  for (int i = 0; i < zarray_size(detections.get()); ++i) {
    apriltag_detection_t* d = nullptr;
    zarray_get(detections.get(), i, &d);
    if (d->id < 0 || d->id >= static_cast<int>(grid.tags.size())) continue;
    if (d->decision_margin < o.min_margin || d->hamming > 0) continue;
    const TagPlacement& t = grid.tags[static_cast<std::size_t>(d->id)];
    for (int c = 0; c < 4; ++c) {
      // libapriltag puts pixel centres at +0.5 (ARCHITECTURE.md: integer centres).
      out.push_back({d->id, c, Vec2(d->p[c][0] - 0.5, d->p[c][1] - 0.5), t.corners[c]});
    }
  }
  return out;
}

}  // namespace procam::sl
