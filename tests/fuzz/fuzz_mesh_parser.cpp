// libFuzzer target: OBJ and PLY meshes (drivers/sim/mesh_io) under tight limits.
// Any bytes must give a mesh within the limits, with every index in range and
// every vertex finite, or an error; never a crash, a throw or an allocation
// beyond what the limits allow.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "sim/mesh_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::string_view bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  procam::sim::MeshLimits limits;
  limits.vertices = 4096;
  limits.faces = 4096;
  limits.face_indices = 16;
  // The first byte picks the reader, so one corpus covers both.
  const char* name = (data[0] & 1) ? "fuzz.ply" : "fuzz.obj";
  auto mesh = procam::sim::parseMesh(bytes, name, limits);
  if (!mesh) return 0;
  if (mesh->faces.empty() || mesh->faces.size() > limits.faces ||
      mesh->vertices.size() > limits.vertices) {
    std::abort();
  }
  const int n = static_cast<int>(mesh->vertices.size());
  for (const auto& f : mesh->faces) {
    if (f.minCoeff() < 0 || f.maxCoeff() >= n) std::abort();
  }
  for (const auto& v : mesh->vertices) {
    if (!v.allFinite()) std::abort();
  }
  return 0;
}
