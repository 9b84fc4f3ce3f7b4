// Content that changes while shown: `content share` (frames another process
// fills in a sealed memfd passed with the request, SCM_RIGHTS) and `content
// stream` (raw frames from a file or FIFO, video through GStreamer). The source
// is read on a timer at its frame rate; each new frame goes through the keystone
// warp like a loaded image. Also 3D content's preparation (content_mesh.hpp).
#include <sys/epoll.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>

#include "content/raw_source.hpp"
#include "content/shm_frames.hpp"
#include "content_mesh.hpp"
#include "daemon.hpp"
#include "geometry/intersect.hpp"
#include "json_matrix.hpp"
#include "render/cpu_renderer.hpp"
#include "render/projective_mesh.hpp"
#include "render/viewer_view.hpp"
#include "request_args.hpp"
#if PROCAM_HAVE_GSTREAMER
#include "content/gst_source.hpp"
#endif

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

namespace {

// An integer side from 2 to 16384; absent is fine when not `required`.
std::optional<int> sideArg(RequestArgs& args, const char* key, bool required) {
  const json* v = args.get(key);
  if (!v) {
    if (required) args.setError("content " + std::string("needs \"") + key + "\"");
    return std::nullopt;
  }
  if (!v->is_number_integer() || v->get<int64_t>() < 2 || v->get<int64_t>() > 16384) {
    args.setError(std::string("\"") + key + "\" must be an integer from 2 to 16384");
    return std::nullopt;
  }
  return v->get<int>();
}

// The one check of [limits] frame_pixels for shared, streamed and test-video frames.
Result<void> framePixels(cv::Size size, std::uint64_t limit) {
  if (std::uint64_t(size.width) * std::uint64_t(size.height) <= limit) return {};
  return fail(ErrorCode::kTooLarge, std::to_string(size.width) + "x" + std::to_string(size.height) +
                                        " frames are over the " + std::to_string(limit) +
                                        "-pixel limit ([limits] frame_pixels)");
}

}  // namespace

void Daemon::cmdContentShare(ClientId client, const proto::Request& req) {
  // Taken before any check: every descriptor is closed on each error return.
  std::vector<UniqueFd> fds = server_->takePassedFds(client);
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "action", "width", "height", "format");
  const auto width = sideArg(args, "width", true);
  const auto height = sideArg(args, "height", true);
  const std::string format_name = args.string("format").value_or("rgba8");
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  auto format = content::parsePixelFormat(format_name);
  if (!format) return errorTo(client, req, code::kBadArgument, format.error().message);
  if (auto ok = framePixels({*width, *height}, config_.limits.frame_pixels); !ok) {
    return errorTo(client, req, code::kTooLarge, ok.error().message);
  }
  if (fds.size() != 1) {
    return errorTo(client, req, code::kBadArgument,
                   "content share needs exactly one memfd passed with the request "
                   "(SCM_RIGHTS); got " +
                       std::to_string(fds.size()));
  }
  ++content_requests_;
  auto source = content::openSharedFrames(fds.front().release(), {*width, *height}, *format);
  if (!source) return errorTo(client, req, code::kBadArgument, source.error().message);
  if (auto ok = startLiveContent(std::move(*source), {{"shared", {{"format", format_name}}}});
      !ok) {
    return errorTo(client, req, code::kInternal, ok.error().message);
  }
  replyTo(client, req, "CONTENT", {{"content", contentJson()}});
}

#if PROCAM_HAVE_GSTREAMER
namespace {

// A file: URI's path, percent-decoded; nullopt for another host or a malformed escape.
std::optional<std::string> fileUriPath(const std::string& uri) {
  std::string rest = uri.substr(std::string("file://").size());
  if (rest.rfind("localhost/", 0) == 0) rest = rest.substr(std::string("localhost").size());
  if (rest.empty() || rest.front() != '/') return std::nullopt;
  std::string path;
  for (std::size_t i = 0; i < rest.size(); ++i) {
    if (rest[i] != '%') {
      path += rest[i];
      continue;
    }
    if (i + 2 >= rest.size() || !std::isxdigit(static_cast<unsigned char>(rest[i + 1])) ||
        !std::isxdigit(static_cast<unsigned char>(rest[i + 2]))) {
      return std::nullopt;
    }
    const char c = static_cast<char>(std::stoi(rest.substr(i + 1, 2), nullptr, 16));
    if (c == '\0') return std::nullopt;
    path += c;
    i += 2;
  }
  return path;
}

}  // namespace
#endif

