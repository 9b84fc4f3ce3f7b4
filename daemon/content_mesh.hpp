#pragma once
// 3D content in the daemon (`content load` of an .obj or .ply file): for every output,
// the mesh placed in front of the planar surface its projector lights, shaded, with
// the planar 3D path's matrix for the viewer (content/mesh_placement.hpp). Pure: runs
// on a worker (content_live.cpp). While a tracker gives the viewer, the drawing follows it
// (content_follow.cpp).
#include <chrono>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "content/mesh_placement.hpp"
#include "content_access.hpp"
#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "geometry/intersect.hpp"
#include "geometry/plane_fit.hpp"
#include "keystone/head_tracked.hpp"
#include "output_frames.hpp"
#include "tl/expected.hpp"

namespace procam::daemon {

// An output and what the rig model knows of it: its projector's model (when
// calibrated with a pose) and the display surface's plane (when planar).
struct MeshOutput {
  std::string name;
  std::optional<geom::CameraModel> projector;
  std::optional<geom::Plane> plane;
  bool surface_known = false;  // the rig has a surface (a plane or a mesh)
  // A non-planar surface's mesh (rig.json meshes), when loaded: the mesh is then drawn
  // for the viewer first and that image shown through the lookup warp.
  std::shared_ptr<const geom::MeshIntersector> surface;
};

// What an output's view-dependent matrix needs: the view it was placed for (its eye is
// replaced by the moved viewer's) and S, fixed at placement.
struct MeshView {
  content::PlanarView view;
  keystone::DisplayRect S;
};

// 3D content drawn for the viewer on a non-planar surface, and the world -> image matrix it
// was drawn with (the lookup warp shows it with the same one).
struct MeshImage {
  std::shared_ptr<const cv::Mat> image;
  Mat34 viewer = Mat34::Zero();
};

struct PreparedMesh {
  std::map<std::string, Mesh3d> meshes;  // output name -> what it draws (planar surface)
  // Non-planar surface: output name -> the mesh as the viewer sees it (RGBA, the output's
  // size), drawn through the lookup warp like image content ([Raskar02] §3.2.3 first pass).
  std::map<std::string, MeshImage> images;
  nlohmann::json placement = nlohmann::json::object();  // output name -> placement plane
  std::map<std::string, MeshView> views;                // output name -> its view
  Vec3 eye = Vec3::Zero();                              // the viewer it was placed for
  nlohmann::json info;                                  // the `content` object of replies
};

// The shown mesh following its tracker (loop thread only; content_follow.cpp).
struct MeshFollow {
  std::map<std::string, MeshView> views;
  std::string tracker;      // the viewer's tracker; empty: the viewer does not move
  Vec3 eye = Vec3::Zero();  // of the frame shown or in flight
  uint64_t updates = 0;     // view updates shown
  bool in_flight = false;   // a view update's frame is rendering
  int timer = -1;           // one-shot: the next update, once a frame period has passed
  std::chrono::steady_clock::time_point last_start;
  std::chrono::nanoseconds frame_period{16'666'667};  // of the first output
  uint64_t generation = 0;                            // of the loaded mesh
};

// RenderSetup::planar3d of every output for the viewer `eye` (the mesh not moved).
Result<std::map<std::string, Mat4>> meshViewMatrices(const std::map<std::string, MeshView>& views,
                                                     const Vec3& eye);

struct MeshFailure {
  const char* code = "";  // a proto::code constant
  std::string message;
};

// True for the 3D content files `content load` takes (.obj, .ply, any case).
bool isMeshFile(const std::string& path);

// Reads the mesh and places it for each output. The viewer is `eye` (world: a
// tracker's, the configuration's or the rig model's, described by `eye_source`, an
// object with "source"). On a planar surface the mesh stands on the wall and is drawn by
// the planar 3D path; on a non-planar one it stands on the plane through the surface point
// at the projector's centre, facing the viewer, sized for the content image the viewer
// sees on the surface, and is drawn once from the viewer into that image (the output's
// size; `images`; the plane and the viewer's matrix reported per output in info "placement").
// `unavailable` when there is no viewer, or an output's projector pose or display surface
// is unknown (or a non-planar surface's mesh is not loaded); `io-error` / `bad-argument`
// when the file cannot be read or parsed.
tl::expected<PreparedMesh, MeshFailure> prepareMeshContent(const ContentAccess& access,
                                                           const std::string& file,
                                                           const std::vector<MeshOutput>& outputs,
                                                           const std::optional<Vec3>& eye,
                                                           const nlohmann::json& eye_source);

}  // namespace procam::daemon
