#pragma once
// The rig model: everything procamd knows about the geometry and light of its rig,
// and the only source of geometry for every consumer (auto keystone, content
// placement, each output's render path, tracker registration). It is the
// document rig.json (version 2; version 1, one projector without an output
// binding, is still read). Pure values: the daemon and procam-calibrate read
// and write the file; nothing here does I/O.
//
// Frames (ARCHITECTURE.md): world right-handed, metres, +Z up; a device's pose
// maps world to device (x right, y down, z forward), P = K [R | t].
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "geometry/plane_fit.hpp"
#include "geometry/plane_homography.hpp"
#include "keystone/accel_calibration.hpp"

namespace procam::rig {

inline constexpr int kRigVersion = 2;

// How and when a device was calibrated ("route (a), 2 cameras", "procam-sim truth").
struct Provenance {
  std::string method;
  std::string time;  // ISO 8601 UTC; empty when unknown
};

struct RigCamera {
  std::string name;
  geom::CameraModel model;
  double rms_px = -1;  // reprojection RMS; < 0 when unknown
  Provenance calibrated;
  // false: only K and the distortion are known (a camera calibrated alone from board
  // views); the pose is then the identity and no route may use the camera.
  bool pose_known = true;
  // The projector it is rigidly mounted on (a handheld projector's camera); empty: it
  // stands on its own. Its pose and that projector's were calibrated together, so the
  // camera-from-projector pose stays true however the pair moves. It may name a
  // projector the rig does not hold yet (cameras calibrated first).
  std::string attached_to;
};

// How a tilt sensor sits on a projector and how its readings are corrected.
struct TiltMountModel {
  std::string sensor;                             // the tilt device's name
  Mat3 sensor_from_projector = Mat3::Identity();  // row i = sensor axis i, projector frame
  keystone::AccelCalibration calibration;         // applied to readings in g
  std::string calibration_source;
  double fit_rms_g = -1;  // of the calibration fit; < 0 when unknown
};

struct RigProjector {
  std::string name;
  std::string output;  // the output device it is bound to; empty (version 1): unbound
  int width = 0, height = 0;
  geom::Intrinsics K;
  geom::Distortion dist;
  bool intrinsics_known = true;  // false: K and dist unknown (only plane_homography is)
  geom::Pose pose;               // world -> projector
  bool pose_known = true;        // false: only K is known (e.g. from a keystone-only set-up)
  bool scale_known = true;       // false: t is up to scale (route (b) without a distance)
  double rms_px = -1;            // reprojection RMS; < 0 when unknown
  long points = 0;               // correspondences of the fit
  Provenance calibrated;
  // Framebuffer pixels -> the planar display surface, in a basis of that plane
  // ([Raskar02] §4.2.1 collineation; route (b′) writes it). Enough for keystone on
  // the plane without K or pose.
  std::optional<geom::PlaneHomography> plane_homography;
  std::optional<TiltMountModel> tilt;
  nlohmann::json photometric = nullptr;  // per-projector response and brightness (reserved)

  geom::CameraModel model() const;
};

// A physical object the projectors light ([Raskar02] §5.2, shader lamps): its model (a
// PLY or OBJ file beside rig.json, in the model's own frame, with the texture coordinates
// a look is painted through) and where it stands: world = R · model + t, from points
// picked on the object and located in the world (eq. 4.2) or the identity for a model
// measured in the world (route (a)'s unified mesh).
struct RigObject {
  std::string mesh;
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
  // Of the placement's points (picked, or the measured surface's after `object refine`);
  // < 0 when unknown.
  double fit_rms_m = -1;
  long points = 0;  // the points it was placed (or last refined) from
  Provenance placed;
};

// The display surface: a plane, a mesh per projector (in its own pixel grid), one mesh
// unified over all projectors, or an object. Mesh files live beside rig.json.
struct RigSurface {
  std::optional<geom::Plane> plane;
  double plane_rms_m = -1;
  std::map<std::string, std::string> meshes;  // projector name -> PLY file name
  std::string unified_mesh;
  std::optional<RigObject> object;

  bool empty() const { return !plane && meshes.empty() && unified_mesh.empty() && !object; }
  // A mesh named in rig.json is a file beside it, never a path out of its folder.
  static bool isPlainFileName(const std::string& name) {
    return !name.empty() && name.find('/') == std::string::npos && name[0] != '.';
  }
};

// The viewer: a static sweet spot, or the tracker that reports them.
struct RigViewer {
  std::optional<Vec3> position;  // world, metres
  std::string tracker;           // empty: none

  bool empty() const { return !position && tracker.empty(); }
};

struct RigModel {
  std::vector<RigCamera> cameras;
  std::vector<RigProjector> projectors;
  RigSurface surface;
  RigViewer viewer;

  const RigCamera* camera(const std::string& name) const;
  // The projector bound to `output`; else an unbound one of that name; else the
  // only projector of a rig whose projector is unbound (version 1).
  const RigProjector* projectorForOutput(const std::string& output) const;
  const RigProjector* projector(const std::string& name) const;
  // The posed camera rigidly mounted on projector `name` (the first), if any.
  const RigCamera* attachedCamera(const std::string& name) const;
  bool empty() const { return cameras.empty() && projectors.empty() && surface.empty(); }
};

// Parses rig.json (version 1 or 2); `where` names the document in messages.
// kParse for a malformed document, kInvalidInput for an unsupported version.
Result<RigModel> rigFromJson(const nlohmann::json& doc, const std::string& where);
Result<RigModel> rigFromText(std::string_view text, const std::string& where);
// One camera entry of a rig.json or cameras.json (`index` names an unnamed one).
Result<RigCamera> cameraFromJson(const nlohmann::json& entry, const std::string& where,
                                 size_t index);
// Version 2; numbers with full double precision.
nlohmann::json rigToJson(const RigModel& rig);
// A 3 x 3 matrix as rig.json writes it: nine numbers, row by row.
nlohmann::json matrixJson(const Mat3& m);

// `update` merged into `base`: its cameras and projectors replace those of the
// same name and are added otherwise; its surface parts (plane, per-projector
// meshes, unified mesh, object) and viewer replace the base's where present. Everything
// else of the base is kept.
RigModel mergeRig(RigModel base, const RigModel& update);

}  // namespace procam::rig
