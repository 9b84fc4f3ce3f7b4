// What a calibrate run needs and what it learnt (calibration_plan.hpp): the devices,
// camera models and route of a plan, and a run's outcome as a rig-model update and the
// reply that shows it.
#include "calibration_plan.hpp"

#include <algorithm>

#include "protocol.hpp"
#include "rig_store.hpp"
#include "structured_light/adaptive_scan.hpp"
#include "surface/surface_model.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;
using Failure = CalibrationFailure;

namespace {

// A camera's K, distortion and pose: the camera of that name in the rig model, as
// procam-calibrate camera/stereo, `procamd --rig` or an earlier calibrate put it. Without
// `pose_needed` (a camera of route (b′) at several positions other than the reference,
// registered through the projectors it shares) K and distortion are enough.
tl::expected<geom::CameraModel, Failure> cameraModel(const DeviceEntry& e, const rig::RigModel& rig,
                                                     bool pose_needed = true) {
  if (const rig::RigCamera* c = rig.camera(e.name)) {
    if (c->pose_known || !pose_needed) return c->model;
    return tl::unexpected(
        Failure{code::kUnavailable,
                "camera '" + e.name +
                    "' has intrinsics but no pose in the rig model (calibrated alone "
                    "from board views): calibrate the camera pair with procam-calibrate "
                    "stereo, or give the rig a pose for it with procamd --rig"});
  }
  return tl::unexpected(Failure{
      code::kUnavailable, "camera '" + e.name +
                              "' is not calibrated: the rig model has no camera of that name "
                              "(calibrate the cameras with procam-calibrate stereo and install "
                              "the result with procamd --rig)"});
}

json positionJson(const geom::Pose& pose) {
  const Vec3 c = pose.center();
  return {c.x(), c.y(), c.z()};
}

rig::RigProjector projectorEntry(const CalibrationPlan& plan) {
  rig::RigProjector p;
  p.name = p.output = plan.output.name;
  p.width = plan.set.options.width;
  p.height = plan.set.options.height;
  return p;
}

// rig.json's photometric record of a projector: its response as the camera saw it.
json responseJson(const blend::ProjectorResponse& r, const CalibrationCamera& camera) {
  json out = {{"response_gamma", r.gamma}, {"black", r.black},   {"white", r.white},
              {"fit_rms", r.rms},          {"levels", r.levels}, {"camera", camera.device.name},
              {"measured", utcNow()}};
  if (r.brightness) out["brightness"] = blend::brightnessToJson(*r.brightness);
  return out;
}

}  // namespace

