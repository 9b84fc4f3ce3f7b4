#pragma once
// Triangle meshes for scene surfaces: Wavefront OBJ (v/f records, polygons fanned
// into triangles, negative indices) and PLY (ascii or binary_little_endian, vertex
// x/y/z and a face vertex-index list; other elements and properties are skipped).
#include <filesystem>

#include "core/error.hpp"
#include "geometry/intersect.hpp"

namespace procam::sim {

// Picks the reader by extension (.obj / .ply, case-insensitive).
Result<geom::TriangleMesh> loadMesh(const std::filesystem::path& file);

Result<geom::TriangleMesh> parseObj(std::string_view text, const std::string& origin);
Result<geom::TriangleMesh> parsePly(std::string_view bytes, const std::string& origin);

}  // namespace procam::sim
