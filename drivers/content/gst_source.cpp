#include "gst_source.hpp"

#include <gst/app/gstappsink.h>
#include <gst/gst.h>
#include <gst/video/video.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace procam::content {

namespace {

struct GstUnref {
  void operator()(GstElement* e) const {
    gst_element_set_state(e, GST_STATE_NULL);
    gst_object_unref(e);
  }
  void operator()(GstSample* s) const { gst_sample_unref(s); }
  void operator()(GstMessage* m) const { gst_message_unref(m); }
  void operator()(GstBus* b) const { gst_object_unref(b); }
  void operator()(GError* e) const { g_error_free(e); }
  void operator()(gchar* s) const { g_free(s); }
};
template <class T>
using GstPtr = std::unique_ptr<T, GstUnref>;

// The pipeline's first error message, if one is waiting on the bus.
std::string busError(GstElement* pipeline) {
  GstPtr<GstBus> bus(gst_element_get_bus(pipeline));
  GstPtr<GstMessage> msg(gst_bus_pop_filtered(bus.get(), GST_MESSAGE_ERROR));
  if (!msg) return {};
  GError* raw = nullptr;
  gst_message_parse_error(msg.get(), &raw, nullptr);
  GstPtr<GError> err(raw);
  return err ? err->message : "unknown GStreamer error";
}

class GstVideo final : public ContentSource {
 public:
  GstVideo(GstPtr<GstElement> pipeline, GstAppSink* sink, cv::Size size,
           std::optional<std::chrono::nanoseconds> interval)
      : pipeline_(std::move(pipeline)), sink_(sink), size_(size), interval_(interval) {}
  ~GstVideo() override { gst_object_unref(sink_); }

  cv::Size size() const override { return size_; }
  PixelFormat format() const override { return PixelFormat::kRgba8; }
  std::optional<std::chrono::nanoseconds> frameInterval() const override { return interval_; }

  Result<ReadStatus> read(Frame& out) override {
    if (ended_) return ReadStatus::kEnd;
    GstPtr<GstSample> sample(gst_app_sink_try_pull_sample(sink_, 0));
    if (!sample) {
      if (const std::string e = busError(pipeline_.get()); !e.empty()) {
        ended_ = true;
        return fail(ErrorCode::kIo, "video: " + e);
      }
      if (gst_app_sink_is_eos(sink_)) {
        ended_ = true;
        return ReadStatus::kEnd;
      }
      return ReadStatus::kNoFrame;
    }
    GstVideoInfo info;
    if (!gst_video_info_from_caps(&info, gst_sample_get_caps(sample.get()))) {
      ended_ = true;
      return fail(ErrorCode::kIo, "video: a sample without video caps");
    }
    GstBuffer* buffer = gst_sample_get_buffer(sample.get());
    GstMapInfo map;
    if (!buffer || !gst_buffer_map(buffer, &map, GST_MAP_READ)) {
      ended_ = true;
      return fail(ErrorCode::kIo, "video: cannot map a frame");
    }
    const int w = GST_VIDEO_INFO_WIDTH(&info), h = GST_VIDEO_INFO_HEIGHT(&info);
    const size_t stride = static_cast<size_t>(GST_VIDEO_INFO_PLANE_STRIDE(&info, 0));
    if (map.size < stride * static_cast<size_t>(h - 1) + static_cast<size_t>(w) * 4) {
      gst_buffer_unmap(buffer, &map);
      ended_ = true;
      return fail(ErrorCode::kIo, "video: frame buffer smaller than its caps");
    }
    // Rows may be padded: copy out row by row into a packed frame.
    out.pixels =
        cv::Mat(h, w, CV_8UC4,
                const_cast<uint8_t*>(map.data) + GST_VIDEO_INFO_PLANE_OFFSET(&info, 0), stride)
            .clone();
    gst_buffer_unmap(buffer, &map);
    out.format = PixelFormat::kRgba8;
    out.sequence = ++sequence_;
    const GstClockTime pts = GST_BUFFER_PTS(buffer);
    out.timestamp =
        GST_CLOCK_TIME_IS_VALID(pts) ? std::chrono::nanoseconds(pts) : std::chrono::nanoseconds(0);
    size_ = {w, h};
    return ReadStatus::kFrame;
  }

