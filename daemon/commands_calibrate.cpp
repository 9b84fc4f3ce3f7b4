// The calibrate operation (PROTOCOL.md): chooses the devices and the route, runs
// the structured-light capture and route (a) or (b′) on the compute worker, and
// writes what it learnt into the rig model (rig_store.hpp): the projector bound to
// the output, and its surface (a plane, or a mesh file for a non-planar surface).
#include <algorithm>

#include "calibration_job.hpp"
#include "calibration_plan.hpp"
#include "daemon.hpp"
#include "device_manager.hpp"
#include "log.hpp"
#include "rig_store.hpp"
#include "surface/surface_model.hpp"
#include "unify_run.hpp"
#include "wall_views_run.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;
using Failure = CalibrationFailure;

CalibrationFailure Daemon::stoppedRun(const CalibrationFailure* error,
                                      const char* cancelled) const {
  CalibrationFailure f = error ? *error : CalibrationFailure{code::kCancelled, cancelled};
  if (f.code == code::kCancelled && !calibration_.removed.empty()) f.message = calibration_.removed;
  return f;
}

void Daemon::endDeviceOp(ClientId client, const proto::Request& req, const std::string& op_id,
                         const char* kind, const char* reply_class, const json& reply,
                         const CalibrationFailure* failure) {
  operations_.erase(op_id);
  calibration_.op.clear();
  json finished = {{"operation", op_id}, {"kind", kind}, {"ok", failure == nullptr}};
  if (failure) {
    finished["error"] = failure->message;
    logWarning(std::string(kind) + " " + op_id + ": " + failure->message);
    errorTo(client, req, failure->code, failure->message);
  } else {
    replyTo(client, req, reply_class, reply);
  }
  operationEvent(client, "finished", finished);
  server_->release(client);  // after the reply: a half-closed client may close now
  // The device manager closes a lost device and retries it (or an ended one).
  if (failure && closesDevice(failure->rc)) {
    device_manager_->report(failure->device, failure->rc, failure->message);
  }
}

void Daemon::writeRig(rig::RigModel update, std::map<std::string, std::string> meshes,
                      std::function<void(const Result<std::string>&)> done) {
  io_worker_->submit(
      [this, dir = options_.state_dir, update = std::move(update), meshes = std::move(meshes),
       done] {
        auto merged = mergeIntoRig(dir, update, meshes);
        return [this, merged, done, path = rigStateFile(dir).path()] {
          if (!merged) {
            return done(fail(ErrorCode::kIo, "rig.json not written: " + merged.error().message));
          }
          rig_ = *merged;
          logInfo("rig model written to " + path);
          // The new rig's meshes are read before `done` can redraw: a display solved now
          // would pair the new poses with the old meshes, and be solved again once they
          // are read.
          onRigChanged();
          done(path);
        };
      },
      [done](const std::string& what) {
        done(fail(ErrorCode::kIo, "rig.json not written: " + what));
      });
}

void Daemon::beginCalibrationOp(const std::string& op_id, std::vector<std::string> devices) {
  calibration_ = {op_id, std::move(devices), "", calibration_.hooked};
  if (!calibration_.hooked) {
    // A device the run uses was unplugged or lost: stop between two frames.
    device_manager_->onDeviceRemoved([this](const DeviceEntry& e) {
      const auto& used = calibration_.devices;
      if (calibration_.op.empty() || std::find(used.begin(), used.end(), e.name) == used.end()) {
        return;
      }
      if (auto it = operations_.find(calibration_.op); it != operations_.end()) {
        calibration_.removed =
            "calibration cancelled: " + std::string(plugins::familyName(e.description.family)) +
            " '" + e.name + "' went away" + (e.error.empty() ? "" : " (" + e.error + ")");
        it->second.cancelled->store(true);
      }
    });
    calibration_.hooked = true;
  }
}

CalibrationHooks Daemon::operationHooks(ClientId client, const std::string& op_id,
                                        std::shared_ptr<std::atomic<bool>> cancelled,
                                        std::function<json(const CalibrationProgress&)> progress) {
  CalibrationHooks hooks;
  hooks.cancelled = [cancelled] { return cancelled->load(); };
  hooks.progress = [this, client, op_id, progress](const CalibrationProgress& p) {
    loop_->post([this, client, op_id, body = progress(p)] {
      if (operations_.count(op_id)) operationEvent(client, "progress", body);
    });
  };
  return hooks;
}