// The devices and camera models of a run; everything but the capture itself.
tl::expected<CalibrationPlan, Failure> makeCalibrationPlan(DeviceSet& devices,
                                                           const CalibrationArgs& args,
                                                           const CalibrationConfig& latency,
                                                           const rig::RigModel& rig) {
  auto pick = [&](procam_family family, const std::string& name,
                  const std::vector<const DeviceEntry*>& taken) -> const DeviceEntry* {
    for (const auto& e : devices.entries()) {
      if (e.description.family != family || !e.usable()) continue;
      if (!name.empty() ? e.name == name
                        : std::find(taken.begin(), taken.end(), &e) == taken.end()) {
        return &e;
      }
    }
    return nullptr;
  };
  const DeviceEntry* out = pick(PROCAM_FAMILY_OUTPUT, args.output, {});
  if (!out) {
    return tl::unexpected(Failure{
        code::kUnavailable, args.output.empty() ? "calibration needs a projector output"
                                                : "no usable output named '" + args.output + "'"});
  }
  // Route (b′) when asked for (a plane, or one camera named), or when one camera is
  // all there is and the rig model knows the display plane; route (a) otherwise.
  int usable = 0;
  for (const auto& e : devices.entries()) {
    usable += e.description.family == PROCAM_FAMILY_CAMERA && e.usable();
  }
  // Several cameras on a plane: route (b′) from cameras at several positions, the first
  // one the calibrated reference (wall_views_route.hpp).
  const bool several =
      !args.board && ((args.plane && args.cameras.size() > 1) || args.cameras.size() > 2);
  const bool planar = several || args.plane || args.board || args.cameras.size() == 1 ||
                      (args.cameras.empty() && usable == 1 && rig.surface.plane);
  const std::size_t wanted = several ? args.cameras.size() : planar ? 1 : 2;
  if (several && args.auto_settle) {
    // The probe times every camera against the projector it scans; at several positions
    // a camera may not see that projector at all.
    return tl::unexpected(Failure{
        code::kBadArgument,
        "settle_frames \"auto\" (the request's, or [calibration] settle_frames of procamd.toml "
        "when the request gives none) times every camera on each projector, and cameras at "
        "several positions do not all see every projector: give settle_frames as a number "
        "(latency measures it per output and camera)"});
  }
  std::vector<const DeviceEntry*> cams;
  for (std::size_t i = 0; i < wanted; ++i) {
    const std::string name = args.cameras.empty() ? "" : args.cameras[i];
    const DeviceEntry* c = pick(PROCAM_FAMILY_CAMERA, name, cams);
    if (!c) {
      return tl::unexpected(
          Failure{code::kUnavailable,
                  !name.empty() ? "no usable camera named '" + name + "'"
                  : planar      ? std::string("calibration needs a calibrated camera; none is open")
                           : "calibration needs two calibrated cameras (route a), or one and the "
                             "display plane (route b′: the argument \"plane\" or the rig "
                             "model's surface plane); " +
                                 std::to_string(cams.size()) + " usable camera(s) open"});
    }
    cams.push_back(c);
  }
  CalibrationPlan plan;
  if (planar && args.board) {
    plan.board = args.board;
    plan.board_text = args.board_text;
  } else if (planar) {
    plan.plane = args.plane ? args.plane : rig.surface.plane;
    plan.plane_from_rig = !args.plane;
    if (!plan.plane) {
      return tl::unexpected(
          Failure{code::kUnavailable,
                  std::string(several ? "route (b′) from cameras at several positions"
                                      : "route (b′) with one camera") +
                      " needs the display plane: give \"plane\" [a, b, c, d] "
                      "(world, metres), or \"board\" (a calibration board fixed flat on it, e.g. "
                      "\"aprilgrid:6x4:0.15\"), or put surface.plane in the rig model"});
    }
  }
  // The adaptive path also takes two cameras and no plane: they triangulate the plane
  // on a planar surface and scan it fully (route (a)) otherwise.
  if (args.tags && (several || args.board || (!planar && !args.adaptive))) {
    return tl::unexpected(Failure{
        code::kBadArgument,
        args.adaptive ? std::string("\"mode\": \"adaptive\" is route (b′) with one camera and "
                                    "the display plane (\"plane\" or the rig model's surface "
                                    "plane), or two cameras and no plane; not with a board or "
                                    "cameras at several positions")
                      : std::string("\"mode\": \"apriltag\" is route (b′) with one camera and "
                                    "the display plane (\"plane\" or the rig model's surface "
                                    "plane), not with a board or several cameras")});
  }
  uint32_t w = 0, h = 0;
  const auto& raw = out->device.raw();
  if (raw.ops.output->get_mode(raw.self, &w, &h, &plan.refresh_hz) != PROCAM_OK || w < 2 || h < 2) {
    return tl::unexpected(Failure{code::kUnavailable, "output '" + out->name + "' has no mode"});
  }
  if (args.tags) {
    auto tags = makeFiducialFrame({static_cast<int>(w), static_cast<int>(h)});
    if (!tags) return tl::unexpected(Failure{code::kUnavailable, tags.error()});
    plan.tags = *tags;
  }
  if (args.adaptive) {
    sl::AdaptiveOptions coarse;
    coarse.full.width = static_cast<int>(w);
    coarse.full.height = static_cast<int>(h);
    auto set = sl::coarsePatternSet(coarse);
    if (!set) return tl::unexpected(Failure{code::kBadArgument, set.error().message});
    plan.coarse = std::move(*set);
  }
  if (!(plan.refresh_hz > 0)) plan.refresh_hz = 60;
  sl::PatternOptions po;
  po.width = static_cast<int>(w);
  po.height = static_cast<int>(h);
  po.mode = args.mode;
  po.step = args.step;
  po.phase_steps = args.phase_steps;
  auto set = sl::makePatternSet(po);
  if (!set) return tl::unexpected(Failure{code::kBadArgument, set.error().message});
  plan.set = std::move(*set);
  plan.grid = args.grid;
  plan.response = args.response.value_or(false);
  plan.settle_frames = args.settle_frames;
  plan.auto_settle = args.auto_settle;
  plan.latency = latency;
  plan.output = {out->name, out->device.share()};
  for (const DeviceEntry* c : cams) {
    auto model = cameraModel(*c, rig, !several || c == cams.front());
    if (!model) return tl::unexpected(model.error());
    plan.cameras.push_back({{c->name, c->device.share()}, *model});
  }
  return plan;
}