void Daemon::cmdContentStream(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "action", "path", "uri", "v4l2", "test", "pipeline", "width", "height",
                    "format", "fps");
  const auto path = args.string("path");
  const auto uri = args.string("uri");
  const auto v4l2 = args.string("v4l2");
  const auto test = args.string("test");
  const auto pipeline = args.string("pipeline");
  const auto width = sideArg(args, "width", false);
  const auto height = sideArg(args, "height", false);
  const std::string format_name = args.string("format").value_or("rgba8");
  double fps = 0;
  if (const json* v = args.get("fps")) {
    if (!v->is_number() || !(v->get<double>() >= 0) || v->get<double>() > 1000) {
      args.setError("\"fps\" must be a number from 0 to 1000");
    } else {
      fps = v->get<double>();
    }
  }
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  const int sources =
      int(bool(path)) + int(bool(uri)) + int(bool(v4l2)) + int(bool(test)) + int(bool(pipeline));
  if (sources != 1 || (path && path->empty())) {
    return errorTo(client, req, code::kBadArgument,
                   "content stream needs one of \"path\", \"uri\", \"v4l2\", \"test\" "
                   "(or \"pipeline\" where the configuration allows it)");
  }
  const ContentAccess access = contentAccess();
  if (width && height) {
    if (auto ok = framePixels({*width, *height}, access.limits.frame_pixels); !ok) {
      return errorTo(client, req, code::kTooLarge, ok.error().message);
    }
  }
  if (pipeline && !access.allow_pipeline) {
    return errorTo(client, req, code::kForbidden,
                   "raw GStreamer pipelines are off ([content] allow_pipeline = false): use "
                   "\"path\", \"uri\", \"v4l2\" or \"test\"");
  }
  if (path && (width || height)) {
    // Raw frames: the size (and format) say how to cut the bytes into frames.
    if (!width || !height) {
      return errorTo(client, req, code::kBadArgument,
                     "raw frames need \"path\", \"width\" and \"height\"");
    }
    auto format = content::parsePixelFormat(format_name);
    if (!format) return errorTo(client, req, code::kBadArgument, format.error().message);
    auto resolved = resolveContentPath(access, *path);
    if (!resolved) {
      return errorTo(client, req, protoCode(resolved.error().code), resolved.error().message);
    }
    auto fd = openContentFile(access, *resolved, ContentKind::kRegularOrFifo);
    if (!fd) return errorTo(client, req, protoCode(fd.error().code), fd.error().message);
    ++content_requests_;
    auto source =
        content::openRawFrames(std::move(*fd), *resolved, {{*width, *height}, *format, fps});
    return startStream(client, req, std::move(source),
                       {{"path", *resolved}, {"raw", {{"format", format_name}, {"fps", fps}}}});
  }
  if ((width || height) && !test) {
    return errorTo(client, req, code::kBadArgument,
                   "\"width\" and \"height\" go with raw frames from \"path\" or a \"test\" "
                   "video");
  }