void Daemon::cmdCalibrate(ClientId client, const proto::Request& req) {
  auto args = parseCalibrationArgs(req.body, config_.calibration);
  if (!args) return errorTo(client, req, code::kBadArgument, args.error());
  if (!calibration_.op.empty()) {
    return errorTo(client, req, code::kBusy,
                   "calibration " + calibration_.op + " is running; wait for it or cancel it");
  }
  // One plan per projector: `projectors` one after the other (same cameras, one rig
  // model written once at the end), else `output` alone.
  std::vector<std::string> outputs = args->outputs;
  if (args->all_outputs) {
    for (const auto& e : devices_.entries()) {
      if (e.description.family == PROCAM_FAMILY_OUTPUT && e.usable()) outputs.push_back(e.name);
    }
    if (outputs.empty()) {
      return errorTo(client, req, code::kUnavailable, "calibration needs a projector output");
    }
  }
  if (outputs.empty()) outputs.push_back(args->output);
  if (args->board && outputs.size() > 1) {
    // Each projector's run would find the board again, lit by that projector alone.
    return errorTo(client, req, code::kBadArgument,
                   "\"board\" finds the plane for one projector: calibrate one projector with it "
                   "(the plane goes into the rig model), then the others without it");
  }
  std::vector<std::shared_ptr<const CalibrationPlan>> plans;
  // Projectors on one planar wall must share its plane (the tiled display joins them on
  // it): the first one triangulated, or the rig's when the new nodes lie on it.
  auto scene_plane = std::make_shared<std::optional<geom::Plane>>(rig_.surface.plane);
  for (const std::string& output : outputs) {
    CalibrationArgs one = *args;
    one.output = output;
    // Several projectors are blended: measure their responses unless told not to.
    if (!one.response && (outputs.size() > 1 || !args->outputs.empty() || args->all_outputs)) {
      one.response = true;
    }
    auto made = makeCalibrationPlan(devices_, one, config_.calibration, rig_);
    if (!made) return errorTo(client, req, made.error().code, made.error().message);
    made->scene_plane = scene_plane;
    plans.push_back(std::make_shared<const CalibrationPlan>(std::move(*made)));
  }
  const auto& plan = plans.front();
  // Every other usable output shows black during the scans: its light would fall into
  // the captures where it overlaps a scanned projector.
  std::vector<IdleOutput> idle;
  for (auto& e : devices_.entries()) {
    if (e.description.family != PROCAM_FAMILY_OUTPUT || !e.usable()) continue;
    const bool scanned = std::any_of(plans.begin(), plans.end(),
                                     [&](const auto& p) { return p->output.name == e.name; });
    if (scanned) continue;
    if (auto mode = outputMode(e.device.raw())) {
      idle.push_back({{e.name, e.device.share()}, mode->width, mode->height});
    }
  }

  const std::string op_id = "op-" + std::to_string(next_operation_++);
  auto cancelled = std::make_shared<std::atomic<bool>>(false);
  operations_[op_id] = Operation{"calibrate", client, req.id, cancelled};
  std::vector<std::string> used;
  json output_names = json::array();
  int captures = 0;
  std::vector<const CalibrationPlan*> all;  // the plans, kept alive by `plans`
  for (const auto& p : plans) {
    used.push_back(p->output.name);
    output_names.push_back(p->output.name);
    captures += p->captures();
    all.push_back(p.get());
  }
  // The coarse pass that finds which projectors can be scanned together, when any can.
  const bool batching = plans.size() > 1 && mayBatch(all);
  if (batching) captures += static_cast<int>((plans.size() + 1) * plans.front()->cameras.size());
  for (const auto& c : plan->cameras) used.push_back(c.device.name);
  // The gate closes here; a read the device manager has running on one of
  // these devices ends before the worker's first driver call (read_fence.hpp).
  const ReadFence fence = device_manager_->readFence(used);
  beginCalibrationOp(op_id, std::move(used));
  server_->hold(client);
  json cameras = json::array();
  for (const auto& c : plan->cameras) cameras.push_back(c.device.name);
  json started = {{"operation", op_id},
                  {"state", "started"},
                  {"output", plan->output.name},
                  {"cameras", cameras},
                  {"route", plan->planar() ? "b'" : "a"},
                  {"mode", plan->coarse ? std::string("adaptive")
                           : plan->tags ? std::string("apriltag")
                                        : std::string(sl::toString(plan->set.options.mode))},
                  {"frames", plan->frames()},
                  {"captures", captures},
                  {"settle_frames", plan->auto_settle ? json("auto") : json(plan->settle_frames)}};
  if (plans.size() > 1 || !args->outputs.empty() || args->all_outputs) {
    started["outputs"] = output_names;
  }
  replyTo(client, req, "CALIBRATE", started);
  logInfo("calibration " + op_id + ": " + std::to_string(plan->frames()) + " pattern frame(s) on " +
          output_names.dump());
  // An adaptive scan that goes on to the full set says how many captures the run now takes.
  auto progress = [op_id, captures](const CalibrationProgress& p) {
    return json{{"operation", op_id},     {"kind", "calibrate"},
                {"fraction", p.fraction}, {"stage", p.stage},
                {"capture", p.capture},   {"captures", p.captures > 0 ? p.captures : captures}};
  };
  operationEvent(client, "progress", progress({0, "starting", 0}));

  const CalibrationHooks hooks = operationHooks(client, op_id, cancelled, progress);
  using Outcomes = tl::expected<std::vector<CalibrationOutcome>, Failure>;
  compute_worker_->submit(
      [this, client, req, op_id, cancelled, plans, all, idle, progress, hooks, fence, captures,
       batching] {
        fence.wait();
        // The projectors one after the other; progress over the whole run.
        Outcomes result = std::vector<CalibrationOutcome>{};
        // An output that cannot show black is left as it is (the device manager hears of
        // it from its own checks); the scan goes on.
        for (const IdleOutput& o : idle) (void)blankOutput(o);
        // Projectors of the run that are not being scanned show black: their light would
        // fall into the overlaps of the one that is.
        if (plans.size() > 1) {
          for (const auto& p : plans) {
            if (auto ok = blankOutput(*p); !ok && result) result = tl::unexpected(ok.error());
          }
        }
        // Which projectors light disjoint parts of the cameras' views and can be scanned
        // together (calibration_job.hpp planScanBatches); one at a time otherwise.
        ScanBatches scan;
        if (batching && result) {
          // Its progress: a share of the run's captures.
          const CalibrationHooks coarse{
              hooks.cancelled, [&](const CalibrationProgress& p) {
                hooks.progress({double(p.capture) / captures, p.stage, p.capture});
              }};
          auto planned = planScanBatches(all, coarse);
          if (planned) {
            scan = std::move(*planned);
          } else {
            result = tl::unexpected(planned.error());
          }
        } else {
          for (std::size_t i = 0; i < plans.size(); ++i) scan.batches.push_back({i});
        }
        int done = scan.captures;
        int grown = 0;  // captures the run took beyond those planned (adaptive scans)
        double shown_fraction = 0;
        std::vector<std::optional<CalibrationOutcome>> by_plan(plans.size());
        for (std::size_t b = 0; b < scan.batches.size() && result; ++b) {
          const std::vector<std::size_t>& batch = scan.batches[b];
          std::vector<const CalibrationPlan*> members;
          std::vector<std::vector<cv::Mat>> footprints;
          std::string names;
          for (std::size_t i : batch) {
            members.push_back(plans[i].get());
            if (batch.size() > 1) footprints.push_back(scan.footprints[i]);
            names += (names.empty() ? "'" : ", '") + plans[i]->output.name + "'";
          }
          const int batch_captures = members.front()->captures();
          int batch_grown = 0;
          CalibrationHooks one{
              hooks.cancelled, [&, done, batch_captures](const CalibrationProgress& p) {
                if (p.captures > 0) batch_grown = std::max(0, p.captures - batch_captures);
                // The batch's share of the run's captures, grown when an adaptive scan
                // went on to the full set; the fraction never goes back.
                const int total = captures + grown + batch_grown;
                const double f =
                    (double(done) + double(batch_captures + batch_grown) * p.fraction) /
                    std::max(1, total);
                shown_fraction = std::max(shown_fraction, std::min(0.97, f));
                hooks.progress({shown_fraction, p.stage, done + p.capture,
                                grown + batch_grown > 0 ? total : 0});
              }};
          auto r = runBatchCalibration(members, footprints, one);
          if (!r) {
            Failure f = r.error();
            if (plans.size() > 1) f.message = "output " + names + ": " + f.message;
            result = tl::unexpected(f);
          } else {
            for (std::size_t k = 0; k < batch.size(); ++k) by_plan[batch[k]] = std::move((*r)[k]);
            if (plans.size() > 1) {
              for (const CalibrationPlan* m : members) {
                if (auto ok = blankOutput(*m); !ok) result = tl::unexpected(ok.error());
              }
            }
          }
          done += batch_captures + batch_grown;
          grown += batch_grown;
        }
        if (result) {
          for (auto& o : by_plan) result->push_back(std::move(*o));
        }
        // Cameras at several positions: every projector scanned, all solved at once.
        json wall;
        if (result && !cancelled->load() && plans.front()->wallViews()) {
          hooks.progress({0.97, "solving", done, grown > 0 ? captures + grown : 0});
          auto solved = solveWallViewsRun(all, *result);
          if (solved) {
            wall = wallViewsJson(*solved, all);
          } else {
            result = tl::unexpected(solved.error());
          }
        }
        // Route (a) over several projectors: their meshes agree where they overlap.
        json unified;
        if (result && !cancelled->load() && plans.size() > 1) {
          // A failure keeps the meshes as triangulated: the run is not lost for it.
          auto made = unifyRunMeshes(all, *result);
          unified = made ? std::move(*made) : json{{"skipped", made.error().message}};
        }
        json batches = json::array();
        for (const auto& batch : scan.batches) {
          json names = json::array();
          for (std::size_t i : batch) names.push_back(plans[i]->output.name);
          batches.push_back(std::move(names));
        }
        const json scanned = {{"batches", std::move(batches)}, {"captures", done}};
        const int taken = captures + grown;
        return [this, client, req, op_id, cancelled, plans, result, progress, captures, taken,
                scanned, wall, unified] {
          auto finish = [this, client, req, op_id](const json& reply, const Failure* failure) {
            endDeviceOp(client, req, op_id, "calibrate", "CALIBRATE", reply, failure);
            refreshOutputs();  // what the outputs showed before the pattern frames
          };
          if (!result || cancelled->load()) {
            const Failure f =
                stoppedRun(result ? nullptr : &result.error(), "calibration cancelled");
            return finish({}, &f);
          }
          // From here on the result is written: a cancel no longer finds the operation.
          operations_.erase(op_id);
          operationEvent(client, "progress",
                         progress({0.98, "writing", taken, taken != captures ? taken : 0}));
          // Every projector's part merged into one update, written once: all or nothing.
          rig::RigModel update;
          std::map<std::string, std::string> meshes;
          json reply, per_output = json::array();
          for (std::size_t i = 0; i < plans.size(); ++i) {
            const CalibrationOutcome& outcome = (*result)[i];
            Learnt learnt = learntFromRun(*plans[i], outcome);
            update = rig::mergeRig(std::move(update), learnt.update);
            meshes.merge(learnt.meshes);
            learnt.reply["output"] = plans[i]->output.name;
            learnt.reply["decoded"] = outcome.decoded;
            learnt.reply["settle_frames"] = outcome.settle_frames;
            if (!outcome.latency.is_null()) learnt.reply["latency"] = outcome.latency;
            if (i == 0) reply = learnt.reply;
            per_output.push_back(std::move(learnt.reply));
          }
          if (plans.size() > 1) {
            reply["outputs"] = per_output;
            reply["scan"] = scanned;
          }
          if (!wall.is_null()) reply["wall"] = wall;
          if (!unified.is_null()) reply["unified"] = unified;
          reply["operation"] = op_id;
          reply["state"] = "done";
          writeRig(std::move(update), std::move(meshes),
                   [this, reply, finish](const Result<std::string>& path) mutable {
                     if (!path) {
                       const Failure f{code::kIo, path.error().message};
                       return finish({}, &f);
                     }
                     reply["path"] = *path;
                     reply["rig"] = {{"cameras", rig_.cameras.size()},
                                     {"projectors", rig_.projectors.size()}};
                     finish(reply, nullptr);
                   });
        };
      },
      [this, client, req, op_id](const std::string& what) {
        const Failure f{code::kInternal, "the job failed: " + what};
        endDeviceOp(client, req, op_id, "calibrate", "CALIBRATE", {}, &f);
        refreshOutputs();
      },
      client);
}

}  // namespace procam::daemon
