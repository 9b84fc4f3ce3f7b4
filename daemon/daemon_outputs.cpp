// What the outputs show (PROTOCOL.md: pattern, content, status `outputs`). Planned on the
// loop thread: per output the render path (render::choosePath over the rig model), its
// setup and the content with its version; drawn by the outputs on compute_worker_
// (output_draw.hpp), results posted back.
#include "daemon.hpp"
#include "json_matrix.hpp"
#include "log.hpp"
#include "output_draw.hpp"
#include "support/render_abi.hpp"

namespace procam::daemon {

using nlohmann::json;

namespace {

// Statistics cost a GPU read-back on GLES outputs: asked for at most this often while
// frames change quickly, and once more after such a burst.
constexpr auto kStatsPeriod = std::chrono::milliseconds(200);
constexpr auto kStatsCatchUp = std::chrono::milliseconds(250);

}  // namespace

bool Daemon::calibrating() const {
  // The calibrate operation shows its own pattern frames on the outputs.
  for (const auto& [id, op] : operations_) {
    if (op.kind == "calibrate") return true;
  }
  return false;
}

render::SceneTraits Daemon::sceneTraits(const std::string& output, bool mesh_content) const {
  render::SceneTraits t;
  const rig::RigProjector* p = rig_.projectorForOutput(output);
  const bool meshed =
      (p && rig_.surface.meshes.count(p->name)) || !rig_.surface.unified_mesh.empty();
  t.surface = !rig_.surface.plane && meshed ? render::SurfaceKind::kNonPlanar
                                            : render::SurfaceKind::kPlanar;
  if (rig_.surface.object) t.surface = render::SurfaceKind::kObject;
  // Tracked: a tracker reports the viewer (the eye viewerEye() gives) or the rig names one.
  // A dome master is made for the static eye: a tracker does not move it.
  const bool dome = config_.content_dome && !mesh_content;
  if (!dome && (!viewerJson().is_null() || !rig_.viewer.tracker.empty())) {
    t.viewer = render::ViewerKind::kTracked;
  } else if (staticEye()) {
    t.viewer = render::ViewerKind::kStatic;
  }
  t.content = mesh_content ? render::ContentKind::kMesh3d : render::ContentKind::kImage;
  t.projectors = std::max<int>(1, static_cast<int>(devices_.count(PROCAM_FAMILY_OUTPUT)));
  return t;
}

std::optional<OutputDraw> Daemon::planOutput(DeviceEntry& e, const OutputDrawPolicy& policy) {
  KeystoneRuntime& k = keystone_rt_;
  int rc = PROCAM_OK;
  auto mode = outputMode(e.device.raw(), &rc);
  if (!mode) {
    // An output that no longer answers for its mode is gone (a projector unplugged): the
    // device manager closes it and opens it again when it is back. Reported from the loop,
    // not while the outputs are being walked.
    if (closesDevice(rc)) {
      loop_->post([this, name = e.name, rc] {
        if (const DeviceEntry* gone = devices_.find(name); gone && gone->usable())
          device_manager_->report(name, rc, "the output does not answer for its mode");
      });
    }
    return std::nullopt;
  }
  FrameRequest r;
  r.output_size = *mode;
  r.pattern = settings_.pattern;
  if (r.pattern != "off") {
    const std::string key =
        r.pattern + " " + std::to_string(mode->width) + "x" + std::to_string(mode->height);
    auto& image = k.patterns[key];
    if (!image) image = patternImage(r.pattern, *mode);
    r.pattern_image = image;
  }
  r.content = k.content;
  if (auto m = k.meshes.find(e.name); m != k.meshes.end()) r.mesh3d = m->second;
  const MeshImage* mesh_image = nullptr;
  if (auto m = k.mesh_images.find(e.name); m != k.mesh_images.end()) {
    mesh_image = &m->second;
    r.content = m->second.image;
  }
  // An object's look: each frame was rendered from this projector per pixel (shader
  // lamps, object_content.hpp) and is shown as it is; an output whose projector does not
  // light the object shows black. A pattern is drawn as on any rig (keystone, tiles).
  const PreparedObject* object = r.pattern == "off" ? object_show_.prepared.get() : nullptr;
  std::string object_note;
  if (object) {
    auto f = object->frames.find(e.name);
    r.content = f != object->frames.end() && f->second->size() == *mode ? f->second : nullptr;
    if (!r.content) object_note = "no frame of the object's look for this output";
  }
  // Several projectors on one wall: this output's share of the one display.
  const bool rig_mode =
      settings_.rig_keystone && !(settings_.auto_keystone && k.estimate) && !object;
  const KeystoneRuntime::Tiled* tiled = rig_mode ? tiledDisplay(sourceSize(r)) : nullptr;
  int tile = tiled ? tiled->index(e.name) : -1;
  r.homography = object      ? std::optional<Mat3>(Mat3::Identity())
                 : tile >= 0 ? std::optional<Mat3>(tiled->display.content_to_framebuffer[tile])
                             : currentWarp(sourceSize(r));
  auto plan = planFrame(r);
  if (!plan) {
    warn("output '" + e.name + "': " + plan.error().message);
    return std::nullopt;
  }
  if (tile >= 0 && tiled->alpha[tile].size() == *mode) {
    // Eq. 4.3 weights in linear light, through the projector's response, matched per
    // pixel or by a brightness gain ([Raskar02] §4.1.2, [Majumder05]).
    plan->setup.final_stage.alpha = tiled->alpha[tile];
    plan->setup.final_stage.weight_lut = tiled->weight_lut[tile];
  }
  const render::SceneTraits traits = sceneTraits(e.name, plan->mesh != nullptr);
  auto& st = k.output_state[e.name];
  st.viewer.reset();
  std::string np_note;
  if (plan->source == "content" && !plan->mesh &&
      traits.surface == render::SurfaceKind::kNonPlanar) {
    // Image content on a non-planar surface: what the viewer should see, drawn by the
    // two-pass path or the lookup warp; a keystone homography when the rig or the viewer
    // do not allow it.
    int share = -1;
    auto np = nonPlanarSetup(e.name, traits, *mode, plan->image->size(),
                             mesh_image ? &mesh_image->viewer : nullptr, &share);
    if (np) {
      plan->setup = **np;
      // A dome master has no world -> content matrix: its content is directions.
      if (!(*np)->viewer.isZero()) st.viewer = (*np)->viewer;
      tile = share;
    } else {
      np_note = "non-planar surface, drawn by homography: " + np.error().message;
    }
  }
  const auto device = e.device.share();
  OutputDraw job;
  job.name = e.name;
  job.device = device;
  job.configure =
      !st.setup || st.device.lock() != device || !render::sameSetup(*st.setup, plan->setup);
  if (job.configure) st.setup = std::make_shared<const render::RenderSetup>(plan->setup);
  st.device = device;
  job.setup = st.setup;
  std::shared_ptr<const void> content =
      plan->image ? std::shared_ptr<const void>(plan->image) : plan->mesh;
  const bool new_content = content != st.content;
  if (new_content) {
    st.content = content;  // held, so that a new content never reuses its address
    ++st.version;
  }
  job.image = plan->image;
  job.mesh = plan->mesh;
  job.version = st.version;
  if (!plugins::outputRenders(device->raw())) {
    if (!st.fallback) st.fallback = std::make_shared<render::CpuRenderer>();
    job.fallback = st.fallback;
  } else {
    st.fallback.reset();
  }
  // A client waiting for this frame, new still content or a new render path gets its
  // numbers at once.
  const std::string path = object && plan->source == "content"
                               ? render::toString(render::RenderPath::kShaderLamps)
                               : render::toString(plan->setup.path);
  job.want_stats = policy.waited_for || (new_content && !policy.live) || path != st.path ||
                   policy.now - st.stats_time >= kStatsPeriod;
  if (job.want_stats) st.stats_time = policy.now;
  st.path = path;
  job.path = path;
  job.viewer = st.viewer;
  if (plan->setup.path == render::RenderPath::kHomography) job.homography = plan->setup.homography;
  job.tile = tile;
  const auto chosen = render::choosePath(traits);
  st.chosen = chosen ? render::toString(chosen->path) : std::string("none");
  st.path_note.clear();
  if (!chosen) {
    st.path_note = chosen.error().message;
  } else if (!object_note.empty()) {
    st.path_note = object_note;
  } else if (traits.surface == render::SurfaceKind::kObject && !object &&
             plan->source == "content") {
    st.path_note =
        "content on an object is painted through its model: content load an image (the "
        "model's texture) or the model; streamed or shared frames are drawn 2D, by homography";
  } else if (!np_note.empty()) {
    st.path_note = np_note;
  } else if (chosen->path != plan->setup.path && plan->source != "content") {
    st.path_note = "patterns and blank frames are drawn 2D, by homography";
  }
  job.source = plan->source;
  return job;
}

void Daemon::refreshOutputs(std::function<void(bool shown)> done, bool supersede) {
  KeystoneRuntime& k = keystone_rt_;
  if (done) k.frame_waiters.push_back(std::move(done));
  if (k.rendering) {
    k.render_again = true;  // after the frame in flight: the state changed since
    // Other content or a pattern a client waits for: the frame in flight is obsolete
    // and stops (before the next output, or midway where the driver can), so a large
    // mesh does not hold the new state back by a whole frame.
    if (supersede && k.frame_stop) k.frame_stop->store(true);
    return;
  }
  auto waiters = std::move(k.frame_waiters);
  k.frame_waiters.clear();
  // The camera's yaw measurement shows its dot grid for a few seconds, a drift check its
  // fiducial frame for a fraction of one: what waits for a frame is drawn when it ends.
  // A calibration shows its own frames for a long run.
  if (k.yaw.measuring || drift_rt_.fiducial_showing) {
    k.frame_waiters.insert(k.frame_waiters.end(), std::make_move_iterator(waiters.begin()),
                           std::make_move_iterator(waiters.end()));
    return;
  }
  if (calibrating()) {
    k.unshown_arrival.reset();  // its frame is the calibration's: no latency to count
    for (auto& w : waiters) w(false);
    return;
  }
  // The automatic keystone's solution this frame carries: for a turn, predicted to the
  // time the frame is asked to go on the wall (keystone_frames.cpp).
  const auto solution = planKeystoneFrame();
  const OutputDrawPolicy policy{std::chrono::steady_clock::now(), !waiters.empty(),
                                live_content_ && !live_content_->ended};
  std::vector<OutputDraw> jobs;
  for (auto& e : devices_.entries()) {
    if (e.description.family != PROCAM_FAMILY_OUTPUT || !e.usable()) continue;
    if (auto job = planOutput(e, policy)) jobs.push_back(std::move(*job));
  }
  const bool stats_pending =
      std::any_of(jobs.begin(), jobs.end(), [](const OutputDraw& j) { return !j.want_stats; });
  if (stats_pending && k.stats_timer < 0) {
    auto timer = loop_->addTimer(kStatsCatchUp, false, [this] {
      keystone_rt_.stats_timer = -1;
      refreshOutputs();
    });
    if (timer) k.stats_timer = *timer;
  }
  if (jobs.empty()) {
    k.unshown_arrival.reset();  // nothing shows it
    for (auto& w : waiters) w(false);
    return;
  }
  // A changed source size changes the auto solution's content: solve again.
  if (settings_.auto_keystone && k.estimate) {
    const cv::Size s = currentSourceSize();
    if (s.width != k.estimate->content_width || s.height != k.estimate->content_height) {
      requestSolve();
    }
  }
  // The tilt solution not shown yet goes with this frame; a frame stopped midway hands
  // it to the one that replaces it. One whose reading came before the camera yaw's dot
  // grid ended waited for the measurement, not for the pipeline: not counted.
  if (k.unshown_arrival && *k.unshown_arrival < k.grid_ended) k.unshown_arrival.reset();
  std::optional<std::chrono::steady_clock::time_point> arrival;
  if (k.unshown_arrival && settings_.auto_keystone) {
    for (auto& job : jobs) {
      if (job.homography) job.reading_arrival = arrival = k.unshown_arrival;
    }
    k.unshown_arrival.reset();
  }
  if (solution) {
    for (auto& job : jobs) {
      if (job.homography) job.present_at_ns = solution->present_at_ns;
    }
  }
  k.rendering = true;
  k.frame_stop = std::make_shared<std::atomic<bool>>(false);
  for (auto& job : jobs) job.stop = k.frame_stop;
  // Shared with the failure handler: the waiters are answered either way.
  auto waiting = std::make_shared<decltype(waiters)>(std::move(waiters));
  compute_worker_->submit(
      [this, jobs = std::move(jobs), waiting, arrival, solution] {
        auto results = std::make_shared<std::vector<OutputDrawn>>();
        for (const auto& job : jobs) results->push_back(drawOutput(job));
        return [this, results, waiting, arrival, solution] {
          KeystoneRuntime& k = keystone_rt_;
          k.rendering = false;
          k.frame_stop.reset();
          bool shown = false, drawn = false, stopped = false;
          std::optional<double> latency;  // the last output's to show it: one per frame
          for (const OutputDrawn& r : *results) {
            auto st = k.output_state.find(r.name);
            if (r.stopped) {
              stopped = true;
              // A setup that never reached the output is handed over next time.
              if (r.configure_asked && !r.configured && st != k.output_state.end()) {
                st->second.setup.reset();
              }
              continue;
            }
            if (!r.ok) {
              warn("output '" + r.name + "': " + r.error);
              // Hand the setup over again next time: the output may not hold it.
              if (st != k.output_state.end()) st->second.setup.reset();
              if (closesDevice(r.rc)) device_manager_->report(r.name, r.rc, r.error);
              continue;
            }
            shown = true;
            drawn = drawn || r.drawn;
            if (st != k.output_state.end()) {
              st->second.shown_setup = r.setup;
              st->second.shown_image = r.image;
              if (r.drawn) st->second.shown_at = std::chrono::steady_clock::now();
            }
            if (r.latency_s) latency = std::max(latency.value_or(0.0), *r.latency_s);
            if (r.stats) {
              k.shown[r.name] = {r.source,
                                 r.stats->lit_fraction,
                                 r.stats->mean_rgb,
                                 r.path,
                                 r.viewer,
                                 r.homography,
                                 r.tile};
            }
          }
          if (drawn) ++k.frames;  // frames drawn, not statistics read again
          if (solution) {
            // One report per frame: the first output that showed the keystone's solution.
            for (const OutputDrawn& r : *results) {
              if (r.ok && r.homography && r.shown_ns) {
                keystoneFrameShown(*solution, r);
                break;
              }
            }
          }
          if (latency) {
            k.latency.add(*latency);
          } else if (stopped && arrival && !k.unshown_arrival) {
            k.unshown_arrival = arrival;
          }
          if (stopped) {
            ++k.frames_stopped;
            // Its waiters wait for the frame that replaces it, drawn next.
            k.frame_waiters.insert(k.frame_waiters.begin(),
                                   std::make_move_iterator(waiting->begin()),
                                   std::make_move_iterator(waiting->end()));
            k.render_again = true;
          } else {
            for (auto& w : *waiting) w(shown);
          }
          // A drift check the frame held back goes in first, even when the next frame
          // is due at once (a stream that comes faster than it is drawn): the frame
          // queues behind it on the worker.
          const bool again = k.render_again;
          if (drift_rt_.check_after_frame && !stopped) {
            k.render_again = false;
            checkDrift();
          }
          if (again) {
            k.render_again = false;
            refreshOutputs();
          }
        };
      },
      [this, waiting](const std::string& what) {
        // Nothing was shown; the state that asked for the frame is answered all the same.
        keystone_rt_.rendering = false;
        keystone_rt_.frame_stop.reset();
        warn("drawing the outputs failed: " + what);
        for (auto& w : *waiting) w(false);
        if (keystone_rt_.render_again) {
          keystone_rt_.render_again = false;
          refreshOutputs();
        }
      });
}

void Daemon::loadContentAtStart() {
  if (settings_.content.empty()) return;
  // The saved path goes through the content roots as a client's would.
  compute_worker_->submit(
      [this, file = settings_.content, access = contentAccess()] {
        auto image = decodeContent(access, file);
        return [this, file, image = std::move(image)] {
          if (settings_.content != file) return;  // replaced meanwhile
          if (!image) {
            warn("saved content not shown: " + image.error().message);
            return;
          }
          keystone_rt_.content = image->image;
          content_info_ = {image->image->cols, image->image->rows};
          refreshOutputs();
        };
      },
      [this](const std::string& what) { warn("saved content not shown: " + what); });
}

json Daemon::outputsJson() const {
  json list = json::array();
  for (const auto& [name, st] : keystone_rt_.shown) {
    json o = {{"name", name},
              {"source", st.source},
              {"lit_fraction", st.lit_fraction},
              {"mean_rgb", {st.mean_rgb[0], st.mean_rgb[1], st.mean_rgb[2]}}};
    // The path and viewer of the frame the statistics describe; chosen path, note and
    // renderer of the latest plan.
    if (!st.path.empty()) o["path"] = st.path;
    if (st.viewer) o["viewer_matrix"] = rowMajor(*st.viewer);
    if (st.homography) o["homography"] = rowMajor(*st.homography);
    // Its share of a display across outputs: on a curved surface (lookup warp for the
    // sweet spot, two-pass for a tracked eye) or a wall.
    const bool on_surface = st.path == render::toString(render::RenderPath::kLookupWarp) ||
                            st.path == render::toString(render::RenderPath::kTwoPassMesh);
    if (st.tile >= 0 && on_surface && keystone_rt_.curved) {
      o["display"] = {{"tile", st.tile},
                      {"tiles", keystone_rt_.curved->outputs.size()},
                      {"surface", "mesh"},
                      {"blend", "feathered"}};
    } else if (st.tile >= 0 && keystone_rt_.tiled) {
      o["display"] = {{"tile", st.tile},
                      {"tiles", keystone_rt_.tiled->outputs.size()},
                      {"surface", "plane"},
                      {"blend", "feathered"}};
    }
    if (auto it = keystone_rt_.output_state.find(name); it != keystone_rt_.output_state.end()) {
      const auto& os = it->second;
      o["chosen_path"] = os.chosen;
      if (!os.path_note.empty()) o["path_note"] = os.path_note;
      o["renderer"] = os.fallback ? "daemon-cpu" : "output";
    }
    if (json drift = driftJson(name); !drift.is_null()) o["drift"] = std::move(drift);
    list.push_back(std::move(o));
  }
  json out = {{"frames", keystone_rt_.frames},
              {"frames_stopped", keystone_rt_.frames_stopped},
              {"shown", list}};
  // Several projectors on a curved surface as one display for the static viewer.
  if (json display = curvedDisplayJson(); !display.is_null()) out["display"] = std::move(display);
  return out;
}

}  // namespace procam::daemon