 private:
  GstPtr<GstElement> pipeline_;
  GstAppSink* sink_;  // a reference of its own
  cv::Size size_;
  std::optional<std::chrono::nanoseconds> interval_;
  uint64_t sequence_ = 0;
  bool ended_ = false;
};

Result<void> initGstreamer() {
  static GError* init_error = [] {
    GError* e = nullptr;
    gst_init_check(nullptr, nullptr, &e);
    return e;
  }();
  if (init_error) return fail(ErrorCode::kIo, std::string("GStreamer: ") + init_error->message);
  return {};
}

}  // namespace

Result<std::unique_ptr<ContentSource>> openGstPipeline(const std::string& description,
                                                       const GstOptions& options) {
  if (auto ok = initGstreamer(); !ok) return tl::unexpected(ok.error());
  // Playback drops frames the reader did not take in time (the newest is shown);
  // offline reading holds the decoder back instead, so that no frame is lost.
  const std::string launch =
      description +
      // Sizes beyond 16384 (procamd's largest side) fail to negotiate before a frame
      // of them is allocated.
      " ! videoconvert ! video/x-raw,format=RGBA,width=[2,16384],height=[2,16384] ! appsink "
      "name=procam_sink " +
      (options.realtime ? "sync=true max-buffers=2 drop=true"
                        : "sync=false max-buffers=4 drop=false");
  GError* raw_error = nullptr;
  GstPtr<GstElement> pipeline(gst_parse_launch(launch.c_str(), &raw_error));
  GstPtr<GError> parse_error(raw_error);
  if (!pipeline || parse_error) {
    return fail(ErrorCode::kInvalidInput,
                "video pipeline '" + description +
                    "': " + (parse_error ? parse_error->message : "does not parse"));
  }
  GstElement* sink_element = gst_bin_get_by_name(GST_BIN(pipeline.get()), "procam_sink");
  if (!sink_element) return fail(ErrorCode::kInvalidInput, "video pipeline without its appsink");
  auto* sink = GST_APP_SINK(sink_element);
  // Paused: the first frame prerolls, which gives the size and frame rate.
  // get_state returns once the frame prerolled or the pipeline failed.
  gst_element_set_state(pipeline.get(), GST_STATE_PAUSED);
  const GstStateChangeReturn state = gst_element_get_state(
      pipeline.get(), nullptr, nullptr,
      static_cast<GstClockTime>(options.preroll_timeout.count()) * GST_MSECOND);
  GstPtr<GstSample> preroll(
      state == GST_STATE_CHANGE_SUCCESS ? gst_app_sink_try_pull_preroll(sink, 0) : nullptr);
  GstVideoInfo info;
  if (!preroll || !gst_video_info_from_caps(&info, gst_sample_get_caps(preroll.get()))) {
    std::string why = busError(pipeline.get());
    if (why.empty()) why = preroll ? "no video caps" : "no frame before the timeout";
    gst_object_unref(sink);
    return fail(ErrorCode::kIo, "video pipeline '" + description + "': " + why);
  }
  std::optional<std::chrono::nanoseconds> interval;
  if (GST_VIDEO_INFO_FPS_N(&info) > 0 && GST_VIDEO_INFO_FPS_D(&info) > 0) {
    interval = std::chrono::nanoseconds(gst_util_uint64_scale(
        GST_SECOND, GST_VIDEO_INFO_FPS_D(&info), GST_VIDEO_INFO_FPS_N(&info)));
  }
  const cv::Size size(GST_VIDEO_INFO_WIDTH(&info), GST_VIDEO_INFO_HEIGHT(&info));
  gst_element_set_state(pipeline.get(), GST_STATE_PLAYING);
  return std::unique_ptr<ContentSource>(
      std::make_unique<GstVideo>(std::move(pipeline), sink, size, interval));
}

