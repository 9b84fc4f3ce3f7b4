// recalibrate = "on-drift" on a fixed rig: while content plays, each output's frame is
// compared with what the rig model says each fixed camera should see of it
// (drift_check.hpp); misregistration held over the threshold for the settle time is
// corrected with the cheapest step, from the content's own correspondences and with no
// pattern shown: a camera that sees drift where another camera sees the output
// registered has moved and gets its pose again (drift/camera_correction.hpp); drift that
// two cameras see and triangulate off the rig's wall, or that one camera sees along its
// epipolar lines with the projector (the rays of both meet off the wall, and the content
// fits no turned projector), is the wall's, whose plane a coarse Gray pass measures again
// (under on-drift-silent the content does, drift/wall_from_views.hpp); other drift that every
// camera sees is the projector's, whose pose and plane collineation are fitted again
// (drift/projector_correction.hpp); the steps themselves are in drift_corrections.cpp.
// Where those fail their check, the projector is scanned: a coarse Gray pass, then the
// full scan (drift_scan.cpp). Loop thread only; the checks run on the compute worker
// between the outputs' frames.
#include <cmath>

#include "blend/rig_tiles.hpp"
#include "daemon.hpp"
#include "log.hpp"
#include "protocol.hpp"
#include "rig_store.hpp"

