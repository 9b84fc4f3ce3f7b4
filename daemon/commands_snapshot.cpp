// The snapshot request (PROTOCOL.md): one frame of a camera for an installer,
// captured on the compute worker while the camera is held from the device
// manager's reads (as calibrate and latency hold it), written as PNG to the state
// directory's snapshots/ (one file per camera, replaced atomically).
#include <cmath>

#include "camera/convert.hpp"
#include "camera_snapshot.hpp"
#include "daemon.hpp"
#include "device_manager.hpp"
#include "log.hpp"
#include "request_args.hpp"
#include "state_file.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

namespace {

// Shortest and longest exposure a request may ask for (seconds): beyond these no
// camera a projector rig uses has a setting, and a typo should not hold the camera.
constexpr double kMinExposure = 1e-6, kMaxExposure = 10.0;

// The snapshot's file name: the device name with anything but [A-Za-z0-9._-] as '_'
// (names come from the configuration and from udev), never a hidden file.
std::string snapshotFileName(const std::string& camera) {
  std::string out;
  for (char c : camera) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                       c == '.' || c == '_' || c == '-';
    out += plain ? c : '_';
  }
  if (out.empty() || out.front() == '.') out.insert(out.begin(), '_');
  return out + ".png";
}

json settingsJson(const std::optional<procam_camera_settings>& s) {
  auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  if (!s) return {{"exposure_s", nullptr}, {"gain", nullptr}, {"gain_unit", nullptr}};
  return {{"exposure_s", number(s->exposure_s)},
          {"gain", number(s->gain)},
          {"gain_unit", std::isfinite(s->gain) ? json(s->gain_db ? "dB" : "device") : json()}};
}

}  // namespace

void Daemon::cmdSnapshot(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "camera", "exposure_s");
  const std::optional<std::string> name = args.string("camera");
  std::optional<double> exposure;
  if (const json* e = args.get("exposure_s")) {
    if (!e->is_number() ||
        !(e->get<double>() >= kMinExposure && e->get<double>() <= kMaxExposure)) {
      args.setError("exposure_s must be a number of seconds in [1e-6, 10]");
    } else {
      exposure = e->get<double>();
    }
  }
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  if (!calibration_.op.empty()) {
    return errorTo(client, req, code::kBusy, calibration_.op + " holds the devices; try again");
  }
  const DeviceEntry* cam = name ? devices_.find(*name) : devices_.firstUsable(PROCAM_FAMILY_CAMERA);
  if (!cam || !cam->usable() || cam->description.family != PROCAM_FAMILY_CAMERA) {
    return errorTo(client, req, code::kUnavailable,
                   name ? "no usable camera named '" + *name + "'" : "no usable camera");
  }
  if (refuseOverJobLimit(client, req)) return;
  const CalibrationDevice camera{cam->name, cam->device.share()};
  const std::string op_id = "snapshot-" + std::to_string(next_operation_++);
  const ReadFence fence = device_manager_->readFence({camera.name});
  beginCalibrationOp(op_id, {camera.name});
  server_->hold(client);  // the reply comes from the worker; answerFailure releases too
  const std::string dir = options_.state_dir + "/snapshots";
  compute_worker_->submit(
      [this, client, req, camera, exposure, fence, dir] {
        fence.wait();
        auto shot = takeSnapshot(camera, exposure);
        // The file is written here too: an fsync must not stall the loop.
        Result<void> written;
        const StateFile file(dir, snapshotFileName(camera.name), nullptr);
        if (shot) {
          written = file.ensureDirectory();
          if (written) {
            written = file.write(std::string_view(reinterpret_cast<const char*>(shot->png.data()),
                                                  shot->png.size()));
          }
        }
        return [this, client, req, camera, shot, written, path = file.path()] {
          calibration_.op.clear();
          server_->release(client);
          if (!shot) {
            logWarning("snapshot of '" + camera.name + "': " + shot.error().message);
            errorTo(client, req, shot.error().code, shot.error().message);
            if (closesDevice(shot.error().rc)) {
              device_manager_->report(shot.error().device, shot.error().rc, shot.error().message);
            }
            return;
          }
          if (!written) return errorTo(client, req, code::kIo, written.error().message);
          json reply = settingsJson(shot->settings);
          reply.update({{"camera", camera.name},
                        {"width", shot->width},
                        {"height", shot->height},
                        {"format", camera::toString(shot->format)},
                        {"timestamp_ns", shot->timestamp_ns},
                        {"saturated_pct", shot->levels.saturated_pct},
                        {"underexposed_pct", shot->levels.underexposed_pct},
                        {"mean_pct", shot->levels.mean_pct},
                        {"path", path},
                        {"bytes", shot->png.size()}});
          logInfo("snapshot of '" + camera.name + "' written to " + path);
          replyTo(client, req, "SNAPSHOT", reply);
        };
      },
      [this, client, req](const std::string& what) {
        calibration_.op.clear();
        answerFailure(client, req)(what);
      },
      client);
}

}  // namespace procam::daemon