Result<std::unique_ptr<ContentSource>> openVideoUri(const std::string& uri,
                                                    const GstOptions& options) {
  const std::size_t colon = uri.find("://");
  const std::string scheme = colon == std::string::npos ? "" : uri.substr(0, colon);
  if (scheme != "http" && scheme != "https" && scheme != "rtsp" && scheme != "rtsps") {
    return fail(ErrorCode::kInvalidInput,
                "video URI '" + uri + "': the scheme must be http, https, rtsp or rtsps");
  }
  if (uri.size() > 2048) return fail(ErrorCode::kInvalidInput, "video URI over 2048 characters");
  for (const char ch : uri) {
    const auto c = static_cast<unsigned char>(ch);
    if (c <= 0x20 || c >= 0x7F || ch == '"' || ch == '\\' || ch == '\'') {
      return fail(ErrorCode::kInvalidInput,
                  "video URI with a character that must be percent-encoded (quote, backslash, "
                  "space, control or non-ASCII)");
    }
  }
  if (auto ok = initGstreamer(); !ok) return tl::unexpected(ok.error());
  if (!gst_uri_is_valid(uri.c_str())) {
    return fail(ErrorCode::kInvalidInput, "video URI '" + uri + "' is not a valid URI");
  }
  return openGstPipeline("uridecodebin uri=\"" + uri + "\"", options);
}

Result<std::unique_ptr<ContentSource>> openV4l2Video(const std::string& device,
                                                     const GstOptions& options) {
  const std::string prefix = "/dev/video";
  const std::string number =
      device.substr(0, prefix.size()) == prefix ? device.substr(prefix.size()) : std::string();
  if (number.empty() || number.size() > 3 ||
      number.find_first_not_of("0123456789") != std::string::npos) {
    return fail(ErrorCode::kInvalidInput, "V4L2 device '" + device + "' is not /dev/videoN");
  }
  return openGstPipeline("v4l2src device=" + device, options);
}

Result<std::unique_ptr<ContentSource>> openTestVideo(const std::string& pattern, cv::Size size,
                                                     double fps, const GstOptions& options) {
  if (std::find(std::begin(kTestVideoPatterns), std::end(kTestVideoPatterns), pattern) ==
      std::end(kTestVideoPatterns)) {
    std::string names;
    for (const char* p : kTestVideoPatterns) names += (names.empty() ? "" : ", ") + std::string(p);
    return fail(ErrorCode::kInvalidInput, "unknown test video '" + pattern + "' (" + names + ")");
  }
  if (size.width < 2 || size.height < 2 || size.width > 16384 || size.height > 16384) {
    return fail(ErrorCode::kInvalidInput, "a test video is 2x2 to 16384x16384 pixels");
  }
  if (!(fps > 0 && fps <= 1000)) {
    return fail(ErrorCode::kInvalidInput, "a test video's frame rate is over 0 and at most 1000");
  }
  const int rate = static_cast<int>(std::lround(fps * 1000));
  return openGstPipeline(
      "videotestsrc pattern=" + pattern + " ! video/x-raw,width=" + std::to_string(size.width) +
          ",height=" + std::to_string(size.height) + ",framerate=" + std::to_string(rate) + "/1000",
      options);
}

Result<std::unique_ptr<ContentSource>> openVideoFile(const std::string& path,
                                                     const GstOptions& options) {
  if (auto ok = initGstreamer(); !ok) return tl::unexpected(ok.error());
  GError* raw_error = nullptr;
  GstPtr<gchar> uri(gst_filename_to_uri(path.c_str(), &raw_error));
  GstPtr<GError> error(raw_error);
  if (!uri) return fail(ErrorCode::kIo, path + ": " + (error ? error->message : "bad path"));
  if (!g_file_test(path.c_str(), G_FILE_TEST_IS_REGULAR)) {
    return fail(ErrorCode::kIo, path + ": no such file");
  }
  auto source = openGstPipeline(std::string("uridecodebin uri=\"") + uri.get() + "\"", options);
  if (!source) return fail(source.error().code, path + ": " + source.error().message);
  return source;
}

}  // namespace procam::content
