#include "object_content.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "content/mesh_content.hpp"
#include "json_matrix.hpp"
#include "output_frames.hpp"
#include "protocol.hpp"
#include "shader_lamps/object_model.hpp"
#include "shader_lamps/object_placement.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

namespace {

tl::unexpected<MeshFailure> failure(const char* c, const std::string& message) {
  return tl::unexpected(MeshFailure{c, "object content: " + message});
}

// The content is the rig's object model when it has the same faces over the same
// vertices (to a micrometre in the model's units, far below what any rig resolves): its
// texture coordinates then belong to the geometry the rig placed.
std::optional<std::string> differsFrom(const geom::TriangleMesh& content,
                                       const geom::TriangleMesh& model) {
  if (content.vertices.size() != model.vertices.size() ||
      content.faces.size() != model.faces.size()) {
    return "it has " + std::to_string(content.vertices.size()) + " vertices and " +
           std::to_string(content.faces.size()) + " triangles, the rig's object model " +
           std::to_string(model.vertices.size()) + " and " + std::to_string(model.faces.size());
  }
  for (std::size_t i = 0; i < model.vertices.size(); ++i) {
    if ((content.vertices[i] - model.vertices[i]).norm() >
        1e-6 * std::max(1.0, model.vertices[i].norm())) {
      return "its vertex " + std::to_string(i) + " is not the model's";
    }
  }
  for (std::size_t f = 0; f < model.faces.size(); ++f) {
    if (content.faces[f] != model.faces[f])
      return "its triangle " + std::to_string(f) + " is not the model's";
  }
  return std::nullopt;
}

// The rig's placement of its object, world = R · model + t.
lamps::ObjectPlacement placementOf(const rig::RigObject& o) {
  lamps::ObjectPlacement p;
  p.R = o.R;
  p.t = o.t;
  return p;
}

}  // namespace

Result<geom::TriangleMesh> rigObjectMesh(const rig::RigModel& rig, const std::string& state_dir) {
  if (!rig.surface.object) return fail(ErrorCode::kNotFound, "the rig model has no object");
  const rig::RigObject& o = *rig.surface.object;
  if (!rig::RigSurface::isPlainFileName(o.mesh))
    return fail(ErrorCode::kInvalidInput,
                "object mesh '" + o.mesh + "' is not a file name in the state directory");
  auto loaded = content::loadMeshContent(std::filesystem::path(state_dir) / o.mesh);
  if (!loaded) return tl::unexpected(loaded.error());
  return lamps::placedMesh(loaded->mesh, placementOf(o));
}

Result<std::map<std::string, std::shared_ptr<const cv::Mat>>> paintObjectFrames(
    const PreparedObject& prepared, const std::optional<Vec3>& eye, json* projectors) {
  std::map<std::string, std::shared_ptr<const cv::Mat>> frames;
  if (projectors) *projectors = json::array();
  for (std::size_t i = 0; i < prepared.lamps->lamps.size(); ++i) {
    const lamps::RigLamp& lamp = prepared.lamps->lamps[i];
    lamps::LampFrameStats stats;
    auto frame = lamps::rigLampFrame(*prepared.lamps, i, *prepared.material, 0, eye, &stats);
    if (!frame) return tl::unexpected(frame.error());
    const std::string& output = prepared.shown_by[i];
    if (!output.empty()) {
      auto rgba = std::make_shared<cv::Mat>();
      cv::cvtColor(*frame, *rgba, cv::COLOR_BGR2RGBA);
      frames[output] = std::move(rgba);
    }
    if (projectors) {
      json p = lamps::describeLamp(lamp);
      p["shown_by"] = output.empty() ? json(nullptr) : json(output);
      p["lit_pixels"] = stats.lit_pixels;
      if (lamp.on) p["clipped_pixels"] = stats.clipped_pixels;
      projectors->push_back(std::move(p));
    }
  }
  return frames;
}

