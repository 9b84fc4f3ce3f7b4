#include "sim_plugin.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "render/cpu_renderer.hpp"
#include "sim/background_rows.hpp"
#include "sim/sensors.hpp"
#include "sim_tilt.hpp"
#include "sim_unplug.hpp"
#include "sim_world.hpp"
#include "support/driver_support.hpp"
#include "support/render_abi.hpp"
#include "tilt/plugin/plugin_support.hpp"

namespace procam::sim::mock {
namespace {

constexpr int kSimScore = 100;

using plugins::property;
using plugins::report;

// An output's own renderer (output operations version 2): one CPU reference renderer per
// output, its warp map built once per render setup.
struct OutputRender {
  render::CpuRenderer renderer;
  std::optional<render::RenderSetup> setup;
  bool showing = true;  // a frame shown 1:1 replaced the rendered one
  plugins::MeshCache mesh;
};

// What a camera saw at its last capture and the geometry it was rendered in. While
// no device moves, a capture of the same frames only draws new noise, and one of new
// frames lights the light paths traced at the second capture of that geometry
// (light_paths.hpp): the ray cast is most of a capture's time, and a calibration
// changes only what the projectors show. The first capture of a geometry casts its
// rays directly, so a moving scene traces nothing it will not use again.
struct CameraRadiance {
  std::vector<geom::Pose> poses;  // every projector's and camera's, in scene order
  std::shared_ptr<const World> world;
  std::vector<double> lenses;  // every projector's fx, fy, skew (a zoom event changes them)
  std::uint64_t shows = 0;
  cv::Mat radiance;
  std::optional<LightPaths> paths;
  bool untraceable = false;  // more paths than LightPaths::kMaxPaths

  static std::vector<double> lensesOf(const SceneState& state) {
    std::vector<double> out;
    for (const auto& p : state.projectors) {
      out.insert(out.end(), {p.model.K.fx, p.model.K.fy, p.model.K.skew});
    }
    return out;
  }

  static std::vector<geom::Pose> posesOf(const SceneState& state) {
    std::vector<geom::Pose> out;
    for (const auto& p : state.projectors) out.push_back(p.model.pose);
    for (const auto& c : state.cameras) out.push_back(c.model.pose);
    return out;
  }
  bool sameGeometry(const std::vector<geom::Pose>& p, const SceneState& state) const {
    if (radiance.empty() || state.world != world || p.size() != poses.size() ||
        lensesOf(state) != lenses) {
      return false;
    }
    // A held pose evaluated at another time differs by rounding (a few 1e-16 from the
    // interpolation between equal keyframes); 1e-12 rad or m moves no pixel.
    constexpr double kSame = 1e-12;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!((p[i].R - poses[i].R).norm() <= kSame)) return false;  // NaN: not the same
      if (!((p[i].t - poses[i].t).norm() <= kSame)) return false;
    }
    return true;
  }
};

struct Device {
  std::shared_ptr<SimWorld> world;
  std::string name;
  std::vector<uint8_t> buffer;  // camera frames
  uint64_t frames = 0;          // camera frames captured: each has its own noise
  std::unique_ptr<OutputRender> output;
  CameraRadiance cache;
  // Outputs: the next rendered frame goes on the wall no earlier than this (CLOCK_MONOTONIC
  // ns, 0: at once); when the last one was ready and shown.
  uint64_t present_not_before = 0;
  uint64_t ready_ns = 0, shown_ns = 0;
};

// PROCAM_OK while the device is plugged in (sim_unplug.hpp).
int presence(const std::string& name, char* err, size_t len) {
  auto gone = unpluggedNow(name);
  if (!gone) return report(err, len, gone.error().message, PROCAM_EINVAL);
  return *gone ? report(err, len, "'" + name + "' is unplugged (" + kUnplugVariable + ")",
                        PROCAM_ENODEV)
               : PROCAM_OK;
}

int noFd(void*) {
  return -1;
}
void destroy(void* self) {
  delete static_cast<Device*>(self);
}

int probe(const procam_device_desc* d) {
  return d->subsystem && std::strcmp(d->subsystem, "sim") == 0 ? kSimScore : 0;
}

