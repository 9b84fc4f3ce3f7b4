#pragma once
// 3D content in the daemon (`content load` of an .obj or .ply file): for every output,
// the mesh placed in front of the planar surface its projector lights, shaded, with
// the planar 3D path's matrix for the viewer (content/mesh_placement.hpp). Pure: runs
// on a worker (content_live.cpp).
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "output_frames.hpp"
#include "tl/expected.hpp"

namespace procam::daemon {

// An output device as the loop sees it: its name and, on the virtual rig, which
// scene and which projector of it (SIM_SCENE, SIM_DEVICE; empty elsewhere).
struct MeshOutput {
  std::string name;
  std::string sim_scene, sim_device;
};

struct PreparedMesh {
  std::map<std::string, Mesh3d> meshes;  // output name -> what it draws
  nlohmann::json info;                   // the `content` object of replies
};

struct MeshFailure {
  const char* code = "";  // a proto::code constant
  std::string message;
};

// True for the 3D content files `content load` takes (.obj, .ply, any case).
bool isMeshFile(const std::string& path);

// Reads the mesh and places it for each output. The viewer is `eye` (world: a tracker's
// or the configuration's, described by `eye_source`, an object with "source") when
// given, else the virtual rig's scene viewer. `unavailable` when
// an output's projector pose or display surface is unknown or the surface it lights is
// not planar; `io-error` / `bad-argument` when the file cannot be read or parsed.
tl::expected<PreparedMesh, MeshFailure> prepareMeshContent(const std::string& file,
                                                           const std::vector<MeshOutput>& outputs,
                                                           const std::optional<Vec3>& eye,
                                                           const nlohmann::json& eye_source);

}  // namespace procam::daemon
