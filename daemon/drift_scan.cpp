// recalibrate = "on-drift" when the content's corrections fail their check: the
// projector scanned with structured light, as calibrate scans it (calibration_plan.hpp),
// first a coarse Gray pass, then, when that one's check fails too, the full scan
// (drift_ladder.hpp nextDriftScan). The scan runs as a calibrate operation of its own:
// the outputs' frames wait, a user's calibrate is busy meanwhile and `cancel` stops it.
// Loop thread only; the scan itself on the compute worker.
#include <cmath>

#include "calibration_plan.hpp"
#include "core/units.hpp"
#include "daemon.hpp"
#include "device_manager.hpp"
#include "geometry/intersect.hpp"
#include "log.hpp"
#include "output_draw.hpp"
#include "protocol.hpp"

namespace procam::daemon {

using nlohmann::json;

namespace {

// The coarse pass: Gray code alone (no phase frames), one code per 8 projector pixels and
// nodes every 16. A collineation or a pose needs few, well-spread nodes ([Raskar02]
// §4.2.1); on a 1920x1080 projector this is 34 frames against the full scan's 50, and no
// phase to decode.
constexpr int kCoarseStep = 8;
constexpr int kCoarseGrid = 16;

// When a scan's rig is written: what was kept to restore is now the scan's (the
// projector's, or the devices with the new wall), and the operation ends.
std::function<void(const Result<std::string>&)> whenScanWritten(
    DriftRuntime& d, const std::string& output,
    const std::function<void(const CalibrationFailure*)>& finish) {
  return [&d, output, finish](const Result<std::string>& written) {
    if (!written) {
      const CalibrationFailure f{proto::code::kIo, written.error().message};
      return finish(&f);
    }
    if (auto it = d.outputs.find(output); it != d.outputs.end()) it->second.forgetBefore();
    finish(nullptr);
  };
}

}  // namespace

void Daemon::escalateDrift(const std::string& output, const std::string& camera,
                           const std::string& step, const std::string& why,
                           const drift::Misregistration& m) {
  const auto next = nextDriftScan(drift_rt_.outputs[output].scan, config_.recalibrate);
  if (next) return scanForDrift(output, camera, *next, step + ": " + why, m);
  std::string tail = "; calibrate again";
  if (config_.recalibrate != RecalibratePolicy::kOnDrift) {
    tail += " (recalibrate = \"" + std::string(recalibratePolicyName(config_.recalibrate)) +
            "\" shows no scan)";
  }
  abandonDrift(output, camera, step, why + tail, m);
}

void Daemon::scanForDrift(const std::string& output, const std::string& camera, DriftScan which,
                          const std::string& why, const drift::Misregistration& m, bool surface) {
  DriftRuntime& d = drift_rt_;
  DriftRuntime::Output& o = d.outputs[output];
  const char* step = driftScanName(which);
  const auto giveUp = [&](const std::string& reason) {
    abandonDrift(output, camera, step, reason, m);
  };
  auto args = parseCalibrationArgs(json::object(), config_.calibration);
  if (!args) return giveUp("the scan's settings: " + args.error());
  args->output = output;
  if (which == DriftScan::kCoarse) {
    args->mode = sl::Mode::kGray;
    args->step = kCoarseStep;
    args->grid = kCoarseGrid;
  }
  // The cameras that check the output: two triangulate (route (a)), one takes the rig's
  // plane (route (b′)).
  for (const std::string& c : o.cameras) {
    if (args->cameras.size() < 2) args->cameras.push_back(c);
  }
  args->response = false;
  // Corrections that did not converge are dropped: the scan starts from the devices as
  // a check last confirmed them (the cameras' poses route (a) triangulates with).
  const rig::RigModel base = o.before ? rig::mergeRig(rig_, *o.before) : rig_;
  // One camera measures a wall with the projector as the second view: its pose,
  // intrinsics and metric scale as a check last confirmed them.
  const rig::RigProjector* projector = base.projectorForOutput(output);
  if (surface && args->cameras.size() < 2 &&
      (!projector || !projector->pose_known || !projector->intrinsics_known ||
       !projector->scale_known)) {
    return giveUp(
        "one camera measures the wall with the projector's metric pose, which the rig model "
        "lacks");
  }
  auto made = makeCalibrationPlan(devices_, *args, config_.calibration, base);
  if (!made) return giveUp("the " + std::string(step) + " cannot run: " + made.error().message);
  made->scene_plane = std::make_shared<std::optional<geom::Plane>>(base.surface.plane);
  if (surface) made->known_projector = projector ? projector->model() : geom::CameraModel{};
  auto plan = std::make_shared<const CalibrationPlan>(std::move(*made));
  // Other outputs show black: their light would fall into the captures.
  std::vector<IdleOutput> idle;
  for (auto& e : devices_.entries()) {
    if (e.description.family != PROCAM_FAMILY_OUTPUT || !e.usable() || e.name == output) continue;
    if (auto mode = outputMode(e.device.raw())) {
      idle.push_back({{e.name, e.device.share()}, mode->width, mode->height});
    }
  }
  std::vector<std::string> used{output};
  json cameras = json::array();
  for (const auto& c : plan->cameras) {
    used.push_back(c.device.name);
    cameras.push_back(c.device.name);
  }
  const std::string op_id = "op-" + std::to_string(next_operation_++);
  auto cancelled = std::make_shared<std::atomic<bool>>(false);
  // No client waits for it: its events go to the watchers.
  operations_[op_id] = Operation{"calibrate", 0, nullptr, cancelled};
  const ReadFence fence = device_manager_->readFence(used);
  beginCalibrationOp(op_id, used);
  o.scanning = true;
  o.scan = which;
  const int captures = plan->captures();
  const json started = {{"output", output},
                        {"camera", camera},
                        {"state", "scanning"},
                        {"step", step},
                        {"why", why},
                        {"operation", op_id},
                        {"route", surface          ? "surface"
                                  : plan->planar() ? "b'"
                                                   : "a"},
                        {"measures", surface ? "surface" : "projector"},
                        {"cameras", cameras},
                        {"frames", plan->frames()},
                        {"captures", captures},
                        {"check", misregistrationJson(m)}};
  logInfo("drift: output '" + output + "': " + why + "; " + step + " (" +
          std::to_string(plan->frames()) + " frames, operation " + op_id + ")");
  broadcast("drift", started);
  auto progress = [op_id, captures](const CalibrationProgress& p) {
    return json{{"operation", op_id}, {"kind", "calibrate"},  {"fraction", p.fraction},
                {"stage", p.stage},   {"capture", p.capture}, {"captures", captures}};
  };
  operationEvent(0, "progress", progress({0, "starting", 0}));
  const CalibrationHooks hooks = operationHooks(0, op_id, cancelled, progress);
  const auto started_at = DriftRuntime::Clock::now();
  // The operation ends once its result is written (or it failed): until then a
  // calibrate request is busy and the outputs' frames wait.
  const auto finish = [this, op_id, output](const CalibrationFailure* failure) {
    operations_.erase(op_id);
    calibration_.op.clear();
    if (auto it = drift_rt_.outputs.find(output); it != drift_rt_.outputs.end()) {
      it->second.scanning = false;
    }
    json finished = {{"operation", op_id}, {"kind", "calibrate"}, {"ok", failure == nullptr}};
    if (failure) {
      finished["error"] = failure->message;
      logWarning("calibrate " + op_id + " (drift scan of output '" + output +
                 "'): " + failure->message);
    }
    operationEvent(0, "finished", finished);
    if (failure && closesDevice(failure->rc)) {
      device_manager_->report(failure->device, failure->rc, failure->message);
    }
    refreshOutputs();  // the content again
  };
  compute_worker_->submit(
      [this, plan, idle, hooks, fence, cancelled, output, camera, which, m, finish, started_at,
       surface] {
        fence.wait();
        for (const IdleOutput& i : idle) (void)blankOutput(i);
        auto r = runCalibration(*plan, hooks);
        return [this, plan, r = std::move(r), cancelled, output, camera, which, m, finish,
                started_at, surface] {
          const char* step = driftScanName(which);
          auto it = drift_rt_.outputs.find(output);
          if (!r || cancelled->load()) {
            const CalibrationFailure f = stoppedRun(r ? nullptr : &r.error(), "scan cancelled");
            finish(&f);
            if (it != drift_rt_.outputs.end()) {
              abandonDrift(output, camera, step,
                           "the " + std::string(step) + " failed: " + f.message, m);
            }
            return;
          }
          if (it == drift_rt_.outputs.end()) return finish(nullptr);  // the output went away
          DriftRuntime::Output& o = it->second;
          if (surface) return scannedWall(output, camera, which, m, *plan, *r, started_at, finish);
          Learnt learnt = learntFromRun(*plan, *r);
          // The scan measures the geometry of the rig's projector for this output: it keeps
          // that one's name, tilt mount and photometric record.
          const rig::RigProjector* old = rig_.projectorForOutput(output);
          std::string name = output;
          for (rig::RigProjector& p : learnt.update.projectors) {
            p.calibrated.method =
                "drift correction, " + std::string(step) + ": " + p.calibrated.method;
            if (!old) continue;
            if (auto mesh = learnt.update.surface.meshes.extract(p.name)) {
              mesh.key() = old->name;
              learnt.update.surface.meshes.insert(std::move(mesh));
            }
            p.name = name = old->name;
            p.tilt = old->tilt;
            if (p.photometric.is_null()) p.photometric = old->photometric;
          }
          // The devices as a check last confirmed them, the projector as scanned.
          rig::RigModel update =
              o.before ? rig::mergeRig(*o.before, learnt.update) : std::move(learnt.update);
          json event = {{"output", output},
                        {"projector", name},
                        {"step", step},
                        {"scan_s", secondsSince(started_at)},
                        {"frames", plan->frames()},
                        {"decoded", r->decoded},
                        {"learnt", learnt.reply}};
          event["learnt"].erase("projector");  // rig.json has it
          logInfo("drift: output '" + output + "': the " + step + " measured the projector (" +
                  std::to_string(plan->frames()) + " frames, " +
                  std::to_string(secondsSince(started_at)) + " s)");
          // Mesh files the corrections rewrote go back with the devices they belong to,
          // unless the scan wrote them.
          std::map<std::string, std::string> meshes = std::move(learnt.meshes);
          for (const auto& [file, text] : o.before_meshes) meshes.emplace(file, text);
          writeDriftCorrection(output, std::move(update), std::move(event), "corrected-scan",
                               std::move(meshes), whenScanWritten(drift_rt_, output, finish));
        };
      },
      [this, output, camera, which, m, finish](const std::string& what) {
        const CalibrationFailure f{proto::code::kInternal, "the scan failed: " + what};
        finish(&f);
        if (drift_rt_.outputs.count(output)) {
          abandonDrift(output, camera, driftScanName(which), f.message, m);
        }
      });
}

void Daemon::scannedWall(const std::string& output, const std::string& camera, DriftScan which,
                         const drift::Misregistration& m, const CalibrationPlan& plan,
                         const CalibrationOutcome& r, DriftRuntime::Clock::time_point started_at,
                         const std::function<void(const CalibrationFailure*)>& finish) {
  const char* step = driftScanName(which);
  const std::string by = plan.cameras.size() > 1
                             ? "cameras '" + plan.cameras[0].device.name + "' and '" +
                                   plan.cameras[1].device.name + "'"
                             : "the projector and camera '" + plan.cameras[0].device.name + "'";
  const auto failed = [&](const std::string& why) {
    const CalibrationFailure f{proto::code::kFailed, why};
    finish(&f);
    abandonDrift(output, camera, step, why, m);
  };
  if (!r.triangulated_plane) return failed("internal: the " + std::string(step) + " gave no wall");
  const geom::PlaneFit& fit = *r.triangulated_plane;
  // The devices as a check last confirmed them (the scan's cameras and projector): what
  // corrections that did not converge changed goes back with the new wall.
  auto it = drift_rt_.outputs.find(output);
  const std::optional<rig::RigModel> before =
      it != drift_rt_.outputs.end() ? it->second.before : std::nullopt;
  const rig::RigModel base = before ? rig::mergeRig(rig_, *before) : rig_;
  auto made = wallUpdate(base, fit.plane, fit.rms);
  if (!made) return failed(made.error().message + "; calibrate again");
  rig::RigModel update = before ? rig::mergeRig(*before, *made) : std::move(*made);
  // How far the wall moved where the projector's optical axis meets it, and how far it
  // turned.
  json event = {{"output", output},
                {"step", step},
                {"measured", "surface"},
                {"triangulated_by", by},
                {"points", fit.inliers.size()},
                {"plane_rms_mm", 1e3 * fit.rms},
                {"scan_s", secondsSince(started_at)},
                {"frames", plan.frames()},
                {"decoded", r.decoded}};
  double offset_m = 0, turned_deg = 0;
  const rig::RigProjector* p = base.projectorForOutput(output);
  if (p && p->pose_known && rig_.surface.plane) {
    const geom::Plane& old = *rig_.surface.plane;
    const geom::Ray axis{p->model().pose.center(), p->model().pose.R.row(2).transpose()};
    if (auto hit = geom::intersectPlane(axis, fit.plane)) {
      offset_m = old.signedDistance(hit->point);
      event["wall_offset_mm"] = 1e3 * offset_m;
    }
    turned_deg = radToDeg(std::acos(std::min(1.0, std::abs(old.n.dot(fit.plane.n)))));
    event["wall_turned_deg"] = turned_deg;
  }
  logInfo("drift: output '" + output + "': the " + step + " measured the wall again (" +
          std::to_string(fit.inliers.size()) + " nodes triangulated by " + by + ", " +
          std::to_string(1e3 * offset_m) + " mm from the rig's, turned " +
          std::to_string(turned_deg) + " deg; " + std::to_string(secondsSince(started_at)) + " s)");
  std::map<std::string, std::string> meshes;
  if (it != drift_rt_.outputs.end()) meshes = it->second.before_meshes;
  writeDriftCorrection(output, std::move(update), std::move(event), "corrected-scan",
                       std::move(meshes), whenScanWritten(drift_rt_, output, finish));
}

}  // namespace procam::daemon