#if PROCAM_HAVE_GSTREAMER
  // The source to open, checked here (roots, names); opening waits for the first
  // decoded frame (up to the preroll timeout): on a worker, the reply once it is
  // shown or refused.
  std::function<Result<std::unique_ptr<content::ContentSource>>()> open;
  json info = {{"video", true}};
  std::optional<std::string> file = path;
  if (uri && uri->rfind("file:", 0) == 0) {
    file = uri->rfind("file://", 0) == 0 ? fileUriPath(*uri) : std::nullopt;
    if (!file) {
      return errorTo(client, req, code::kBadArgument,
                     "file URI '" + *uri + "' is not file:///absolute/path");
    }
  }
  if (file) {
    auto resolved = resolveContentPath(access, *file);
    if (!resolved) {
      return errorTo(client, req, protoCode(resolved.error().code), resolved.error().message);
    }
    if (auto fd = openContentFile(access, *resolved, ContentKind::kRegular); !fd) {
      return errorTo(client, req, protoCode(fd.error().code), fd.error().message);
    }
    info["path"] = *resolved;
    open = [f = *resolved] { return content::openVideoFile(f); };
  } else if (uri) {
    info["uri"] = *uri;
    open = [u = *uri] { return content::openVideoUri(u); };
  } else if (v4l2) {
    info["v4l2"] = *v4l2;
    open = [d = *v4l2] { return content::openV4l2Video(d); };
  } else if (test) {
    const cv::Size size(width.value_or(1280), height.value_or(720));
    if (auto ok = framePixels(size, access.limits.frame_pixels); !ok) {
      return errorTo(client, req, code::kTooLarge, ok.error().message);
    }
    const double rate = fps > 0 ? fps : 30.0;
    info["test"] = *test;
    open = [t = *test, size, rate] { return content::openTestVideo(t, size, rate); };
  } else {
    info["pipeline"] = *pipeline;
    open = [p = *pipeline] { return content::openGstPipeline(p); };
  }
  if (refuseOverJobLimit(client, req)) return;
  server_->hold(client);
  const uint64_t request = ++content_requests_;
  compute_worker_->submit(
      [this, client, req, open, info, max_pixels = access.limits.frame_pixels, request] {
        auto opened = std::make_shared<Result<std::unique_ptr<content::ContentSource>>>(open());
        // A source whose first frame is over the limit is closed before it plays.
        if (*opened) {
          if (auto ok = framePixels((**opened)->size(), max_pixels); !ok) {
            *opened = tl::unexpected(ok.error());
          }
        }
        return [this, client, req, opened, info, request] {
          if (request != content_requests_) {
            errorTo(client, req, code::kCancelled, "replaced by a later content request");
          } else {
            startStream(client, req, std::move(*opened), info);
          }
          server_->release(client);
        };
      },
      answerFailure(client, req), client);
#else
  return errorTo(client, req, code::kUnavailable,
                 "video needs GStreamer, which this procamd was built without");
#endif
}

void Daemon::startStream(ClientId client, const proto::Request& req,
                         Result<std::unique_ptr<content::ContentSource>> source, const json& info) {
  if (!source) return errorTo(client, req, protoCode(source.error().code), source.error().message);
  if (auto ok = startLiveContent(std::move(*source), {{"stream", info}}); !ok) {
    return errorTo(client, req, code::kInternal, ok.error().message);
  }
  replyTo(client, req, "CONTENT", {{"content", contentJson()}});
}

Result<void> Daemon::startLiveContent(std::unique_ptr<content::ContentSource> source, json info) {
  stopLiveContent();
  // A new stream's first held drift check is due at once.
  for (auto& [name, o] : drift_rt_.outputs) {
    o.held_at.reset();
    o.quick_holds = 0;
    o.held_checks = 0;
  }
  // A source with an fd (a FIFO) is read whenever bytes arrive, so that its
  // writer never waits for a timer; the others are read at their frame rate.
  const int fd = source->pollFd();
  int timer = -1;
  if (fd >= 0) {
    if (auto ok = loop_->add(fd, EPOLLIN, [this](uint32_t) { pollLiveContent(); }); !ok) {
      return tl::unexpected(ok.error());
    }
  } else {
    const auto interval = source->frameInterval().value_or(std::chrono::milliseconds(16));
    auto added = loop_->addTimer(interval, true, [this] { pollLiveContent(); });
    if (!added) return tl::unexpected(added.error());
    timer = *added;
  }
  settings_.content.clear();
  keystone_rt_.content.reset();
  content_info_ = {source->size().width, source->size().height};
  keystone_rt_.meshes.clear();
  keystone_rt_.mesh_images.clear();
  clearObjectContent();
  live_content_ = LiveContent{std::move(source), timer, fd, std::move(info), 0, false};
  pollLiveContent();  // a frame already there shows at once
  broadcast("content", {{"content", contentJson()}});
  return {};
}