namespace procam::daemon {

using nlohmann::json;

namespace {

// What a view's fitted blur depends on: the framebuffer (work pixels are half its pixels)
// and the camera's lens (a camera pixel in work pixels).
Vec3 blurKey(const rig::RigProjector& p, const rig::RigCamera& c) {
  return {static_cast<double>(p.width), c.model.K.fx, c.model.K.fy};
}

// Fiducial frames an output may show between two at drift_fiducial_period_s, to confirm
// drift and check corrections: the bump on wall_oblique under grey content took 4 (a
// settle of 0.5 s, one correction); three more passes, room to spare.
constexpr int kQuickFiducials = 12;

// Whether an output's periodic check (a fiducial frame, a stream's held frame) is due:
// `last` at least `period_s` ago or never (`at_period`), or sooner, at every check, while
// drift a camera saw is confirmed or a correction of it checked: at most kQuickFiducials
// (`quick` so far) between two at the period, none while the output is unresolved.
bool periodicCheckDue(const DriftRuntime::Output& o,
                      const std::optional<DriftRuntime::Clock::time_point>& last, int quick,
                      double period_s, bool& at_period) {
  at_period = !last || secondsSince(*last) >= period_s;
  return at_period || (!o.unresolved && (o.drifted() || o.passes > 0) && quick < kQuickFiducials);
}

}  // namespace

void Daemon::setupDriftCheck() {
  DriftRuntime& d = drift_rt_;
  if (d.timer >= 0) {
    loop_->removeTimer(d.timer);
    d.timer = -1;
  }
  if (!watchesDrift(config_.recalibrate)) {
    d.outputs.clear();
    return;
  }
  const auto period = std::chrono::duration<double>(config_.drift.period_s);
  auto timer = loop_->addTimer(std::chrono::duration_cast<std::chrono::nanoseconds>(period), true,
                               [this] { checkDrift(); });
  if (!timer) {
    warn("drift check not started: " + timer.error().message);
    return;
  }
  d.timer = *timer;
}

std::vector<const rig::RigCamera*> Daemon::driftCameras(const Vec3& centre) const {
  // Posed cameras standing on their own (one mounted on a projector moves with it) that
  // are open and see the surface point the centre of the projector's frame lights.
  std::vector<const rig::RigCamera*> out;
  for (const rig::RigCamera& cam : rig_.cameras) {
    if (!cam.pose_known || !cam.attached_to.empty()) continue;
    const DeviceEntry* e = const_cast<DeviceSet&>(devices_).find(cam.name);
    if (!e || e->description.family != PROCAM_FAMILY_CAMERA || !e->usable()) continue;
    auto px = cam.model.project(centre);
    if (px && cam.model.inImage(*px)) out.push_back(&cam);
  }
  return out;
}

bool Daemon::driftMayRun() const {
  const KeystoneRuntime& k = keystone_rt_;
  // Not while an operation holds the devices, the camera yaw's dot grid is shown or a
  // frame is in flight (what the output shows is about to change).
  return watchesDrift(config_.recalibrate) && !calibrating() && calibration_.op.empty() &&
         !k.yaw.measuring && !k.rendering && !k.render_again;
}

bool Daemon::streamPlaying() const {
  return live_content_ && !live_content_->ended;
}

bool Daemon::fiducialFramesOn() const {
  return config_.recalibrate == RecalibratePolicy::kOnDrift && config_.drift.fiducial_period_s > 0;
}

bool Daemon::heldFramesOn() const {
  return config_.recalibrate == RecalibratePolicy::kOnDriftSilent &&
         config_.drift.stream_period_s > 0;
}

void Daemon::checkDrift() {
  DriftRuntime& d = drift_rt_;
  d.check_after_frame = false;
  if (d.checking || d.writing) return;
  if (!driftMayRun()) {
    // A stream's frames follow each other closely: the check goes in after this one.
    const KeystoneRuntime& k = keystone_rt_;
    d.check_after_frame = (k.rendering || k.render_again) && streamPlaying();
    return;
  }
  // One check at a time (the worker also draws the frames), led by the outputs in turn:
  // the lead's camera (its cameras in turn) captures once for every output it sees.
  std::vector<DeviceEntry*> outputs;
  for (auto& e : devices_.entries()) {
    if (e.description.family == PROCAM_FAMILY_OUTPUT && e.usable()) outputs.push_back(&e);
  }
  for (auto it = d.outputs.begin(); it != d.outputs.end();) {
    const bool open = std::any_of(outputs.begin(), outputs.end(),
                                  [&](const DeviceEntry* e) { return e->name == it->first; });
    it = open ? std::next(it) : d.outputs.erase(it);
  }
  if (outputs.empty()) return;
  const std::size_t lead = d.next++ % outputs.size();
  auto first = planDriftCheck(*outputs[lead], nullptr);
  if (!first) return;
  std::vector<DriftCheckPlan> plans;
  std::vector<DriftKey> keys;
  plans.push_back(std::move(first->first));
  keys.push_back(std::move(first->second));
  const bool fiducial = plans[0].fiducial != nullptr;
  for (std::size_t i = 1; i < outputs.size() && !fiducial; ++i) {
    auto more = planDriftCheck(*outputs[(lead + i) % outputs.size()], &keys[0].camera);
    if (!more) continue;
    plans.push_back(std::move(more->first));
    keys.push_back(std::move(more->second));
  }
  // The device manager keeps off the camera while the check drives it.
  d.camera_in_use = keys[0].camera;
  d.checking = true;
  const std::string name = keys[0].output;
  compute_worker_->submit(
      [this, plans = std::move(plans), keys] {
        auto r = runDriftChecks(plans);
        return [this, keys, r = std::move(r)]() mutable {
          DriftRuntime& d = drift_rt_;
          d.checking = false;
          d.camera_in_use.clear();
          for (std::size_t i = 0; i < keys.size(); ++i) {
            // A correction or scan one output's check began changes the rig under the
            // others': theirs wait for the next check.
            if (i > 0 && (d.writing || !calibration_.op.empty())) break;
            onDriftChecked(keys[i], std::move(r[i]));
          }
          endFiducialFrame(keys[0].output);
        };
      },
      [this, name](const std::string& what) {
        drift_rt_.checking = false;
        drift_rt_.camera_in_use.clear();
        warn("drift check of output '" + name + "' failed: " + what);
        endFiducialFrame(name);
      });
}

std::optional<std::pair<DriftCheckPlan, DriftKey>> Daemon::planDriftCheck(
    DeviceEntry& out, const std::string* camera) {
  DriftRuntime& d = drift_rt_;
  KeystoneRuntime& k = keystone_rt_;
  DriftRuntime::Output& o = d.outputs[out.name];
  const auto unavailable = [&](std::string why) {
    o.unavailable = std::move(why);
    o.camera.clear();
    o.forgetDrift();
    return std::nullopt;
  };
  const rig::RigProjector* p = rig_.projectorForOutput(out.name);
  if (!p) return unavailable("the rig model has no projector for the output");
  if (settings_.auto_keystone) {
    return unavailable("auto keystone corrects the projector from its tilt sensor");
  }
  // A stream's frame changes between camera frames: under on-drift its checks are
  // fiducial frames (their own frame, shown for one capture); under on-drift-silent,
  // which shows none, the stream's frame is held on the outputs for a capture now and
  // then and compared as content is.
  const bool streamed = streamPlaying();
  const bool held = streamed && heldFramesOn();
  if (streamed && !fiducialFramesOn() && !held) {
    return unavailable("streamed content: the frame changes between camera frames, and " +
                       std::string(config_.recalibrate == RecalibratePolicy::kOnDrift
                                       ? "fiducial frames are off (drift_fiducial_period_s = 0)"
                                       : "held frames are off (drift_stream_period_s = 0)"));
  }
  if (streamed && !held && !d.fiducial_unavailable.empty()) {
    return unavailable("streamed content: the frame changes between camera frames, and " +
                       d.fiducial_unavailable);
  }
  // The surface the output draws on: a plane, or a mesh (sceneTraits, as the frames).
  const bool curved = sceneTraits(out.name, false).surface == render::SurfaceKind::kNonPlanar;
  Result<blend::DisplayTile> tile = fail(ErrorCode::kNotFound, "a curved surface");
  std::shared_ptr<const RigSurfaceMesh> mesh;
  std::optional<Vec3> centre;
  const Vec2 middle((p->width - 1) / 2.0, (p->height - 1) / 2.0);
  if (curved) {
    if (rig_surfaces_loading_) return std::nullopt;  // the new rig's meshes, not the old
    mesh = rigSurfaceFor(p->name);
    if (!mesh) return unavailable("the rig's surface mesh is not loaded");
    if (!p->pose_known || !p->intrinsics_known) {
      return unavailable("on a surface mesh the projector's pose and intrinsics are needed");
    }
    auto ray = p->model().backproject(middle);
    auto hit = ray ? mesh->intersector.intersect(*ray) : std::nullopt;
    if (hit) centre = hit->point;
  } else {
    tile = blend::displayTile(*p, rig_.surface);
    if (!tile) return unavailable("not mapped onto a display plane: " + tile.error().message);
    const Vec3 c = tile->projector_to_plane.H * middle.homogeneous();
    if (std::abs(c.z()) > 1e-12) centre = tile->projector_to_plane.basis.toWorld(c.hnormalized());
  }
  const auto cams = centre ? driftCameras(*centre) : std::vector<const rig::RigCamera*>{};
  if (cams.empty())
    return unavailable("no open, posed, fixed camera of the rig model sees the frame");
  o.cameras.clear();
  for (const rig::RigCamera* c : cams) o.cameras.push_back(c->name);
  for (auto v = o.views.begin(); v != o.views.end();) {
    const bool sees = std::find(o.cameras.begin(), o.cameras.end(), v->first) != o.cameras.end();
    v = sees ? std::next(v) : o.views.erase(v);
  }
  const rig::RigCamera* cam = nullptr;
  if (camera) {
    // Another output's check captures with this camera: this one's is measured too
    // where the camera sees it.
    for (const rig::RigCamera* c : cams) {
      if (c->name == *camera) cam = c;
    }
    if (!cam) return std::nullopt;
  } else {
    // The camera that looked at it longest ago (one never looked first): the output's
    // cameras in turn whichever outputs lead and which cameras their checks took, so a
    // drift one camera saw is confirmed or told apart by another's check soon after.
    for (const rig::RigCamera* c : cams) {
      auto v = o.views.find(c->name);
      if (v == o.views.end()) {
        cam = c;
        break;
      }
      if (!cam || v->second.checked_at < o.views.at(cam->name).checked_at) cam = c;
    }
  }
  auto st = k.output_state.find(out.name);
  if (st == k.output_state.end() || !st->second.shown_image || !st->second.shown_setup) {
    return unavailable("nothing shown yet");
  }
  if (camera) {
    // Measured in another output's capture: not when this camera found the frame too
    // plain at its last look (a too plain result clears the drift its fiducial frames
    // saw), nor a stream's; its own checks with this camera look again.
    if (streamed || o.views[cam->name].foundPlain(st->second.shown_setup, st->second.shown_image)) {
      return std::nullopt;
    }
  }
  // The camera must see the frame drawn, not the one before it: a frame's latency to
  // the camera is a few output frames ([calibration] settle_frames, as calibrate waits).
  // A fiducial frame over a stream waits as long after it is shown.
  const double settle = std::max(0.1, (config_.calibration.settle_frames + 2) / 60.0);
  if (!streamed && secondsSince(st->second.shown_at) < settle) return std::nullopt;
  // Nor the fiducial frame a check showed before the content came back.
  if (o.fiducial_at && secondsSince(*o.fiducial_at) < settle) return std::nullopt;
  o.unavailable.clear();
  DeviceEntry* cam_entry = devices_.find(cam->name);
  // No fiducial frame for an output measured in another's capture.
  const bool fiducial =
      !camera && fiducialDue(o, o.views[cam->name], st->second, {p->width, p->height});
  // A stream is checked by the next fiducial frame, or in its turn by a held frame.
  if (streamed && !fiducial && !(held && holdDue(o))) return std::nullopt;
  DriftCheckPlan plan;
  plan.output = out.name;
  plan.camera = {cam->name, cam_entry->device.share()};
  DriftRuntime::View& view = o.views[cam->name];
  plan.reference = view.reference;
  // A blur fitted for another framebuffer or camera lens is fitted again.
  if (view.blur_for != blurKey(*p, *cam)) view.reference_blur.reset();
  plan.reference_blur = view.reference_blur;
  // A frame a fit already found too little in is measured sharp, not fitted every check.
  if (!plan.reference_blur && view.blur_tried.is(st->second.shown_setup, st->second.shown_image)) {
    plan.reference_blur = 0.0;
  }
  plan.setup = st->second.shown_setup;
  plan.image = st->second.shown_image;
  plan.rig_generation = rig_generation_;
  plan.framebuffer = {p->width, p->height};
  if (mesh) {
    plan.surface_mesh = std::shared_ptr<const geom::MeshIntersector>(mesh, &mesh->intersector);
    plan.projector_model = p->model();
    plan.own_mesh = rig_surfaces_.count(p->name) > 0;
  } else {
    plan.projector_to_plane = tile->projector_to_plane;
  }
  plan.camera_model = cam->model;
  if (auto response = blend::projectorResponse(*p)) plan.projector_gamma = response->gamma;
  plan.frames = config_.drift.frames;
  if (held) {
    // Held from now: the worker draws no frame while the check runs.
    plan.hold_until =
        st->second.shown_at + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                  std::chrono::duration<double>(settle));
  }
  if (fiducial) {
    // The frames wait while the fiducial frame is up (refreshOutputs).
    plan.fiducial = d.fiducial.at({p->width, p->height});
    plan.output_device = {out.name, out.device.share()};
    plan.settle_s = settle;
    d.fiducial_showing = true;
  }
  plan.fence = device_manager_->readFence({cam->name});
  DriftKey key{out.name,
               cam->name,
               plan.setup,
               plan.image,
               st->second.shown_at,
               rig_generation_,
               plan.hold_until.has_value()};
  return std::make_pair(std::move(plan), std::move(key));
}

