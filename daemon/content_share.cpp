// `content share`: frames another process fills in a sealed memfd passed with the
// request (SCM_RIGHTS), shown through the keystone warp as they change.
#include "content/shm_frames.hpp"
#include "daemon.hpp"
#include "request_args.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

namespace {

std::optional<int> sideArg(RequestArgs& args, const char* key) {
  const json* v = args.get(key);
  if (!v) {
    args.setError(std::string("content share needs \"") + key + "\"");
    return std::nullopt;
  }
  if (!v->is_number_integer() || v->get<int64_t>() < 2 || v->get<int64_t>() > 16384) {
    args.setError(std::string("\"") + key + "\" must be an integer from 2 to 16384");
    return std::nullopt;
  }
  return v->get<int>();
}

}  // namespace

void Daemon::cmdContentShare(ClientId client, const proto::Request& req) {
  // Taken before any check: every descriptor is closed on each error return.
  std::vector<UniqueFd> fds = server_->takePassedFds(client);
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "action", "width", "height", "format");
  const auto width = sideArg(args, "width");
  const auto height = sideArg(args, "height");
  const std::string format_name = args.string("format").value_or("rgba8");
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  auto format = content::parsePixelFormat(format_name);
  if (!format) return errorTo(client, req, code::kBadArgument, format.error().message);
  if (fds.size() != 1) {
    return errorTo(client, req, code::kBadArgument,
                   "content share needs exactly one memfd passed with the request "
                   "(SCM_RIGHTS); got " +
                       std::to_string(fds.size()));
  }
  auto source = content::openSharedFrames(fds.front().release(), {*width, *height}, *format);
  if (!source) return errorTo(client, req, code::kBadArgument, source.error().message);

  stopSharedContent();
  settings_.content.clear();
  keystone_rt_.content.reset();
  content_info_ = {*width, *height};
  const auto interval = (*source)->frameInterval().value_or(std::chrono::milliseconds(16));
  auto timer = loop_->addTimer(interval, true, [this] { pollSharedContent(); });
  if (!timer) return errorTo(client, req, code::kInternal, timer.error().message);
  shared_content_ = SharedContent{std::move(*source), *timer, format_name, 0};
  pollSharedContent();  // a frame published before the request shows at once
  broadcast("content", {{"content", contentJson()}});
  replyTo(client, req, "CONTENT", {{"content", contentJson()}});
}

void Daemon::pollSharedContent() {
  // One frame in flight at a time: the newest is taken once it is shown.
  if (!shared_content_ || keystone_rt_.rendering) return;
  content::Frame frame;
  auto status = shared_content_->source->read(frame);
  if (!status) {
    warn("shared content stopped: " + status.error().message);
    stopSharedContent();
    return;
  }
  if (*status != content::ReadStatus::kFrame) return;
  keystone_rt_.content = std::make_shared<const cv::Mat>(content::toRgba(frame));
  ++shared_content_->frames;
  refreshOutputs();
}

void Daemon::stopSharedContent() {
  if (!shared_content_) return;
  loop_->removeTimer(shared_content_->timer);
  shared_content_.reset();
}

json Daemon::sharedContentJson() const {
  return {{"shared", {{"format", shared_content_->format}, {"frames", shared_content_->frames}}},
          {"size", {content_info_.width, content_info_.height}}};
}

}  // namespace procam::daemon
