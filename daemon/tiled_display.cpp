// Several projectors on one planar wall shown as one display ([Raskar02] §4.2.4,
// PROTOCOL.md "Keystone from the rig model"): with `keystone rig on` and two or more
// usable outputs whose projectors the rig maps onto the same display plane
// (blend/rig_tiles.hpp), the content fills the largest upright rectangle of its aspect
// inside the union of their images, or the rectangle [keystone] display_centre and
// display_size give (blend/tiled_display.hpp), and every output shows
// its share through its own homography, feathered in the overlaps (eq. 4.3,
// blend/feather.hpp). The display is made on the compute worker (the feathering
// takes about half a second for four 1280x800 outputs) and kept until the content's
// size, the outputs or the rig change.
#include <cmath>
#include <functional>
#include <sstream>
#include <string_view>

#include "blend/rig_tiles.hpp"
#include "blend/tiled_blend.hpp"
#include "daemon.hpp"
#include "log.hpp"

namespace procam::daemon {

using nlohmann::json;

int KeystoneRuntime::DisplayShares::index(const std::string& output) const {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    if (outputs[i] == output) return static_cast<int>(i);
  }
  return -1;
}

std::vector<Daemon::RigTile> Daemon::rigTiles() const {
  std::vector<RigTile> tiles;
  for (const auto& e : devices_.entries()) {
    if (e.description.family != PROCAM_FAMILY_OUTPUT || !e.usable()) continue;
    const rig::RigProjector* p = rig_.projectorForOutput(e.name);
    if (!p) continue;
    if (auto tile = blend::displayTile(*p, rig_.surface)) {
      tiles.push_back({e.name, *tile, rigResponse(*p)});
    }
  }
  return tiles;
}

const Daemon::RigResponse& Daemon::rigResponse(const rig::RigProjector& projector) const {
  if (rig_responses_generation_ != rig_generation_) {
    rig_responses_.clear();
    rig_responses_generation_ = rig_generation_;
  }
  auto it = rig_responses_.find(projector.name);
  if (it != rig_responses_.end()) return it->second;
  RigResponse r{blend::projectorResponse(projector), {}};
  if (r.response) {
    // What a display is made with: the fitted response, the camera, and the brightness
    // map (by a digest of its nodes).
    std::ostringstream key;
    key.precision(17);
    key << " r " << r.response->gamma << ' ' << r.response->black << ' ' << r.response->white << ' '
        << r.response->camera;
    if (const auto& map = r.response->brightness) {
      const auto* bytes = map->white.ptr<char>();
      key << " b " << map->step << ' '
          << std::hash<std::string_view>{}(
                 std::string_view(bytes, map->white.total() * map->white.elemSize()));
    }
    r.key = key.str();
  }
  return rig_responses_.emplace(projector.name, std::move(r)).first->second;
}

std::optional<blend::WorldRect> Daemon::displayRect() const {
  const KeystoneConfig& k = config_.keystone;
  if (!k.display_centre || !k.display_size) return std::nullopt;
  const auto& c = *k.display_centre;
  return blend::WorldRect{Vec3(c[0], c[1], c[2]), (*k.display_size)[0], (*k.display_size)[1]};
}

namespace {

// What a display is made for: the content's size, every tile's mapping and response,
// and the rectangle the configuration gives.
std::string tiledKey(cv::Size content, const std::vector<Daemon::RigTile>& tiles,
                     const std::optional<blend::WorldRect>& rect) {
  std::ostringstream key;
  key.precision(17);
  key << content.width << 'x' << content.height;
  for (const auto& t : tiles) {
    key << ' ' << t.output << ' ' << t.tile.width << 'x' << t.tile.height;
    const auto& ph = t.tile.projector_to_plane;
    for (int i = 0; i < 9; ++i) key << ' ' << ph.H(i / 3, i % 3);
    key << ' ' << ph.basis.origin.transpose() << ' ' << ph.basis.u.transpose() << ' '
        << ph.basis.v.transpose();
    key << t.response.key;
  }
  if (rect)
    key << " rect " << rect->centre.transpose() << ' ' << rect->width << ' ' << rect->height;
  return key.str();
}

}  // namespace