namespace {

// Route (a): the projector bound to the output gets K, pose and its surface; the
// cameras keep their models.
Learnt learntByStereoRoute(const CalibrationPlan& plan, const CalibrationOutcome& result) {
  const calib::StereoRouteResult& route = result.route;
  Learnt out;
  rig::RigProjector projector = projectorEntry(plan);
  projector.K = route.projector.K;
  projector.pose = route.projector.pose;
  projector.scale_known = route.projector.scale_known;
  projector.rms_px = route.projector.rms_px;
  projector.points = route.projector.points;
  // The adaptive path's coarse pass says why the full scan followed it.
  std::string how = plan.coarse ? "a coarse Gray pass, then structured light, route (a): cameras"
                                : "structured light, route (a): cameras";
  for (const auto& c : plan.cameras) how += " " + c.device.name;
  projector.calibrated = {how, utcNow()};
  out.update.projectors.push_back(projector);
  if (route.surface.planar) {
    out.update.surface.plane = route.surface.plane;
    out.update.surface.plane_rms_m = route.surface.plane_rms;
  } else {
    const std::string file = meshFileName(projector.name);
    out.update.surface.meshes[projector.name] = file;
    out.meshes[file] = surface::toPly(route.surface.mesh);
  }
  const json learnt = rig::rigToJson(out.update);
  out.reply = {{"route", "a"},
               {"projector", learnt["projectors"][0]},
               {"position", positionJson(route.projector.pose)},
               {"reprojection_rms_px", route.projector.rms_px},
               {"surface", learnt["surface"]},
               {"surface_type", route.surface.planar ? "plane" : "mesh"},
               {"triangulated", route.triangulated}};
  return out;
}

// Route (b′): the projector bound to the output gets its collineation with the
// display plane (no K, no pose); a plane given as an argument or found from a board
// becomes the rig's surface, one read from the rig stays as it was.
Learnt learntByPlaneRoute(const CalibrationPlan& plan, const CalibrationOutcome& result) {
  const calib::PlaneHomographyResult& route = *result.planar;
  // Route (b′) always has a plane: the request's or the rig's (plan.plane), a board's,
  // or the one two cameras triangulated.
  geom::Plane plane = plan.plane.value_or(geom::Plane{});
  const char* source = plan.plane_from_rig ? "rig" : "request";
  if (result.board) {
    plane = result.board->plane;
    source = "board";
  } else if (result.triangulated_plane) {
    plane = result.triangulated_plane->plane;
    source = "cameras";
  }
  Learnt out;
  rig::RigProjector projector = projectorEntry(plan);
  projector.intrinsics_known = false;
  projector.pose_known = false;
  projector.plane_homography = route.projector_to_plane;
  projector.rms_px = route.rms_projector_px;
  projector.points = static_cast<long>(route.inliers);
  std::string cameras = "camera " + plan.cameras.at(0).device.name;
  if (plan.wallViews()) {
    cameras = "cameras at several positions, " + plan.cameras.at(0).device.name + " (reference)";
    for (std::size_t c = 1; c < plan.cameras.size(); ++c) {
      cameras += ", " + plan.cameras[c].device.name;
    }
  }
  projector.calibrated = {
      std::string(!plan.tags ? "structured light"
                  // An adaptive pass that went on to the full scan (a planar scene after all).
                  : result.coarse.contains("then") ? "a coarse Gray pass, then structured light"
                  : plan.coarse ? "a coarse Gray pass (planar) and one AprilTag frame"
                                : "one AprilTag frame") +
          ", route (b′): " + cameras + ", plane from the " +
          (result.board                ? "board " + plan.board_text
           : result.triangulated_plane ? "cameras " + plan.cameras.at(0).device.name + " and " +
                                             plan.cameras.at(1).device.name + " (a planar scene)"
           : plan.plane_from_rig ? std::string("rig model")
                                 : std::string("calibrate request")),
      utcNow()};
  out.update.projectors.push_back(projector);
  if (!plan.plane_from_rig || result.triangulated_plane) out.update.surface.plane = plane;
  rig::RigModel shown = out.update;
  shown.surface.plane = plane;
  const json learnt = rig::rigToJson(shown);
  out.reply = {{"route", "b'"},
               {"projector", learnt["projectors"][0]},
               {"reprojection_rms_px", route.rms_projector_px},
               {"surface", learnt["surface"]},
               {"surface_type", "plane"},
               {"plane_source", source},
               {"homography",
                {{"rms_camera_px", route.rms_camera_px},
                 {"rms_projector_px", route.rms_projector_px},
                 {"condition", route.condition},
                 {"coverage", route.coverage},
                 {"samples", route.samples},
                 {"inliers", route.inliers}}}};
  if (result.triangulated_plane) {
    out.reply["triangulated_plane"] = {{"rms_m", result.triangulated_plane->rms},
                                       {"inliers", result.triangulated_plane->inliers.size()}};
  }
  if (result.board) {
    out.reply["board"] = {{"spec", plan.board_text},
                          {"points", result.board->points},
                          {"rms_px", result.board->rms_px},
                          {"incidence_deg", result.board->incidence_deg}};
  }
  return out;
}

}  // namespace

