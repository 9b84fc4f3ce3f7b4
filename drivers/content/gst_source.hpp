#pragma once
// Video through GStreamer: decoded frames taken from an appsink, converted to
// RGBA by videoconvert. Built only when gstreamer-1.0 and gstreamer-app-1.0 are
// found (PROCAM_HAVE_GSTREAMER).
#include <memory>
#include <string>

#include "content_source.hpp"

namespace procam::content {

struct GstOptions {
  // true: frames arrive at their presentation time (playback); false: as fast
  // as they decode (tests, offline use).
  bool realtime = true;
  // How long open waits for the first frame (the size and frame rate come from it).
  std::chrono::milliseconds preroll_timeout{5000};
};

// A video file (any container and codec the installed plugins decode).
Result<std::unique_ptr<ContentSource>> openVideoFile(const std::string& path,
                                                     const GstOptions& options = {});

// The fixed pipelines procamd builds itself from what a client names, each
// argument checked before it goes into the description (no client text reaches
// gst_parse_launch unchecked):
//  - a network URI: http, https, rtsp or rtsps, with no quote, backslash, space
//    or control character (a file: URI is the caller's: openVideoFile on the path);
//  - a V4L2 capture device, /dev/videoN;
//  - a videotestsrc pattern (kTestVideoPatterns) at a size and frame rate.
// kInvalidInput for what fails those checks; otherwise as openGstPipeline.
Result<std::unique_ptr<ContentSource>> openVideoUri(const std::string& uri,
                                                    const GstOptions& options = {});
Result<std::unique_ptr<ContentSource>> openV4l2Video(const std::string& device,
                                                     const GstOptions& options = {});
inline constexpr const char* kTestVideoPatterns[] = {
    "smpte", "snow",    "black",      "white",    "red",    "green", "blue",    "checkers-8",
    "ball",  "smpte75", "zone-plate", "gradient", "colors", "bar",   "pinwheel"};
Result<std::unique_ptr<ContentSource>> openTestVideo(const std::string& pattern, cv::Size size,
                                                     double fps, const GstOptions& options = {});

// A gst-launch description of the source part, e.g. "videotestsrc num-buffers=3";
// videoconvert and the appsink are appended. kInvalidInput when it does not parse,
// kIo when it fails before the first frame (the pipeline's own message).
Result<std::unique_ptr<ContentSource>> openGstPipeline(const std::string& description,
                                                       const GstOptions& options = {});

}  // namespace procam::content