const KeystoneRuntime::Tiled* Daemon::tiledDisplay(cv::Size content) {
  KeystoneRuntime& k = keystone_rt_;
  const auto tiles = rigTiles();
  if (tiles.size() < 2 || content.width < 1 || content.height < 1) {
    k.tiled.reset();
    k.tiled_key.clear();
    k.tiled_error.clear();
    return nullptr;
  }
  const std::string key = tiledKey(content, tiles, displayRect());
  if (key == k.tiled_key) return k.tiled.get();  // made, failed, or on its way
  k.tiled_key = key;
  k.tiled_error.clear();
  k.tiled.reset();               // made for something else: no output draws with it meanwhile
  if (k.tiling) return nullptr;  // the job running sees the new key when it ends
  k.tiling = true;
  std::vector<std::string> names;
  std::vector<blend::DisplayTile> input;
  std::vector<std::optional<blend::ProjectorResponse>> responses;
  for (const auto& t : tiles) {
    names.push_back(t.output);
    input.push_back(t.tile);
    responses.push_back(t.response.response);
  }
  blend::TiledDisplayOptions options;
  options.world_rect = displayRect();
  logInfo("display across " + std::to_string(names.size()) + " outputs: solving");
  compute_worker_->submit(
      [this, key, content, names, input, responses, options] {
        auto made = std::make_shared<KeystoneRuntime::Tiled>();
        std::string error;
        // Brightness matched to the dimmest projector and weights in linear light when
        // every projector's response is measured; the assumed gamma otherwise.
        auto blended = blend::makeTiledBlend(input, responses, content, options);
        if (blended) {
          static_cast<blend::TiledBlend&>(*made) = std::move(*blended);
          made->weights.clear();  // the outputs take the 8-bit mask
          made->content = content;
          made->outputs = names;
        } else {
          error = blended.error().message;
        }
        return [this, key, made, error] {
          KeystoneRuntime& k = keystone_rt_;
          k.tiling = false;
          if (key == k.tiled_key) {
            if (error.empty()) {
              k.tiled = made;
              logInfo("display across " + std::to_string(made->outputs.size()) +
                      " outputs: " + std::to_string(2 * made->display.rect.half_width) + " m x " +
                      std::to_string(2 * made->display.rect.half_height) + " m");
            } else {
              k.tiled.reset();
              k.tiled_error = error;
              warn("no display across the rig's projectors: " + error);
            }
            broadcast("keystone", keystoneJson());
          } else {
            k.tiled_key.clear();  // made for something older: make it again
          }
          refreshOutputs();
        };
      },
      [this, key](const std::string& what) {
        KeystoneRuntime& k = keystone_rt_;
        k.tiling = false;
        if (key == k.tiled_key) {
          k.tiled.reset();
          k.tiled_error = what;
          warn("no display across the rig's projectors: " + what);
          broadcast("keystone", keystoneJson());
        }
      });
  return nullptr;
}

json Daemon::tiledDisplayJson() const {
  const KeystoneRuntime& k = keystone_rt_;
  if (!k.tiled) {
    if (!k.tiled_error.empty()) return {{"unavailable", k.tiled_error}};
    if (k.tiling) return {{"state", "solving"}};
    return nullptr;
  }
  const auto& d = k.tiled->display;
  json tiles = json::array();
  for (std::size_t t = 0; t < k.tiled->outputs.size(); ++t) {
    json quad = json::array();
    for (const Vec2& q : d.footprints[t]) quad.push_back({q.x(), q.y()});
    tiles.push_back({{"output", k.tiled->outputs[t]},
                     {"footprint_m", quad},
                     {"response_gamma", k.tiled->gamma[t]},
                     {"gain", k.tiled->gain[t]}});
  }
  return {{"state", "ready"},
          {"outputs", k.tiled->outputs},
          {"content_size", {k.tiled->content.width, k.tiled->content.height}},
          {"rect_m",
           {{"centre", {d.rect.centre.x(), d.rect.centre.y()}},
            {"size", {2 * d.rect.half_width, 2 * d.rect.half_height}}}},
          {"rect_source", displayRect() ? "config" : "largest"},
          {"union_area_m2", d.union_area_m2},
          {"cell_m", d.cell_m},
          {"basis",
           {{"origin", {d.basis.origin.x(), d.basis.origin.y(), d.basis.origin.z()}},
            {"u", {d.basis.u.x(), d.basis.u.y(), d.basis.u.z()}},
            {"v", {d.basis.v.x(), d.basis.v.y(), d.basis.v.z()}}}},
          {"tiles", tiles},
          {"blend",
           {{"weights", "feathered"},
            {"response", k.tiled->measured ? "measured" : "assumed gamma 2.2"},
            {"photometric", blend::matchingJson(*k.tiled)}}}};
}

}  // namespace procam::daemon
