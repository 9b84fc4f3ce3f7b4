// The calibrate-camera operation (PROTOCOL.md): a camera's intrinsics from a board
// the installer moves in front of it, on the compute worker while the camera is held
// from the device manager's reads (as calibrate holds its cameras); progress after
// every frame; the result merged into rig.json on the I/O worker. `action: "finish"`
// asks a running one to solve with the views it has kept.
#include "camera_calibration_job.hpp"
#include "daemon.hpp"
#include "device_manager.hpp"
#include "log.hpp"
#include "rig_store.hpp"  // utcNow

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

namespace {

json cameraJson(const rig::RigCamera& c) {
  const auto& m = c.model;
  return {{"name", c.name},
          {"width", m.width},
          {"height", m.height},
          {"K", {m.K.fx, m.K.skew, m.K.cx, 0.0, m.K.fy, m.K.cy, 0.0, 0.0, 1.0}},
          {"dist", {m.dist.k1, m.dist.k2, m.dist.p1, m.dist.p2, m.dist.k3}},
          {"pose_known", c.pose_known},
          {"reprojection_rms_px", c.rms_px}};
}

}  // namespace

void Daemon::cmdCalibrateCamera(ClientId client, const proto::Request& req) {
  if (req.body.contains("action") && !req.body["action"].is_string()) {
    return errorTo(client, req, code::kBadArgument,
                   "\"action\" is \"start\" (the default) or \"finish\"");
  }
  if (req.body.value("action", "") == "finish") {
    json finishing = json::array();
    for (auto& [id, op] : operations_) {
      if (op.kind == "calibrate-camera" && op.finish) {
        op.finish->store(true);
        finishing.push_back(id);
      }
    }
    if (finishing.empty()) {
      return errorTo(client, req, code::kNotFound, "no camera calibration is running");
    }
    replyTo(client, req, "CALIBRATE-CAMERA", {{"finishing", finishing}});
    return;
  }
  if (req.body.contains("action") && req.body.value("action", "") != "start") {
    return errorTo(client, req, code::kBadArgument,
                   "\"action\" is \"start\" (the default) or \"finish\"");
  }
  auto args = parseCameraCalibrationArgs(req.body);
  if (!args) return errorTo(client, req, code::kBadArgument, args.error());
  if (!calibration_.op.empty()) {
    return errorTo(client, req, code::kBusy,
                   calibration_.op + " holds the devices; wait for it or cancel it");
  }
  const DeviceEntry* cam = args->camera.empty() ? devices_.firstUsable(PROCAM_FAMILY_CAMERA)
                                                : devices_.find(args->camera);
  if (!cam || !cam->usable() || cam->description.family != PROCAM_FAMILY_CAMERA) {
    return errorTo(client, req, code::kUnavailable,
                   args->camera.empty() ? "no usable camera"
                                        : "no usable camera named '" + args->camera + "'");
  }
  auto plan = std::make_shared<CameraCalibrationPlan>();
  plan->camera = {cam->name, cam->device.share()};
  plan->args = *args;
  plan->finish = std::make_shared<std::atomic<bool>>(false);
  procam_pixel_format format{};
  uint32_t w = 0, h = 0;
  const auto& raw = cam->device.raw();
  if (raw.ops.camera->get_format(raw.self, &w, &h, &format) != PROCAM_OK || w < 16 || h < 16 ||
      w > 16384 || h > 16384) {
    return errorTo(client, req, code::kUnavailable,
                   "camera '" + cam->name + "' reports no usable frame size");
  }
  plan->width = int(w);
  plan->height = int(h);

  const std::string op_id = "op-" + std::to_string(next_operation_++);
  auto cancelled = std::make_shared<std::atomic<bool>>(false);
  operations_[op_id] = Operation{"calibrate-camera", client, req.id, cancelled, plan->finish};
  const ReadFence fence = device_manager_->readFence({plan->camera.name});
  beginCalibrationOp(op_id, {plan->camera.name});
  server_->hold(client);
  replyTo(client, req, "CALIBRATE-CAMERA",
          {{"operation", op_id},
           {"state", "started"},
           {"camera", plan->camera.name},
           {"board", plan->args.board_text},
           {"width", plan->width},
           {"height", plan->height},
           {"targets",
            {{"views", plan->args.views},
             {"coverage", plan->args.coverage},
             {"rms_px", plan->args.rms_px},
             {"timeout_s", plan->args.timeout_s}}}});
  logInfo("calibrate-camera " + op_id + ": camera '" + plan->camera.name + "', board " +
          plan->args.board_text);
  // Progress after every frame: what the installer moves the board by.
  auto on_frame = [this, client, op_id](const CameraCalibrationStatus& s) {
    json body = cameraCalibrationJson(s);
    body["operation"] = op_id;
    body["kind"] = "calibrate-camera";
    loop_->post([this, client, op_id, body = std::move(body)] {
      if (operations_.count(op_id)) operationEvent(client, "views", body);
    });
  };
  auto progress = [op_id](const CalibrationProgress& p) {
    return json{{"operation", op_id},
                {"kind", "calibrate-camera"},
                {"fraction", p.fraction},
                {"stage", p.stage}};
  };
  const CalibrationHooks hooks = operationHooks(client, op_id, cancelled, progress);
  auto end = [this, client, req, op_id](const CalibrationFailure* failure, const json& reply) {
    endDeviceOp(client, req, op_id, "calibrate-camera", "CALIBRATE-CAMERA", reply, failure);
  };
  compute_worker_->submit(
      [this, plan, hooks, on_frame, fence, cancelled, end, op_id] {
        fence.wait();
        auto result = runCameraCalibration(*plan, hooks, on_frame);
        return [this, plan, result, cancelled, end, op_id] {
          if (!result || cancelled->load()) {
            const CalibrationFailure f =
                stoppedRun(result ? nullptr : &result.error(), "camera calibration cancelled");
            return end(&f, {});
          }
          // The camera keeps the pose the rig model has for it (its intrinsics refined);
          // a camera new to the rig has none until a pair calibration gives it one.
          rig::RigCamera camera;
          camera.name = plan->camera.name;
          camera.model = result->calibration.camera;
          camera.model.pose = {};
          camera.pose_known = false;
          if (const rig::RigCamera* known = rig_.camera(camera.name); known && known->pose_known) {
            camera.model.pose = known->model.pose;
            camera.pose_known = true;
          }
          camera.rms_px = result->calibration.rms_px;
          camera.calibrated = {"board views (" + std::to_string(result->status.kept) + ", " +
                                   plan->args.board_text + ")",
                               utcNow()};
          json reply = cameraCalibrationJson(result->status);
          reply.update({{"operation", op_id},
                        {"state", "done"},
                        {"camera", cameraJson(camera)},
                        {"stopped", result->stopped},
                        {"reprojection_rms_px", camera.rms_px}});
          rig::RigModel update;
          update.cameras.push_back(camera);
          // Past cancelling: the result is being written.
          operations_.erase(op_id);
          writeRig(std::move(update), {}, [reply, end](const Result<std::string>& path) mutable {
            if (!path) {
              const CalibrationFailure f{code::kIo, path.error().message};
              return end(&f, {});
            }
            reply["path"] = *path;
            end(nullptr, reply);
          });
        };
      },
      [end](const std::string& what) {
        const CalibrationFailure f{code::kInternal, "the job failed: " + what};
        end(&f, {});
      },
      client);
}

}  // namespace procam::daemon
