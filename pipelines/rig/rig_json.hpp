#pragma once
// rig.json and cameras.json (daemon/calibrate_cli/README.md): every device with
// name, width, height, K, R, t (world -> device) and, for cameras, dist; rig.json
// adds the projectors and the display surface. Written by procam-calibrate and by
// procamd's calibrate operation.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calibration/projector_calibration.hpp"
#include "core/error.hpp"
#include "geometry/camera_model.hpp"
#include "surface/surface_model.hpp"

namespace procam::rig {

struct NamedCamera {
  std::string name;
  geom::CameraModel model;
  double rms_px = -1;  // written when >= 0
};
struct NamedProjector {
  std::string name;
  int width = 0, height = 0;
  calib::ProjectorCalibration calibration;
};

nlohmann::json cameraJson(const NamedCamera& c);
nlohmann::json projectorJson(const NamedProjector& p);
// {"plane": [a, b, c, d], "rms_m": r} for a planar model, else {"mesh": mesh_file}.
nlohmann::json surfaceJson(const surface::SurfaceModel& model, const std::string& mesh_file);
// {"cameras": [...], "projectors": [projector], "surface": surface (omitted when null)}.
nlohmann::json rigJson(const std::vector<NamedCamera>& cameras, const NamedProjector& projector,
                       const nlohmann::json& surface);

// The "cameras" array of a cameras.json or rig.json document; `where` names the
// document in messages. kParse for a missing or malformed field.
Result<std::vector<NamedCamera>> camerasFromJson(const nlohmann::json& doc,
                                                 const std::string& where);

}  // namespace procam::rig
