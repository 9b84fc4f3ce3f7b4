// Several projectors on one planar wall shown as one display ([Raskar02] §4.2.4,
// PROTOCOL.md "Keystone from the rig model"): with `keystone rig on` and two or more
// usable outputs whose projectors the rig maps onto the same display plane (route (b′)
// plane_homography), the content fills the largest upright rectangle of its aspect
// inside the union of their images (blend/tiled_display.hpp) and every output shows
// its share through its own homography, feathered in the overlaps (eq. 4.3,
// blend/feather.hpp). The display is made on the compute worker (the feathering
// takes about half a second for four 1280x800 outputs) and kept until the content's
// size, the outputs or the rig change.
#include <cmath>
#include <sstream>

#include "blend/feather.hpp"
#include "blend/response.hpp"
#include "daemon.hpp"
#include "log.hpp"

namespace procam::daemon {

using nlohmann::json;

int KeystoneRuntime::Tiled::index(const std::string& output) const {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    if (outputs[i] == output) return static_cast<int>(i);
  }
  return -1;
}

std::vector<std::pair<std::string, const rig::RigProjector*>> Daemon::rigTiles() const {
  std::vector<std::pair<std::string, const rig::RigProjector*>> tiles;
  for (const auto& e : devices_.entries()) {
    if (e.description.family != PROCAM_FAMILY_OUTPUT || !e.usable()) continue;
    const rig::RigProjector* p = rig_.projectorForOutput(e.name);
    if (p && p->plane_homography && p->width > 1 && p->height > 1) tiles.emplace_back(e.name, p);
  }
  return tiles;
}

namespace {

// A projector's measured response (rig.json photometric), if it has one.
std::optional<blend::ProjectorResponse> responseOf(const rig::RigProjector& p) {
  const json& ph = p.photometric;
  if (!ph.is_object()) return std::nullopt;
  const auto number = [&](const char* key) {
    const auto it = ph.find(key);
    return it != ph.end() && it->is_number() ? it->get<double>() : std::nan("");
  };
  blend::ProjectorResponse r;
  r.gamma = number("response_gamma");
  r.black = number("black");
  r.white = number("white");
  if (!(r.gamma >= 1 && r.gamma <= 4) || !std::isfinite(r.black) || !(r.white > r.black)) {
    return std::nullopt;
  }
  return r;
}

// What a display is made for: the content's size and every tile's mapping.
std::string tiledKey(cv::Size content,
                     const std::vector<std::pair<std::string, const rig::RigProjector*>>& tiles) {
  std::ostringstream key;
  key.precision(17);
  key << content.width << 'x' << content.height;
  for (const auto& [name, p] : tiles) {
    key << ' ' << name << ' ' << p->width << 'x' << p->height;
    const auto& ph = *p->plane_homography;
    for (int i = 0; i < 9; ++i) key << ' ' << ph.H(i / 3, i % 3);
    key << ' ' << ph.basis.origin.transpose() << ' ' << ph.basis.u.transpose() << ' '
        << ph.basis.v.transpose() << ' ' << p->photometric.dump();
  }
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
  const std::string key = tiledKey(content, tiles);
  if (key == k.tiled_key) return k.tiled.get();  // made, failed, or on its way
  k.tiled_key = key;
  k.tiled_error.clear();
  k.tiled.reset();               // made for something else: no output draws with it meanwhile
  if (k.tiling) return nullptr;  // the job running sees the new key when it ends
  k.tiling = true;
  std::vector<std::string> names;
  std::vector<blend::DisplayTile> input;
  std::vector<blend::ProjectorResponse> responses;
  for (const auto& [name, p] : tiles) {
    names.push_back(name);
    input.push_back({*p->plane_homography, p->width, p->height});
    if (auto r = responseOf(*p)) responses.push_back(*r);
  }
  logInfo("display across " + std::to_string(names.size()) + " outputs: solving");
  compute_worker_->submit(
      [this, key, content, names, input, responses] {
        auto made = std::make_shared<KeystoneRuntime::Tiled>();
        std::string error;
        auto display = blend::solveTiledDisplay(input, content.width, content.height);
        if (display) {
          std::vector<blend::FeatherTile> feather;
          for (std::size_t t = 0; t < input.size(); ++t) {
            feather.push_back({display->footprints[t], display->plane_to_framebuffer[t],
                               input[t].width, input[t].height});
          }
          auto weights = blend::featherWeights(feather);
          if (weights) {
            for (const cv::Mat& w : *weights) made->alpha.push_back(blend::alphaMask(w));
            // Brightness matched to the dimmest projector and weights in linear light, when
            // every projector's response is measured; the assumed gamma otherwise.
            made->measured = responses.size() == input.size();
            const std::vector<double> gains = made->measured
                                                  ? blend::matchedGains(responses)
                                                  : std::vector<double>(input.size(), 1.0);
            for (std::size_t t = 0; t < input.size(); ++t) {
              const double gamma = made->measured ? responses[t].gamma : kAssumedGamma;
              made->gamma.push_back(gamma);
              made->gain.push_back(gains[t]);
              auto lut = blend::weightLut(gamma, gains[t]);
              if (!lut) {
                error = lut.error().message;
                break;
              }
              made->weight_lut.push_back(*lut);
            }
            made->content = content;
            made->outputs = names;
            made->display = std::move(*display);
          } else {
            error = weights.error().message;
          }
        } else {
          error = display.error().message;
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
          {"union_area_m2", d.union_area_m2},
          {"cell_m", d.cell_m},
          {"basis",
           {{"origin", {d.basis.origin.x(), d.basis.origin.y(), d.basis.origin.z()}},
            {"u", {d.basis.u.x(), d.basis.u.y(), d.basis.u.z()}},
            {"v", {d.basis.v.x(), d.basis.v.y(), d.basis.v.z()}}}},
          {"tiles", tiles},
          {"blend",
           {{"weights", "feathered"},
            {"response", k.tiled->measured ? "measured" : "assumed gamma 2.2"}}}};
}

}  // namespace procam::daemon
