// The latency operation (PROTOCOL.md): measures the display-to-capture latency
// of an output seen by cameras on the compute worker (latency_probe.hpp) and
// reports it with the settle frames it implies. It holds the devices as
// calibrate does: one of the two runs at a time.
#include "daemon.hpp"
#include "device_manager.hpp"
#include "latency_probe.hpp"
#include "log.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

namespace {

tl::expected<LatencyPlan, CalibrationFailure> makeLatencyPlan(DeviceSet& devices,
                                                              const LatencyArgs& args) {
  using Failure = CalibrationFailure;
  LatencyPlan plan;
  const DeviceEntry* out =
      args.output.empty() ? devices.firstUsable(PROCAM_FAMILY_OUTPUT) : devices.find(args.output);
  if (!out || !out->usable() || out->description.family != PROCAM_FAMILY_OUTPUT) {
    return tl::unexpected(Failure{
        code::kUnavailable, args.output.empty() ? "the latency measurement needs a projector output"
                                                : "no usable output named '" + args.output + "'"});
  }
  const auto& raw = out->device.raw();
  if (raw.ops.output->get_mode(raw.self, &plan.width, &plan.height, &plan.refresh_hz) !=
          PROCAM_OK ||
      plan.width < 1 || plan.height < 1) {
    return tl::unexpected(Failure{code::kUnavailable, "output '" + out->name + "' has no mode"});
  }
  if (!(plan.refresh_hz > 0)) plan.refresh_hz = 60;
  plan.output = {out->name, out->device.share()};
  for (const auto& e : devices.entries()) {
    if (e.description.family != PROCAM_FAMILY_CAMERA || !e.usable()) continue;
    if (args.cameras.empty() ||
        std::find(args.cameras.begin(), args.cameras.end(), e.name) != args.cameras.end()) {
      plan.cameras.push_back({e.name, e.device.share()});
    }
  }
  for (const auto& name : args.cameras) {
    const bool found = std::any_of(plan.cameras.begin(), plan.cameras.end(),
                                   [&](const CalibrationDevice& c) { return c.name == name; });
    if (!found) {
      return tl::unexpected(Failure{code::kUnavailable, "no usable camera named '" + name + "'"});
    }
  }
  if (plan.cameras.empty()) {
    return tl::unexpected(
        Failure{code::kUnavailable, "the latency measurement needs a camera that sees the output"});
  }
  plan.repeats = args.repeats;
  plan.timeout_s = args.timeout_s;
  plan.margin_frames = args.margin_frames;
  return plan;
}

}  // namespace

void Daemon::cmdLatency(ClientId client, const proto::Request& req) {
  auto args = parseLatencyArgs(req.body, config_.calibration);
  if (!args) return errorTo(client, req, code::kBadArgument, args.error());
  if (!calibration_.op.empty()) {
    return errorTo(client, req, code::kBusy,
                   "calibration " + calibration_.op + " is running; wait for it or cancel it");
  }
  auto made = makeLatencyPlan(devices_, *args);
  if (!made) return errorTo(client, req, made.error().code, made.error().message);
  auto plan = std::make_shared<const LatencyPlan>(std::move(*made));

  const std::string op_id = "op-" + std::to_string(next_operation_++);
  auto cancelled = std::make_shared<std::atomic<bool>>(false);
  operations_[op_id] = Operation{"latency", client, req.id, cancelled};
  std::vector<std::string> used{plan->output.name};
  json cameras = json::array();
  for (const auto& c : plan->cameras) {
    used.push_back(c.name);
    cameras.push_back(c.name);
  }
  // The gate closes here; a read the device manager has running on one of
  // these devices ends before the worker's first driver call (read_fence.hpp).
  const ReadFence fence = device_manager_->readFence(used);
  beginCalibrationOp(op_id, std::move(used));
  server_->hold(client);
  replyTo(client, req, "LATENCY",
          {{"operation", op_id},
           {"state", "started"},
           {"output", plan->output.name},
           {"cameras", cameras},
           {"repeats", plan->repeats}});
  logInfo("latency " + op_id + ": output '" + plan->output.name + "', " +
          std::to_string(plan->cameras.size()) + " camera(s)");
  auto progress = [op_id](const CalibrationProgress& p) {
    return json{
        {"operation", op_id}, {"kind", "latency"}, {"fraction", p.fraction}, {"stage", p.stage}};
  };
  operationEvent(client, "progress", progress({0, "starting", 0}));

  const CalibrationHooks hooks = operationHooks(client, op_id, cancelled, progress);
  compute_worker_->submit(
      [this, client, req, op_id, cancelled, plan, hooks, fence] {
        fence.wait();
        auto result = runLatencyProbe(*plan, hooks);
        return [this, client, req, op_id, cancelled, plan, result] {
          if (!result || cancelled->load()) {
            const CalibrationFailure f =
                stoppedRun(result ? nullptr : &result.error(), "latency measurement cancelled");
            endDeviceOp(client, req, op_id, "latency", "LATENCY", {}, &f);
          } else {
            json reply = latencyJson(*result, *plan);
            reply["operation"] = op_id;
            reply["state"] = "done";
            logInfo("latency " + op_id + ": " + std::to_string(result->latency_s) + " s, settle " +
                    std::to_string(result->settle_frames) + " frames");
            endDeviceOp(client, req, op_id, "latency", "LATENCY", reply, nullptr);
          }
          refreshOutputs();  // what the output showed before the black and white frames
        };
      },
      [this, client, req, op_id](const std::string& what) {
        const CalibrationFailure f{code::kInternal, "the job failed: " + what};
        endDeviceOp(client, req, op_id, "latency", "LATENCY", {}, &f);
        refreshOutputs();
      },
      client);
}

}  // namespace procam::daemon