Learnt learntFromRun(const CalibrationPlan& plan, const CalibrationOutcome& outcome) {
  Learnt learnt =
      outcome.planar ? learntByPlaneRoute(plan, outcome) : learntByStereoRoute(plan, outcome);
  if (outcome.response) {
    const json photometric = responseJson(*outcome.response, plan.cameras[0]);
    for (auto& p : learnt.update.projectors) p.photometric = photometric;
    learnt.reply["response"] = photometric;
    // The reply names the brightness map's extent, not its nodes.
    if (const auto& map = outcome.response->brightness) {
      double lo = 0, hi = 0;
      cv::minMaxLoc(map->white, &lo, &hi);
      learnt.reply["response"]["brightness"] = {{"nodes", {map->white.cols, map->white.rows}},
                                                {"step_px", map->step},
                                                {"min_over_max", hi > 0 ? lo / hi : 0.0}};
    } else {
      learnt.reply["response"]["brightness"] = {{"measured", false},
                                                {"why", outcome.brightness_note}};
    }
  } else if (!outcome.response_note.empty()) {
    learnt.reply["response"] = {{"measured", false}, {"why", outcome.response_note}};
  }
  if (!outcome.coarse.is_null()) learnt.reply["coarse"] = outcome.coarse;
  return learnt;
}

}  // namespace procam::daemon
