#pragma once
// procam-render on a curved rig: the projectors with a pose and a surface mesh in the rig
// model shown as one display for a viewer at a sweet spot (blend/curved_display.hpp), or
// as one dome master around that eye (render/dome_master.hpp).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "rig/rig_model.hpp"

namespace procam::render_cli {

struct CurvedRenderInput {
  const rig::RigModel* rig = nullptr;
  std::filesystem::path rig_file;       // its meshes are files beside it
  std::vector<std::string> projectors;  // only these (empty: every posed one with a mesh)
  std::optional<Vec3> viewer;           // --viewer, else the rig model's
  std::optional<Vec3> dome_front;       // a dome master's front (render/dome_master.hpp)
  double dome_fov_deg = 180;
  cv::Mat content;              // decoded, 8 or 16 bit
  std::filesystem::path out;    // frames go here (empty: none)
  std::filesystem::path mpcdi;  // the MPCDI package (empty: none)
  std::string date;             // the package's date, in MPCDI's form
  int bit_depth = 8;
  bool geometry_only = false;
};

// Draws every share (with `out`), writes the MPCDI package (with `mpcdi`) and returns
// display.json's document (without the rig and content entries the caller adds). kNotFound without
// a viewer or a projector with a pose and a mesh; kInvalidInput for a mesh named outside the rig
// file's folder; errors of reading the meshes and of blend::makeCurvedBlend.
Result<nlohmann::json> renderCurved(const CurvedRenderInput& in);

}  // namespace procam::render_cli