bool Daemon::fiducialDue(DriftRuntime::Output& o, const DriftRuntime::View& view,
                         const KeystoneRuntime::OutputState& shown, cv::Size framebuffer) {
  DriftRuntime& d = drift_rt_;
  // Only where the content this camera last looked at was too plain to register, or is
  // a stream, never with "on-drift-silent"; at its pace (every camera's check counts).
  if (!(streamPlaying() || view.foundPlain(shown.shown_setup, shown.shown_image)) ||
      !fiducialFramesOn()) {
    return false;
  }
  bool due = false;
  if (!periodicCheckDue(o, o.fiducial_at, o.quick_fiducials, config_.drift.fiducial_period_s,
                        due)) {
    return false;
  }
  const std::pair<int, int> size{framebuffer.width, framebuffer.height};
  if (!d.fiducial.count(size)) {
    auto made = makeFiducialFrame(framebuffer);
    if (!made) {
      if (d.fiducial_unavailable != made.error()) warn("drift: " + made.error());
      d.fiducial_unavailable = made.error();
      return false;
    }
    d.fiducial[size] = *made;
    d.fiducial_unavailable.clear();
  }
  o.quick_fiducials = due ? 0 : o.quick_fiducials + 1;
  return true;
}

bool Daemon::holdDue(DriftRuntime::Output& o) {
  bool due = false;
  if (!periodicCheckDue(o, o.held_at, o.quick_holds, config_.drift.stream_period_s, due)) {
    return false;
  }
  if (due) {
    o.held_at = DriftRuntime::Clock::now();
    o.quick_holds = 0;
  } else {
    ++o.quick_holds;
  }
  return true;
}

