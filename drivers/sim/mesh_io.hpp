#pragma once
// Triangle meshes for scene surfaces: Wavefront OBJ (v/vt/f records, polygons fanned
// into triangles, negative indices; when every face corner has a texture coordinate,
// each distinct vertex and texture coordinate pair is a vertex with its `texcoord`) and
// PLY (ascii or binary_little_endian, vertex x/y/z, optional u/v — a measured surface's
// projector pixels — and s/t or texture_u/texture_v texture coordinates, a face
// vertex-index list; other elements and properties are skipped).
#include <filesystem>

#include "core/error.hpp"
#include "geometry/intersect.hpp"

namespace procam::sim {

// Bounds on what a file may declare or hold; a file over one is refused with
// kTooLarge before the memory is taken. The defaults fit any scene surface.
struct MeshLimits {
  std::size_t vertices = 4'000'000;
  std::size_t faces = 4'000'000;  // triangles, after polygons are fanned
  std::size_t face_indices = 64;  // vertices of one polygon
  std::size_t file_bytes = std::size_t{512} << 20;
};

// Picks the reader by extension (.obj / .ply, case-insensitive).
Result<geom::TriangleMesh> loadMesh(const std::filesystem::path& file,
                                    const MeshLimits& limits = {});
// The same from bytes already read; `name` gives the extension and the messages' origin.
Result<geom::TriangleMesh> parseMesh(std::string_view bytes, const std::string& name,
                                     const MeshLimits& limits = {});

Result<geom::TriangleMesh> parseObj(std::string_view text, const std::string& origin,
                                    const MeshLimits& limits = {});
Result<geom::TriangleMesh> parsePly(std::string_view bytes, const std::string& origin,
                                    const MeshLimits& limits = {});

}  // namespace procam::sim