tl::expected<PreparedObject, MeshFailure> prepareObjectContent(
    const ContentAccess& access, const std::string& state_dir, const rig::RigModel& rig,
    const ObjectLook& look, const std::vector<ObjectOutput>& outputs,
    const std::optional<Vec3>& eye, const json& eye_source) {
  if (!rig.surface.object)
    return failure(code::kUnavailable, "the rig model has no object (object place)");
  if (!(look.specular >= 0 && look.specular <= 1))
    return failure(code::kBadArgument, "\"specular\" must be from 0 to 1");
  if (!(look.shininess >= 1 && look.shininess <= 10000))
    return failure(code::kBadArgument, "\"shininess\" must be from 1 to 10000");
  // Which projector each output shows: the others of the rig are off.
  std::map<std::string, std::string> output_of;  // projector -> output
  for (const ObjectOutput& o : outputs) {
    const rig::RigProjector* p = rig.projectorForOutput(o.name);
    if (p && p->pose_known && p->intrinsics_known && p->width == o.mode.width &&
        p->height == o.mode.height)
      output_of[p->name] = o.name;
  }
  if (output_of.empty())
    return failure(code::kUnavailable,
                   "no output shows a posed projector of the rig at its calibrated size "
                   "(run calibrate)");
  lamps::RigLampOptions options;
  for (const rig::RigProjector& p : rig.projectors) {
    if (!p.pose_known || !p.intrinsics_known) continue;
    if (!output_of.count(p.name)) options.off.push_back(p.name);
  }

  auto model = rigObjectMesh(rig, state_dir);
  if (!model) return failure(code::kUnavailable, "the rig's object: " + model.error().message);
  const rig::RigObject& placed = *rig.surface.object;
  // The texture coordinates: the content model's, or (an image alone) the rig's model's.
  std::vector<Vec2> texcoord = model->texcoord;
  std::string coordinates_of = "the rig's object model " + placed.mesh;
  if (!look.file.empty()) {
    auto bytes = readContentFile(access, look.file);
    if (!bytes)
      return tl::unexpected(MeshFailure{protoCode(bytes.error().code), bytes.error().message});
    const sim::MeshLimits limits{access.limits.mesh_vertices, access.limits.mesh_faces,
                                 access.limits.face_indices, access.limits.file_bytes};
    auto content = content::meshContentFromBytes(*bytes, look.file, limits);
    if (!content)
      return tl::unexpected(MeshFailure{protoCode(content.error().code), content.error().message});
    // Both placed by the rig's pose, compared in the world.
    geom::TriangleMesh in_world = lamps::placedMesh(content->mesh, placementOf(placed));
    if (auto why = differsFrom(in_world, *model))
      return failure(code::kBadArgument, look.file + " is not the rig's object model: " + *why +
                                             " (place this model with `object place` first)");
    texcoord = std::move(content->mesh.texcoord);
    coordinates_of = look.file;
  }

  auto material = std::make_shared<lamps::Material>();
  const bool textured = !look.texture.empty();
  if (textured) {
    if (texcoord.size() != model->vertices.size())
      return failure(code::kBadArgument, coordinates_of +
                                             " has no texture coordinates (OBJ vt, PLY s t) "
                                             "for the texture");
    auto decoded = decodeContent(access, look.texture);
    if (!decoded)
      return tl::unexpected(MeshFailure{protoCode(decoded.error().code), decoded.error().message});
    cv::Mat bgra;
    cv::cvtColor(*decoded->image, bgra, cv::COLOR_RGBA2BGRA);
    material->texture = lamps::linearTexture(bgra);
  }
  material->specular_rgb = Vec3::Constant(look.specular);
  material->shininess = look.shininess;
  if (auto ok = lamps::checkMaterial(*material); !ok)
    return failure(code::kBadArgument, ok.error().message);

  auto object = lamps::ObjectModel::build(*model, textured ? texcoord : std::vector<Vec2>{});
  if (!object) return failure(code::kBadArgument, "the object model: " + object.error().message);
  auto prepared_lamps = lamps::prepareRigLamps(rig, *object, options);
  if (!prepared_lamps)
    return failure(prepared_lamps.error().code == ErrorCode::kNotFound ? code::kUnavailable
                                                                       : code::kBadArgument,
                   prepared_lamps.error().message);

  PreparedObject out;
  out.lamps = std::make_shared<const lamps::RigLamps>(std::move(*prepared_lamps));
  out.material = std::move(material);
  out.view_dependent = look.specular > 0;
  for (const lamps::RigLamp& lamp : out.lamps->lamps) {
    auto it = output_of.find(lamp.name);
    out.shown_by.push_back(it != output_of.end() ? it->second : std::string());
  }
  json projectors;
  const std::optional<Vec3> shade_eye = out.view_dependent ? eye : std::nullopt;
  if (out.view_dependent && !eye)
    return failure(code::kUnavailable,
                   "a highlight needs a viewer: a tracker, [content] viewer in the "
                   "configuration, or the rig model's viewer");
  auto frames = paintObjectFrames(out, shade_eye, &projectors);
  if (!frames) return failure(code::kBadArgument, frames.error().message);
  out.frames = std::move(*frames);

  json display = lamps::describeDisplay(*out.lamps, 0);
  if (out.view_dependent) {
    json viewer = eye_source;
    viewer["position"] = vectorJson(*eye);
    display["viewer"] = viewer;
    display["view_updates"] = 0;
  }
  json object_info = {{"mesh", placed.mesh},
                      {"faces", object->mesh().faces.size()},
                      {"textured", textured},
                      {"placed", {{"method", placed.placed.method}, {"time", placed.placed.time}}}};
  if (placed.fit_rms_m >= 0) object_info["fit_rms_m"] = placed.fit_rms_m;
  out.info = {{"path", look.file.empty() ? look.texture : look.file},
              {"object", object_info},
              {"look",
               {{"texture", textured ? json(look.texture) : json(nullptr)},
                {"specular", look.specular},
                {"shininess", look.shininess}}},
              {"display", std::move(display)},
              {"projectors", std::move(projectors)}};
  return out;
}

}  // namespace procam::daemon