void Daemon::endFiducialFrame(const std::string& output) {
  DriftRuntime& d = drift_rt_;
  if (!d.fiducial_showing) return;
  d.fiducial_showing = false;
  auto it = d.outputs.find(output);
  if (it != d.outputs.end()) {
    it->second.fiducial_at = DriftRuntime::Clock::now();
    ++it->second.fiducial_checks;
  }
  refreshOutputs();  // the content again
}

void Daemon::onDriftChecked(const DriftKey& key, tl::expected<DriftCheck, CalibrationFailure> r) {
  DriftRuntime& d = drift_rt_;
  d.checking = false;
  d.camera_in_use.clear();
  auto it = d.outputs.find(key.output);
  if (it == d.outputs.end() || !watchesDrift(config_.recalibrate)) return;
  DriftRuntime::Output& o = it->second;
  DriftRuntime::View& v = o.views[key.camera];
  o.camera = key.camera;
  v.checked_at = DriftRuntime::Clock::now();
  if (!r) {
    // The last good rig stays; a camera gone is the device manager's.
    ++o.failures;
    o.error = r.error().message;
    v.above.reset();
    warn("drift check: " + r.error().message);
    if (!r.error().device.empty() && closesDevice(r.error().rc)) {
      device_manager_->report(r.error().device, r.error().rc, r.error().message);
    }
    return;
  }
  o.error.clear();
  v.reference = r->reference;
  v.timing = {{"check_s", r->seconds},
              {"reference_s", r->reference_s},
              {"capture_s", r->capture_s},
              {"measure_s", r->measure_s}};
  // What changed while the check ran makes it say nothing: another frame on the output,
  // a new rig model (a correction landed), an operation or auto keystone taking over.
  const auto st = keystone_rt_.output_state.find(key.output);
  const bool same_frame =
      st != keystone_rt_.output_state.end() && st->second.shown_setup == key.setup &&
      st->second.shown_image == key.image && st->second.shown_at == key.shown_at;
  if (!same_frame || key.rig_generation != rig_generation_ || settings_.auto_keystone ||
      calibrating() || !calibration_.op.empty()) {
    return;
  }
  ++o.checks;
  if (key.held) ++o.held_checks;
  const rig::RigProjector* projector = rig_.projectorForOutput(key.output);
  const rig::RigCamera* camera = rig_.camera(key.camera);
  if (r->blur_fitted && !r->fitted_blur) v.blur_tried = {key.setup, key.image};
  if (r->fitted_blur && projector && camera) {
    v.reference_blur = r->fitted_blur;
    v.blur_for = blurKey(*projector, *camera);
    logInfo("drift: camera '" + key.camera + "' sees output '" + key.output + "' blurred by " +
            std::to_string(*r->fitted_blur) +
            " work px; its frames' light is compared blurred alike");
  }
  const drift::Misregistration& m = r->misregistration;
  v.last = m;
  v.last_generation = key.rig_generation;
  v.last_fiducial = r->fiducial;
  if (r->fiducial && !m.too_plain) o.fiducial_px = m.rms_px;
  if (!r->fiducial) {
    // Whether this frame's content can be registered: fiducialDue asks.
    v.plain = m.too_plain ? DriftRuntime::Frame{key.setup, key.image} : DriftRuntime::Frame{};
  }
  const double threshold = config_.drift.threshold_px;
  if (m.too_plain || m.rms_px <= threshold) {
    v.above.reset();
    if (!m.too_plain && (o.passes > 0 || o.scan != DriftScan::kNone) && !o.drifted()) {
      logInfo("drift: output '" + key.output + "' registered again (camera '" + key.camera +
              "'): " + std::to_string(m.rms_px) + " px after " +
              (o.scan != DriftScan::kNone ? std::string("the ") + driftScanName(o.scan)
                                          : std::to_string(o.passes) + " correction(s)"));
      json event = {{"output", key.output},
                    {"camera", key.camera},
                    {"state", "corrected"},
                    {"passes", o.passes},
                    {"check", misregistrationJson(m)},
                    {"timing", v.timing}};
      if (o.scan != DriftScan::kNone) event["scan"] = driftScanName(o.scan);
      broadcast("drift", event);
      o.passes = 0;
      o.forgetBefore();
    }
    if (!m.too_plain && !o.drifted()) o.scan = DriftScan::kNone;
    if (!m.too_plain) o.unresolved = false;
    return;
  }
  if (!v.above) {
    v.above = v.checked_at;
    logInfo("drift: output '" + key.output + "' misregistered by " + std::to_string(m.rms_px) +
            " px in camera '" + key.camera + "' (threshold " + std::to_string(threshold) + ")");
    broadcast("drift", {{"output", key.output},
                        {"camera", key.camera},
                        {"state", "detected"},
                        {"check", misregistrationJson(m)},
                        {"timing", v.timing}});
  }
  if (o.unresolved || secondsSince(*v.above) < config_.drift.settle_s) return;
  // Whose drift: another camera's check captured after this one first saw it tells. One
  // that sees the output registered means this camera moved; drift in every camera is
  // the projector's. With one camera a moved camera and a moved projector cannot be told
  // apart (on a plane both move the content by a collineation): the projector is assumed
  // to have moved, unless the content moved as a moved wall moves it.
  bool other_registered = false, other_drifted = false;
  for (const std::string& name : o.cameras) {
    if (name == key.camera) continue;
    auto ov = o.views.find(name);
    if (ov == o.views.end() || !ov->second.last || ov->second.last->too_plain ||
        ov->second.checked_at <= *v.above) {
      continue;
    }
    (ov->second.last->rms_px <= threshold ? other_registered : other_drifted) = true;
  }
  if (!other_registered && o.cameras.size() > 1 && !other_drifted) return;  // not looked since
  if (o.passes >= kMaxDriftPasses || o.scan != DriftScan::kNone) {
    // Named by the last correction made (a surface step too), else by whose drift it is.
    std::string step = other_registered ? "camera-pose" : "projector-pose";
    if (o.last_correction.is_object() && o.last_correction.contains("step") &&
        o.last_correction["step"].is_string()) {
      step = o.last_correction["step"].get<std::string>();
    }
    const std::string why = o.scan == DriftScan::kNone
                                ? "corrections from the content left " + std::to_string(m.rms_px) +
                                      " px (over " + std::to_string(threshold) + ") after " +
                                      std::to_string(kMaxDriftPasses) + " passes"
                                : "the output is still " + std::to_string(m.rms_px) +
                                      " px off after the " + driftScanName(o.scan);
    o.passes = 0;
    // The projector's corrections (or a scan of it) climb to the next scan; a camera that
    // moved is not found by scanning a projector, nor a wall (one projector's scan would
    // leave the others on the old one), which its own coarse pass measured already.
    const bool wall_scanned =
        o.last_correction.is_object() && o.last_correction.value("measured", "") == "surface";
    if (!wall_scanned && (step == "projector-pose" || o.scan != DriftScan::kNone)) {
      return escalateDrift(key.output, key.camera, step, why, m);
    }
    return abandonDrift(key.output, key.camera, step, why + "; calibrate again", m);
  }
  if (other_registered) return correctCamera(key.output, key.camera, m);
  if (other_drifted) {
    // Two cameras that see drift tell a moved wall from a moved projector: where both
    // found the same content, their rays meet on the wall as it stands now.
    if (auto wall = movedWall(key.output, key.camera)) {
      return correctSurface(key.output, key.camera, m, *wall, "two cameras");
    }
  } else if (auto wall = movedWallOneCamera(key.output, key.camera)) {
    return correctSurface(key.output, key.camera, m, *wall,
                          "the projector and camera '" + key.camera + "'");
  }
  correctDrift(key.output, key.camera, m);
}