void Daemon::pollLiveContent() {
  if (!live_content_ || live_content_->ended) return;
  LiveContent& live = *live_content_;
  // Timer sources: one frame in flight at a time, the newest taken once it is
  // shown. A FIFO is drained whenever it is readable (its writer must not
  // block); frames that arrive while one renders replace each other.
  if (live.fd < 0 && keystone_rt_.rendering) return;
  content::Frame frame, newest;
  Result<content::ReadStatus> status = content::ReadStatus::kNoFrame;
  while ((status = live.source->read(frame)) && *status == content::ReadStatus::kFrame) {
    newest = std::move(frame);
    if (live.fd < 0) break;
  }
  if (!newest.pixels.empty()) {
    // A video may change its size mid-stream: the limit holds for every frame.
    if (auto ok = framePixels(newest.pixels.size(), config_.limits.frame_pixels); !ok) {
      status = tl::unexpected(ok.error());
      newest = {};
    }
  }
  if (!newest.pixels.empty()) {
    keystone_rt_.content = std::make_shared<const cv::Mat>(content::toRgba(newest));
    content_info_ = {newest.pixels.cols, newest.pixels.rows};
    ++live.frames;
    refreshOutputs({}, live.frames == 1);  // the first frame replaces other content
  }
  if (!status || *status == content::ReadStatus::kEnd) {
    // The last frame stays shown; the source is closed.
    if (!status) warn("content stopped: " + status.error().message);
    stopWatchingLiveContent();
    live.source.reset();
    live.ended = true;
    broadcast("content", {{"content", contentJson()}});
  }
}

void Daemon::stopWatchingLiveContent() {
  if (live_content_->fd >= 0) loop_->remove(live_content_->fd);
  if (live_content_->timer >= 0) loop_->removeTimer(live_content_->timer);
  live_content_->fd = live_content_->timer = -1;
}

void Daemon::stopLiveContent() {
  if (!live_content_) return;
  stopWatchingLiveContent();
  live_content_.reset();
}

json Daemon::liveContentJson() const {
  json j = live_content_->info;
  j["frames"] = live_content_->frames;
  j["ended"] = live_content_->ended;
  j["size"] = {content_info_.width, content_info_.height};
  return j;
}

bool isMeshFile(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext == ".obj" || ext == ".ply";
}

namespace {

struct ViewerImage {
  std::shared_ptr<const cv::Mat> image;
  content::PlanarView view;  // the placement plane
};

// A mesh on a non-planar surface: the content image that render::viewerContentMatrix
// places on the surface for the eye (the output's size) plays the projector's part in the
// rules of content/mesh_placement.hpp: the mesh stands on the plane through the surface
// point at the projector's centre, facing the viewer, inside that image's rectangle on the
// plane, and is drawn from the eye into it ([Raskar02] §3.2.3: the first pass of two).
Result<ViewerImage> drawForViewer(const content::MeshContent& mesh, const geom::CameraModel& model,
                                  const geom::MeshIntersector& surface, const Vec3& eye) {
  const cv::Size size(model.width, model.height);
  const Mat34 P = model.projectionMatrix();
  auto ray = model.backproject(Vec2((model.width - 1) / 2.0, (model.height - 1) / 2.0));
  if (!ray) return tl::unexpected(ray.error());
  const auto hit = surface.intersect(*ray);
  if (!hit) return fail(ErrorCode::kDegenerate, "the projector's central ray misses the surface");
  auto V = render::viewerContentMatrix(surface, P, size, eye, size);
  if (!V) return tl::unexpected(V.error());
  // Placed for the content image as the viewer sees it (its rectangle on the plane is
  // S), so that the whole mesh lies where the surface can show it.
  ViewerImage out;
  out.view.projector = *V;
  out.view.size = size;
  out.view.plane_point = hit->point;
  out.view.plane_normal = (eye - hit->point).normalized();
  out.view.eye = eye;
  auto placed = content::placeMeshContent(mesh, out.view);
  if (!placed) return tl::unexpected(placed.error());
  double near = INFINITY, far = 0;
  for (const Vec3& x : placed->mesh.vertices) {
    const double w = V->row(2).dot(x.homogeneous());
    if (w <= 0) return fail(ErrorCode::kDegenerate, "the placed mesh reaches behind the viewer");
    near = std::min(near, w);
    far = std::max(far, w);
  }
  auto depth = render::pixelProjectionWithDepth(*V, 0.5 * near, 2.0 * far);
  if (!depth) return tl::unexpected(depth.error());
  render::RenderSetup setup;
  setup.output_size = size;
  setup.path = render::RenderPath::kPlanar3d;
  setup.planar3d = *depth;
  render::CpuRenderer renderer;
  if (auto ok = renderer.configure(setup); !ok) return tl::unexpected(ok.error());
  if (auto ok = renderer.render({nullptr, &placed->mesh, 1}); !ok) {
    return tl::unexpected(ok.error());
  }
  out.image = std::make_shared<const cv::Mat>(renderer.frame().clone());
  return out;
}

}  // namespace

