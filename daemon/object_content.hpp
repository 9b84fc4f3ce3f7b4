#pragma once
// Content on an object rig (rig.json surface.object; [Raskar02] §5.2, shader lamps): the
// textured model a client loads is the look the projectors paint on the physical object.
// The object's geometry and place come from the rig model only; the content gives the
// texture coordinates (on the same model), the texture and the material. Prepared on a
// worker: each output's frame rendered from its projector with the radiance correction
// and the feathering weights (shader_lamps/rig_lamps.hpp). Pure but for reading files.
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "content_access.hpp"
#include "content_mesh.hpp"
#include "core/types.hpp"
#include "rig/rig_model.hpp"
#include "shader_lamps/appearance.hpp"
#include "shader_lamps/rig_lamps.hpp"
#include "tl/expected.hpp"

namespace procam::daemon {

// What `content load` asked for on an object rig.
struct ObjectLook {
  std::string file;     // the textured model (.obj / .ply); empty: the rig's model's coordinates
  std::string texture;  // an image under the content roots; empty: white
  double specular = 0;  // Blinn-Phong highlight for the viewer's eye, 0..1
  double shininess = 32;
};

// An output to paint and the mode it shows.
struct ObjectOutput {
  std::string name;
  cv::Size mode;
};

struct PreparedObject {
  // Output name -> its frame (RGBA, the output's mode); an output without a posed
  // projector of the object's size gets none (`info` says why).
  std::map<std::string, std::shared_ptr<const cv::Mat>> frames;
  std::shared_ptr<const lamps::RigLamps> lamps;  // views and weights: kept for a new eye
  std::shared_ptr<const lamps::Material> material;
  std::vector<std::string> shown_by;  // per lamp: the output showing it; empty: none
  bool view_dependent = false;        // the look depends on the eye (specular)
  nlohmann::json info;                // the `content` object of replies
};

// The rig's object model, read from `state_dir`, placed in the world.
Result<geom::TriangleMesh> rigObjectMesh(const rig::RigModel& rig, const std::string& state_dir);

// Reads the look (a model's texture coordinates, or the rig's model's own with an image
// alone) and paints the rig's object with every output's projector; projectors
// of the rig without a usable output are off (what only they reach is reported unlit).
// `unavailable` when the rig has no object or no posed projector for any output;
// `bad-argument` when the content is not the rig's object model (other vertices or
// faces), has no texture coordinates for a texture, or the material is out of range;
// `io-error` and the content codes when a file cannot be read.
tl::expected<PreparedObject, MeshFailure> prepareObjectContent(
    const ContentAccess& access, const std::string& state_dir, const rig::RigModel& rig,
    const ObjectLook& look, const std::vector<ObjectOutput>& outputs,
    const std::optional<Vec3>& eye, const nlohmann::json& eye_source);

// The frames of a prepared object for another eye (the view-dependent part moves).
Result<std::map<std::string, std::shared_ptr<const cv::Mat>>> paintObjectFrames(
    const PreparedObject& prepared, const std::optional<Vec3>& eye, nlohmann::json* projectors);

}  // namespace procam::daemon
