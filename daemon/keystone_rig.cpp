// Keystone from the rig model (PROTOCOL.md, "Keystone from the rig model"): on a
// planar wall whose collineation with the projector the rig model gives (route (b′)'s
// plane_homography, or the projector's K and pose and the surface plane), the content is shown in
// the largest upright rectangle of its aspect inside the projector's image on the wall ([Raskar02]
// §3.2.5, §4.2.1). No sensor is read and nothing is solved in the background: the
// solution is a small linear program, made again whenever a warp is needed.
#include "blend/rig_tiles.hpp"
#include "daemon.hpp"
#include "keystone/rig_keystone.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

Result<keystone::KeystoneSolution> Daemon::solveRigKeystone(cv::Size content) const {
  auto* self = const_cast<Daemon*>(this);  // device queries do not change the set
  const DeviceEntry* out = self->devices_.firstUsable(PROCAM_FAMILY_OUTPUT);
  if (!out) {
    return fail(ErrorCode::kNotFound,
                "keystone from the rig needs a projector output; none is open");
  }
  const rig::RigProjector* p = rig_.projectorForOutput(out->name);
  if (!p) {
    return fail(ErrorCode::kNotFound, "keystone from the rig needs the projector on output '" +
                                          out->name + "' in the rig model; it has none");
  }
  auto tile = blend::displayTile(*p, rig_.surface);
  if (!tile) {
    return fail(ErrorCode::kNotFound,
                "keystone from the rig needs the projector on output '" + out->name +
                    "' mapped onto the display plane: " + tile.error().message);
  }
  if (content.width < 1 || content.height < 1) {
    return fail(ErrorCode::kInvalidInput, "nothing to show: the content has no size");
  }
  keystone::RigKeystoneProblem problem;
  problem.projector_to_plane = tile->projector_to_plane;
  problem.width = tile->width;
  problem.height = tile->height;
  problem.content_width = content.width;
  problem.content_height = content.height;
  auto s = keystone::solveRigKeystone(problem);
  if (!s) {
    return fail(s.error().code,
                "keystone from the rig model of output '" + out->name + "': " + s.error().message);
  }
  return s;
}

std::optional<Mat3> Daemon::rigKeystoneWarp(cv::Size content) const {
  if (!settings_.rig_keystone) return std::nullopt;
  auto s = solveRigKeystone(content);
  if (!s) return std::nullopt;
  return s->H;
}

Result<void> Daemon::setRigKeystone(bool enable) {
  if (enable) {
    auto s = solveRigKeystone(currentSourceSize());
    if (!s) return tl::unexpected(s.error());
    // One correction at a time: the rig's replaces the tilt sensor's.
    if (settings_.auto_keystone) (void)setAutoKeystone(false);
  }
  settings_.rig_keystone = enable;
  return {};
}

json Daemon::rigKeystoneJson(cv::Size content) const {
  auto s = solveRigKeystone(content);
  if (!s) return {{"unavailable", s.error().message}};
  json quad = json::array();
  for (const Vec2& q : s->wall_quad) quad.push_back({q.x(), q.y()});
  const auto& r = s->rect;
  return {
      {"footprint_m", quad},
      {"rect_m",
       {{"centre", {r.centre.x(), r.centre.y()}}, {"size", {2 * r.half_width, 2 * r.half_height}}}},
      {"scale", s->scale}};
}

}  // namespace procam::daemon