tl::expected<PreparedMesh, MeshFailure> prepareMeshContent(const ContentAccess& access,
                                                           const std::string& file,
                                                           const std::vector<MeshOutput>& outputs,
                                                           const std::optional<Vec3>& eye,
                                                           const json& eye_source) {
  if (outputs.empty())
    return tl::unexpected(MeshFailure{code::kUnavailable, "no output to show 3D content on"});
  // Geometry before the file: an uncalibrated rig is the common case to report.
  for (const MeshOutput& o : outputs) {
    auto unavailable = [&](const std::string& why) {
      return tl::unexpected(
          MeshFailure{code::kUnavailable, "3D content on output '" + o.name + "': " + why});
    };
    if (!o.projector) {
      return unavailable("the rig model has no calibrated projector pose for it (run calibrate)");
    }
    if (!o.surface_known) {
      return unavailable("the rig model has no display surface (run calibrate)");
    }
    if (!o.plane && !o.surface) {
      return unavailable("the display surface is not planar and its mesh is not loaded");
    }
  }
  if (!eye) {
    return tl::unexpected(
        MeshFailure{code::kUnavailable,
                    "3D content needs a viewer: a tracker, [content] viewer in the "
                    "configuration, or the rig model's viewer"});
  }
  auto bytes = readContentFile(access, file);
  if (!bytes) {
    return tl::unexpected(MeshFailure{protoCode(bytes.error().code), bytes.error().message});
  }
  const sim::MeshLimits limits{access.limits.mesh_vertices, access.limits.mesh_faces,
                               access.limits.face_indices, access.limits.file_bytes};
  auto loaded = content::meshContentFromBytes(*bytes, file, limits);
  if (!loaded) {
    return tl::unexpected(MeshFailure{protoCode(loaded.error().code), loaded.error().message});
  }
  PreparedMesh out;
  for (const MeshOutput& o : outputs) {
    auto unavailable = [&](const std::string& why) {
      return tl::unexpected(
          MeshFailure{code::kUnavailable, "3D content on output '" + o.name + "': " + why});
    };
    const geom::CameraModel& model = *o.projector;
    // The display surface is where the projector's central ray meets the plane.
    auto ray = model.backproject(Vec2((model.width - 1) / 2.0, (model.height - 1) / 2.0));
    if (!ray) return unavailable(ray.error().message);
    if (!o.plane) {
      auto drawn = drawForViewer(*loaded, model, *o.surface, *eye);
      if (!drawn) return unavailable(drawn.error().message);
      out.images[o.name] = MeshImage{drawn->image, drawn->view.projector};
      json matrix = json::array();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) matrix.push_back(drawn->view.projector(r, c));
      out.placement[o.name] = {{"plane_point", vectorJson(drawn->view.plane_point)},
                               {"plane_normal", vectorJson(drawn->view.plane_normal)},
                               {"viewer_matrix", matrix},
                               {"size", {drawn->view.size.width, drawn->view.size.height}}};
      out.eye = *eye;
      continue;
    }
    const auto hit = geom::intersectPlane(*ray, *o.plane);
    if (!hit) return unavailable("the projector's central ray does not meet the display plane");
    content::PlanarView view;
    view.projector = model.projectionMatrix();
    view.size = {model.width, model.height};
    view.plane_point = hit->point;
    view.plane_normal = hit->normal;  // facing the projector, as the lit side of a wall does
    view.eye = *eye;
    auto placed = content::placeMeshContent(*loaded, view);
    if (!placed) return unavailable(placed.error().message);
    out.views[o.name] = MeshView{view, placed->S};
    out.eye = view.eye;
    out.meshes[o.name] = Mesh3d{
        std::make_shared<const render::ColoredMesh>(std::move(placed->mesh)), placed->planar3d};
  }
  json viewer = eye_source;
  viewer["position"] = {eye->x(), eye->y(), eye->z()};
  out.info = {{"path", file},
              {"mesh",
               {{"triangles", loaded->mesh.faces.size()},
                {"vertices", loaded->mesh.vertices.size()},
                {"shading", "lambert"},
                {"viewer", viewer}}}};
  if (!out.placement.empty()) out.info["mesh"]["placement"] = out.placement;
  return out;
}

}  // namespace procam::daemon
