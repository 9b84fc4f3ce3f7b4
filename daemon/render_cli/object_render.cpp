#include "object_render.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "blend/mpcdi.hpp"
#include "blend/rig_tiles.hpp"
#include "content/mesh_content.hpp"
#include "json_matrix.hpp"
#include "replace_file.hpp"
#include "shader_lamps/object_model.hpp"
#include "shader_lamps/rig_lamps.hpp"

namespace procam::render_cli {

namespace fs = std::filesystem;
using nlohmann::json;

Result<json> renderObject(const ObjectRenderInput& in) {
  auto loaded = content::loadMeshContent(in.object);
  if (!loaded) return tl::unexpected(loaded.error());
  std::vector<Vec2> uv = loaded->mesh.texcoord;
  if (!in.texture.empty() && uv.empty())
    return fail(
        ErrorCode::kInvalidInput,
        in.object.string() + " has no texture coordinates (OBJ vt, PLY s t) for the texture");
  const bool textured = !uv.empty() && !in.texture.empty();
  auto object = lamps::ObjectModel::build(loaded->mesh, textured ? uv : std::vector<Vec2>{});
  if (!object) return tl::unexpected(object.error());

  for (const rig::RigProjector& p : in.rig->projectors) {
    const bool asked =
        std::find(in.projectors.begin(), in.projectors.end(), p.name) != in.projectors.end();
    if ((in.projectors.empty() || asked) && !blend::isSafeRegionId(p.name))
      return fail(
          ErrorCode::kInvalidInput,
          "projector name '" + p.name + "' cannot name a file (1-128 of A-Z a-z 0-9 . _ -)");
  }
  if (in.white && (!(*in.white > 0) || !std::isfinite(*in.white)))
    return fail(ErrorCode::kInvalidInput, "--white must be positive");
  lamps::RigLampOptions options{in.projectors, in.off, in.max_incidence_deg};
  auto prepared = lamps::prepareRigLamps(*in.rig, *object, options);
  if (!prepared) return tl::unexpected(prepared.error());
  const double white = in.white ? *in.white : prepared->white;

  lamps::Material material;
  if (textured) material.texture = lamps::linearTexture(in.texture);
  material.light_dir = in.light;
  material.specular_rgb = Vec3::Constant(in.specular);
  material.shininess = in.shininess;
  if (auto ok = lamps::checkMaterial(material); !ok) return tl::unexpected(ok.error());

  std::error_code ec;
  if (!in.out.empty()) {
    fs::create_directories(in.out, ec);
    if (ec) return fail(ErrorCode::kIo, "cannot create " + in.out.string() + ": " + ec.message());
  }
  json projectors = json::array();
  for (std::size_t i = 0; i < prepared->lamps.size(); ++i) {
    const lamps::RigLamp& lamp = prepared->lamps[i];
    const std::string file = lamp.name + ".png";
    json p = lamps::describeLamp(lamp);
    p["file"] = file;
    lamps::LampFrameStats stats;
    auto frame =
        lamps::rigLampFrame(*prepared, i, material, white, in.viewer, &stats, in.bit_depth);
    if (!frame) return tl::unexpected(frame.error());
    p["lit_pixels"] = stats.lit_pixels;
    if (lamp.on) p["clipped_pixels"] = stats.clipped_pixels;
    projectors.push_back(std::move(p));
    if (!in.out.empty()) {
      std::vector<uint8_t> png;
      if (!cv::imencode(".png", *frame, png))
        return fail(ErrorCode::kIo, "cannot encode " + lamp.name + "'s frame");
      if (auto ok = replaceFileWith(in.out / file, std::string(png.begin(), png.end())); !ok)
        return tl::unexpected(ok.error());
    }
  }
  json display = lamps::describeDisplay(*prepared, white);
  display["white_source"] = in.white ? "given" : "brightest all give";
  json doc = {{"object",
               {{"path", in.object.string()},
                {"faces", object->mesh().faces.size()},
                {"textured", textured}}},
              {"display", std::move(display)},
              {"projectors", projectors}};
  if (in.viewer) doc["display"]["viewer"] = daemon::vectorJson(*in.viewer);
  return doc;
}

}  // namespace procam::render_cli