json Daemon::driftJson(const std::string& output) const {
  if (!watchesDrift(config_.recalibrate)) return nullptr;
  auto it = drift_rt_.outputs.find(output);
  if (it == drift_rt_.outputs.end()) return {{"unavailable", "not checked yet"}};
  const DriftRuntime::Output& o = it->second;
  json j = {{"checks", o.checks},
            {"failures", o.failures},
            {"corrections", o.corrections},
            {"last_correction", o.last_correction}};
  if (!o.error.empty()) j["error"] = o.error;
  j["content_streamed"] = streamPlaying();
  if (heldFramesOn() && streamPlaying()) {
    json h = {{"checks", o.held_checks}, {"period_s", config_.drift.stream_period_s}};
    if (o.held_at) h["age_s"] = secondsSince(*o.held_at);
    j["held"] = std::move(h);
  }
  if (config_.recalibrate == RecalibratePolicy::kOnDrift) {
    json f = {{"frames", o.fiducial_checks}, {"period_s", config_.drift.fiducial_period_s}};
    if (o.fiducial_at) f["age_s"] = secondsSince(*o.fiducial_at);
    if (o.fiducial_px) f["misregistration_px"] = *o.fiducial_px;
    if (!drift_rt_.fiducial_unavailable.empty()) f["unavailable"] = drift_rt_.fiducial_unavailable;
    j["fiducial"] = std::move(f);
  }
  if (!o.unavailable.empty()) {
    j["unavailable"] = o.unavailable;
    return j;
  }
  // The last check's figures, and each camera's.
  j["camera"] = o.camera;
  if (const DriftRuntime::View* v = o.lastView(); v && v->last) {
    j.update(misregistrationJson(*v->last));
    j["age_s"] = secondsSince(v->checked_at);
    j.update(v->timing);
  }
  json cameras = json::array();
  bool checked = false, plain = true, content_plain = false;
  for (const auto& [name, v] : o.views) {
    if (!v.last) continue;
    checked = true;
    plain = plain && v.last->too_plain;
    content_plain = content_plain || v.plain.image;
    cameras.push_back(
        {{"camera", name},
         {"misregistration_px", v.last->rms_px},
         {"too_plain", v.last->too_plain},
         {"from", v.last_fiducial ? "fiducial" : "content"},
         {"drifted", v.above.has_value()},
         {"age_s", secondsSince(v.checked_at)},
         {"reference_blur_px", v.reference_blur ? json(*v.reference_blur) : json(nullptr)}});
  }
  j["cameras"] = std::move(cameras);
  j["content_too_plain"] = content_plain;
  std::string state = "registered";
  if (!checked && !o.scanning) {
    state = "checking";
  } else if (o.scanning) {
    state = "scanning";
  } else if (plain) {
    state = "too plain to tell";
  } else if (o.unresolved) {
    state = "unresolved";
  } else if (o.drifted()) {
    state = "drifted";
  }
  j["state"] = state;
  return j;
}

json Daemon::driftPolicyJson() const {
  const DriftConfig& c = config_.drift;
  return {{"policy", recalibratePolicyName(config_.recalibrate)},
          {"period_s", c.period_s},
          {"threshold_px", c.threshold_px},
          {"settle_s", c.settle_s},
          {"frames", c.frames}};
}

}  // namespace procam::daemon