// --- tracker ---
int trackerRead(void* self, procam_pose_sample* out, char* err, size_t len) {
  auto* dev = static_cast<Device*>(self);
  if (int rc = presence(dev->name, err, len); rc != PROCAM_OK) return rc;
  const double t = dev->world->now();
  auto s = sampleTracker(dev->world->scene(), dev->name, t);
  if (!s) return report(err, len, s.error().message, PROCAM_EIO);
  for (int i = 0; i < 3; ++i) out->position[i] = s->position[i];
  out->orientation[0] = 1;  // position-only trackers: identity orientation
  out->orientation[1] = out->orientation[2] = out->orientation[3] = 0;
  out->timestamp_ns = static_cast<uint64_t>(t * 1e9);
  return PROCAM_OK;
}
int trackerRate(void* self, double* hz) {
  auto* dev = static_cast<Device*>(self);
  for (const auto& t : dev->world->scene().trackers()) {
    if (t.name == dev->name && t.rate_hz > 0) {
      *hz = t.rate_hz;
      return PROCAM_OK;
    }
  }
  return PROCAM_ENOTSUP;
}
const procam_tracker_ops kTrackerOps = {PROCAM_TRACKER_OPS_VERSION, trackerRead, trackerRate};

// --- output ---
const ProjectorSpec* projectorSpec(const Device* dev) {
  for (const auto& p : dev->world->scene().projectors()) {
    if (p.name == dev->name) return &p;
  }
  return nullptr;
}

// Every virtual projector is a 60 Hz display; one with `vsync` presents a rendered
// frame at a vblank, world time k / kRefreshHz (SCENE-FORMAT.md).
constexpr double kRefreshHz = 60.0;

int outputMode(void* self, uint32_t* w, uint32_t* h, double* hz) {
  const ProjectorSpec* p = projectorSpec(static_cast<Device*>(self));
  if (!p || presence(p->name, nullptr, 0) != PROCAM_OK) return PROCAM_ENODEV;
  *w = static_cast<uint32_t>(p->width);
  *h = static_cast<uint32_t>(p->height);
  *hz = kRefreshHz;
  return PROCAM_OK;
}

int outputPresentAt(void* self, uint64_t not_before_ns) {
  static_cast<Device*>(self)->present_not_before = not_before_ns;
  return PROCAM_OK;
}

int outputTiming(void* self, uint64_t* ready_ns, uint64_t* shown_ns, uint64_t* period_ns) {
  auto* dev = static_cast<Device*>(self);
  const ProjectorSpec* p = projectorSpec(dev);
  if (!p) return PROCAM_ENODEV;
  if (ready_ns) *ready_ns = dev->ready_ns;
  if (shown_ns) *shown_ns = dev->shown_ns;
  if (period_ns) *period_ns = p->vsync ? static_cast<uint64_t>(std::llround(1e9 / kRefreshHz)) : 0;
  return PROCAM_OK;
}

// A rendered frame, drawn: it goes on the wall no earlier than the time asked for and,
// with `vsync`, at the first vblank from then (a page flip: render returns once it is
// on). Without: queued, render returns once it is drawn, and the next frame may be
// drawn while this one waits.
void presentFrame(Device& dev, const ProjectorSpec& p, cv::Mat bgr) {
  SimWorld& world = *dev.world;
  const double ready = world.now();
  double shown = ready;
  // One frame per vblank: the one after the frame before's (which is on by now: render
  // returned once it was).
  if (p.vsync && dev.shown_ns)
    shown = std::max(shown, world.worldTime(dev.shown_ns) + 1 / kRefreshHz);
  if (dev.present_not_before) shown = std::max(shown, world.worldTime(dev.present_not_before));
  // The first vblank at or after then. A time up to a thousandth of a period after a
  // vblank counts as that vblank: a client steps the period in whole nanoseconds (the
  // ABI's), 0.33 ns off per 60 Hz period, which adds up over a few seconds of periods.
  if (p.vsync) shown = std::ceil(shown * kRefreshHz - 1e-3) / kRefreshHz;
  dev.present_not_before = 0;  // for the next frame only
  // After a frame queued before it, if that one goes on later.
  shown = world.show(dev.name, std::move(bgr), shown);
  dev.ready_ns = world.monotonicNs(ready);
  dev.shown_ns = std::max(dev.ready_ns, world.monotonicNs(shown));
  if (p.vsync) {
    // A page flip returns once the frame is on, as KMS does: the next frame is drawn
    // for the vblank after it, not queued behind it.
    std::this_thread::sleep_until(
        std::chrono::steady_clock::time_point(std::chrono::nanoseconds(dev.shown_ns)));
  }
}

