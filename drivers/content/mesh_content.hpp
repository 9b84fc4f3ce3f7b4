#pragma once
// A triangle mesh as 3D content (the single-pass A'4x4 path and the two-pass
// surface path place and render it). Read with the virtual rig's mesh reader
// (drivers/sim/mesh_io: OBJ, and PLY too); this adds what content needs on top:
// its bounds for placing it in the scene.
#include <filesystem>

#include "core/error.hpp"
#include "geometry/intersect.hpp"
#include "sim/mesh_io.hpp"

namespace procam::content {

struct MeshContent {
  geom::TriangleMesh mesh;
  Vec3 min = Vec3::Zero();  // axis-aligned bounds of the vertices used by faces
  Vec3 max = Vec3::Zero();
};

// kIo / kParse / kInvalidInput from the reader (which refuses a mesh without a
// triangle); kTooLarge over `limits`.
Result<MeshContent> loadMeshContent(const std::filesystem::path& file,
                                    const sim::MeshLimits& limits = {});
// The same from the file's bytes; `name` gives the format (.obj, .ply).
Result<MeshContent> meshContentFromBytes(std::string_view bytes, const std::string& name,
                                         const sim::MeshLimits& limits = {});

}  // namespace procam::content
