#pragma once
// procam-render --object: the frames that paint a neutral object with a texture (shader
// lamps, [Raskar02] §5.2), drawn offline from rig.json (projectors with K and pose) and
// the object's model (a mesh in the rig's world, with texture coordinates).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "rig/rig_model.hpp"

namespace procam::render_cli {

struct ObjectRenderInput {
  const rig::RigModel* rig = nullptr;
  std::filesystem::path object;         // PLY (vertex u v) or OBJ, world coordinates
  cv::Mat texture;                      // decoded image, sRGB codes; empty: white
  std::vector<std::string> projectors;  // only these (empty: every posed one)
  std::vector<std::string> off;         // switched off: dark, their part reported unlit
  std::optional<Vec3> viewer;           // the eye for the highlight
  std::optional<Vec3> light;            // direction towards a virtual light
  double specular = 0, shininess = 32;
  double max_incidence_deg = 60;
  std::optional<double> white;  // the white level; default the brightest all give
  std::filesystem::path out;    // frames go here (empty: none)
  int bit_depth = 8;
};

// Draws every projector's frame and returns display.json's document: the white level and
// its units, the coverage (lit, unlit because a projector is off, never lit) and per
// projector its file, response, gain and where they came from, lit and clipped pixels.
// kNotFound without a posed projector; errors of reading the mesh and of the pipeline.
Result<nlohmann::json> renderObject(const ObjectRenderInput& in);

}  // namespace procam::render_cli