int outputShow(void* self, const procam_image* frame, char* err, size_t len) {
  auto* dev = static_cast<Device*>(self);
  const ProjectorSpec* p = projectorSpec(dev);
  if (!p) return report(err, len, "projector gone", PROCAM_ENODEV);
  if (int rc = presence(dev->name, err, len); rc != PROCAM_OK) return rc;
  if (static_cast<int>(frame->width) != p->width || static_cast<int>(frame->height) != p->height) {
    return report(err, len,
                  "frame is not " + std::to_string(p->width) + "x" + std::to_string(p->height),
                  PROCAM_EINVAL);
  }
  try {
    cv::Mat bgr;
    if (frame->format == PROCAM_PIXEL_RGBA8) {
      cv::cvtColor(cv::Mat(frame->height, frame->width, CV_8UC4, frame->data, frame->stride), bgr,
                   cv::COLOR_RGBA2BGR);
    } else if (frame->format == PROCAM_PIXEL_RGB8) {
      cv::cvtColor(cv::Mat(frame->height, frame->width, CV_8UC3, frame->data, frame->stride), bgr,
                   cv::COLOR_RGB2BGR);
    } else if (frame->format == PROCAM_PIXEL_GRAY8) {
      bgr = cv::Mat(frame->height, frame->width, CV_8UC1, frame->data, frame->stride).clone();
    } else if (frame->format == PROCAM_PIXEL_GRAY16) {
      bgr = cv::Mat(frame->height, frame->width, CV_16UC1, frame->data, frame->stride).clone();
    } else {
      return report(err, len, "unsupported pixel format", PROCAM_EINVAL);
    }
    dev->world->show(dev->name, std::move(bgr));
    if (dev->output) dev->output->showing = true;
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
  return PROCAM_OK;
}

int outputConfigure(void* self, const procam_render_setup* setup, char* err, size_t len) {
  auto* dev = static_cast<Device*>(self);
  const ProjectorSpec* p = projectorSpec(dev);
  if (!p) return report(err, len, "projector gone", PROCAM_ENODEV);
  if (int rc = presence(dev->name, err, len); rc != PROCAM_OK) return rc;
  try {
    if (!setup) return report(err, len, "no render setup", PROCAM_EINVAL);
    auto s = plugins::setupFromAbi(*setup);
    if (!s) return report(err, len, s.error().message, PROCAM_EINVAL);
    if (s->output_size != cv::Size(p->width, p->height)) {
      return report(err, len, "render setup size differs from the projector's", PROCAM_EINVAL);
    }
    if (!dev->output) dev->output = std::make_unique<OutputRender>();
    if (auto ok = dev->output->renderer.configure(*s); !ok) {
      return report(err, len, ok.error().message, PROCAM_EINVAL);
    }
    dev->output->setup = std::move(*s);
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

int outputRenderStoppable(void* self, const procam_content* content, int (*stop)(void*),
                          void* stop_ctx, int* drawn, procam_frame_stats* stats, char* err,
                          size_t len) {
  auto* dev = static_cast<Device*>(self);
  if (drawn) *drawn = 0;
  if (int rc = presence(dev->name, err, len); rc != PROCAM_OK) return rc;
  try {
    OutputRender* o = dev->output.get();
    if (!o || !o->setup) return report(err, len, "render before configure", PROCAM_EINVAL);
    if (!content) return report(err, len, "no content", PROCAM_EINVAL);
    cv::Mat header;
    auto c = plugins::contentFromAbi(*content, *o->setup, header, o->mesh);
    if (!c) return report(err, len, c.error().message, PROCAM_EINVAL);
    if (stop) c->stop = [stop, stop_ctx] { return stop(stop_ctx) != 0; };
    if (o->showing) o->renderer.redraw();
    auto rendered = o->renderer.render(*c);
    if (!rendered) {
      const bool stopped = rendered.error().code == ErrorCode::kCancelled;
      return report(err, len, rendered.error().message, stopped ? PROCAM_ECANCELED : PROCAM_EINVAL);
    }
    if (*rendered || o->showing) {
      // The simulated projector lights the world with a BGR frame.
      cv::Mat bgr;
      cv::cvtColor(o->renderer.frame(), bgr, cv::COLOR_RGBA2BGR);
      const ProjectorSpec* p = projectorSpec(dev);
      if (!p) return report(err, len, "projector gone", PROCAM_ENODEV);
      presentFrame(*dev, *p, std::move(bgr));
      o->showing = false;
      if (drawn) *drawn = 1;
    }
    if (stats) {
      auto st = plugins::abiFrameStats(o->renderer.frame());
      if (!st) return report(err, len, st.error().message, PROCAM_EINTERNAL);
      *stats = *st;
    }
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

int outputRender(void* self, const procam_content* content, int* drawn, procam_frame_stats* stats,
                 char* err, size_t len) {
  return outputRenderStoppable(self, content, nullptr, nullptr, drawn, stats, err, len);
}

const procam_output_ops kOutputOps = {
    PROCAM_OUTPUT_OPS_VERSION, outputMode,      outputShow,  outputConfigure, outputRender,
    outputRenderStoppable,     outputPresentAt, outputTiming};

// --- camera ---
const CameraSpec* cameraSpec(const Device* dev) {
  for (const auto& c : dev->world->scene().cameras()) {
    if (c.name == dev->name) return &c;
  }
  return nullptr;
}

int cameraFormat(void* self, uint32_t* w, uint32_t* h, procam_pixel_format* f) {
  const CameraSpec* c = cameraSpec(static_cast<Device*>(self));
  if (!c || presence(c->name, nullptr, 0) != PROCAM_OK) return PROCAM_ENODEV;
  *w = static_cast<uint32_t>(c->width);
  *h = static_cast<uint32_t>(c->height);
  *f = c->channels == 3   ? PROCAM_PIXEL_RGB8
       : c->bit_depth > 8 ? PROCAM_PIXEL_GRAY16
                          : PROCAM_PIXEL_GRAY8;
  return PROCAM_OK;
}

int cameraExposure(void*, double, char* err, size_t len) {
  return report(err, len, "the virtual camera's exposure is fixed by the scene", PROCAM_ENOTSUP);
}

int cameraCapture(void* self, int, procam_image* out, char* err, size_t len) {
  auto* dev = static_cast<Device*>(self);
  if (int rc = presence(dev->name, err, len); rc != PROCAM_OK) return rc;
  try {
    const double t = dev->world->now();
    const Scene& scene = dev->world->scene();
    const CameraSpec* spec = cameraSpec(dev);
    if (!spec) return report(err, len, "camera gone", PROCAM_ENODEV);
    // The outputs as they were latency_s ago (SCENE-FORMAT.md, mock drivers).
    const std::uint64_t shows = dev->world->showCount();
    const Framebuffers shown =
        spec->latency_s > 0 ? dev->world->shownAt(t - spec->latency_s) : dev->world->shown();
    SceneState state = scene.at(t);
    const std::vector<geom::Pose> poses = CameraRadiance::posesOf(state);
    CameraRadiance& cache = dev->cache;
    const bool still = cache.sameGeometry(poses, state);
    // With a latency the frames lit are those of another time: always light again.
    if (!still || spec->latency_s > 0 || shows != cache.shows) {
      if (!still) {
        cache = {poses, state.world, CameraRadiance::lensesOf(state), 0, {}, std::nullopt, false};
      }
      auto renderer = Renderer::create(scene, std::move(state), shown);
      if (!renderer) return report(err, len, renderer.error().message, PROCAM_EIO);
      if (still && !cache.paths && !cache.untraceable) {
        auto paths = renderer->cameraLightPaths(dev->name);
        if (paths) {
          cache.paths = std::move(*paths);
        } else if (paths.error().code == ErrorCode::kTooLarge) {
          cache.untraceable = true;  // too many to keep: cast every capture's rays
        } else {
          return report(err, len, paths.error().message, PROCAM_EIO);
        }
      }
      auto radiance = cache.paths ? renderer->cameraRadiance(dev->name, *cache.paths)
                                  : renderer->cameraRadiance(dev->name);
      if (!radiance) {
        cache = {};
        return report(err, len, radiance.error().message, PROCAM_EIO);
      }
      cache.radiance = std::move(*radiance);
      cache.shows = shows;
    }
    // A real sensor's noise is new in every frame: averaging frames reduces it.
    RenderOptions options;
    options.seed = ++dev->frames;
    cv::Mat m = Renderer::cameraImage(*spec, cache.radiance, options);
    if (m.channels() == 3) cv::cvtColor(m, m, cv::COLOR_BGR2RGB);
    if (!m.isContinuous()) m = m.clone();
    dev->buffer.assign(m.datastart, m.dataend);
    out->width = static_cast<uint32_t>(m.cols);
    out->height = static_cast<uint32_t>(m.rows);
    out->stride = static_cast<uint32_t>(m.step[0]);
    out->format = m.channels() == 3     ? PROCAM_PIXEL_RGB8
                  : m.depth() == CV_16U ? PROCAM_PIXEL_GRAY16
                                        : PROCAM_PIXEL_GRAY8;
    out->data = dev->buffer.data();
    out->timestamp_ns = dev->world->monotonicNs(t);  // the ABI's clock
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
  return PROCAM_OK;
}
// Liveness without a ray cast: the device is there unless unplugged.
int cameraCheck(void* self, char* err, size_t len) {
  return presence(static_cast<Device*>(self)->name, err, len);
}
// The scene's exposure is a factor on radiance, not a time: only the gain is told,
// in dB of its amplitude factor.
int cameraSettings(void* self, procam_camera_settings* out) {
  auto* dev = static_cast<Device*>(self);
  const CameraSpec* spec = cameraSpec(dev);
  if (!spec) return PROCAM_ENODEV;
  out->exposure_s = std::nan("");
  out->gain = 20.0 * std::log10(spec->gain);
  out->gain_db = 1;
  return PROCAM_OK;
}

const procam_camera_ops kCameraOps = {PROCAM_CAMERA_OPS_VERSION,
                                      cameraFormat,
                                      cameraExposure,
                                      cameraCapture,
                                      cameraCheck,
                                      cameraSettings};

template <procam_family Family>
int create(const procam_device_desc* d, const procam_config*, procam_device* out, char* err,
           size_t len) {
  try {
    const std::string scene = property(d, "SIM_SCENE");
    const std::string name = property(d, "SIM_DEVICE");
    if (scene.empty() || name.empty()) {
      return report(err, len, "a sim device needs SIM_SCENE and SIM_DEVICE", PROCAM_EINVAL);
    }
    if (int rc = presence(name, err, len); rc != PROCAM_OK) return rc;
    auto world = SimWorld::open(scene);
    if (!world) return report(err, len, world.error().message, PROCAM_EINVAL);
    auto dev = std::make_unique<Device>(Device{*world, name, {}, 0, nullptr, {}});
    bool known = false;
    const Scene& s = (*world)->scene();
    if constexpr (Family == PROCAM_FAMILY_CAMERA) {
      known = cameraSpec(dev.get()) != nullptr;
      out->ops.camera = &kCameraOps;
      // A virtual camera's frames are rendered on the daemon's cores, where a real
      // one's take none of them: below the daemon's own threads (background_rows.hpp).
      setBackgroundRendering(true);
    } else if constexpr (Family == PROCAM_FAMILY_TILT) {
      for (const auto& t : s.tiltSensors()) known = known || t.name == name;
      // Through the tilt drivers' wrapper: the same sample gate and counts as hardware.
      if (known) {
        return tilt::plugin::finishTiltDevice(std::make_unique<SimTiltSensor>(*world, name),
                                              tilt::SampleGateOptions{}, out, err, len);
      }
    } else if constexpr (Family == PROCAM_FAMILY_TRACKER) {
      for (const auto& t : s.trackers()) known = known || t.name == name;
      out->ops.tracker = &kTrackerOps;
    } else {
      known = projectorSpec(dev.get()) != nullptr;
      out->ops.output = &kOutputOps;
    }
    if (!known) {
      return report(err, len, "scene '" + s.name() + "' has no such device '" + name + "'",
                    PROCAM_ENODEV);
    }
    out->family = Family;
    out->self = dev.release();
    out->poll_fd = noFd;
    out->destroy = destroy;
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

// --- enumerate ---
// The devices of the scene named by the option "scene" (procamd --sim SCENE), one
// list per family, kept until the next call for that family.
struct Listed {
  std::vector<std::string> strings;  // stable storage: reserved before pointers are taken
  std::vector<std::array<procam_kv, 3>> kv;
  std::vector<procam_device_desc> descs;
};

template <procam_family Family>
int enumerate(const procam_config* config, const procam_device_desc** out, size_t* n, char* err,
              size_t len) {
  static std::mutex mutex;
  static Listed listed;
  try {
    *out = nullptr;
    *n = 0;
    std::string scene_name;
    for (size_t i = 0; config && i < config->n_options; ++i) {
      const procam_kv& o = config->options[i];
      if (o.key && o.value && std::strcmp(o.key, "scene") == 0) scene_name = o.value;
    }
    if (scene_name.empty()) return PROCAM_OK;  // not asked for a virtual rig
    auto world = SimWorld::open(scene_name);
    if (!world) return report(err, len, world.error().message, PROCAM_EINVAL);
    const Scene& scene = (*world)->scene();
    std::vector<std::string> names;
    if constexpr (Family == PROCAM_FAMILY_CAMERA) {
      for (const auto& c : scene.cameras()) names.push_back(c.name);
    } else if constexpr (Family == PROCAM_FAMILY_TILT) {
      for (const auto& t : scene.tiltSensors()) names.push_back(t.name);
    } else if constexpr (Family == PROCAM_FAMILY_TRACKER) {
      for (const auto& t : scene.trackers()) names.push_back(t.name);
    } else {
      for (const auto& p : scene.projectors()) names.push_back(p.name);
    }
    std::lock_guard lock(mutex);
    listed = Listed{};
    listed.strings.reserve(names.size() * 4 + 2);
    listed.kv.reserve(names.size());
    listed.descs.reserve(names.size());
    const char* subsystem = listed.strings.emplace_back("sim").c_str();
    const char* scene_value = listed.strings.emplace_back(scene_name).c_str();
    const char* role = listed.strings
                           .emplace_back(Family == PROCAM_FAMILY_CAMERA    ? "camera"
                                         : Family == PROCAM_FAMILY_TILT    ? "tilt"
                                         : Family == PROCAM_FAMILY_TRACKER ? "tracker"
                                                                           : "output")
                           .c_str();
    for (const auto& name : names) {
      const char* n_ptr = listed.strings.emplace_back(name).c_str();
      listed.kv.push_back({procam_kv{"PROCAM_ROLE", role}, procam_kv{"SIM_SCENE", scene_value},
                           procam_kv{"SIM_DEVICE", n_ptr}});
      procam_device_desc d{};
      d.family = Family;
      d.subsystem = subsystem;
      d.name = n_ptr;
      d.properties = listed.kv.back().data();
      d.n_properties = listed.kv.back().size();
      listed.descs.push_back(d);
    }
    *out = listed.descs.data();
    *n = listed.descs.size();
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

const procam_driver_factory kFactories[] = {
    {PROCAM_FAMILY_CAMERA, "sim-camera", "virtual rig camera (ray-cast rendering)", probe,
     create<PROCAM_FAMILY_CAMERA>, enumerate<PROCAM_FAMILY_CAMERA>},
    {PROCAM_FAMILY_TILT, "sim-tilt", "virtual rig accelerometer", probe, create<PROCAM_FAMILY_TILT>,
     enumerate<PROCAM_FAMILY_TILT>},
    {PROCAM_FAMILY_TRACKER, "sim-tracker", "virtual rig head tracker", probe,
     create<PROCAM_FAMILY_TRACKER>, enumerate<PROCAM_FAMILY_TRACKER>},
    {PROCAM_FAMILY_OUTPUT, "sim-output", "virtual rig projector", probe,
     create<PROCAM_FAMILY_OUTPUT>, enumerate<PROCAM_FAMILY_OUTPUT>},
};

const procam_plugin_table kTable = {PROCAM_PLUGIN_ABI_VERSION, "sim", "1", 4, kFactories};

}  // namespace
}  // namespace procam::sim::mock

extern "C" const procam_plugin_table* procam_sim_plugin_entry(void) {
  return &procam::sim::mock::kTable;
}
