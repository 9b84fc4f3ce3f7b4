// OBJ meshes as 3D content: the vertices and triangles written, their bounds,
// and the refusals (no triangle, unreadable, malformed).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "content/mesh_content.hpp"

namespace procam::content {
namespace {

class MeshFile {
 public:
  MeshFile(const std::string& name, const std::string& text) {
    char tmpl[] = "/tmp/procam-mesh-XXXXXX";
    dir_ = ::mkdtemp(tmpl);
    path_ = dir_ / name;
    std::ofstream(path_) << text;
  }
  ~MeshFile() { std::filesystem::remove_all(dir_); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path dir_, path_;
};

TEST(MeshContent, ObjQuadAndTriangleWithBounds) {
  // A quad (fanned into two triangles) and a triangle given with negative
  // indices; vertex 5 is used by no face and stays out of the bounds.
  MeshFile f("m.obj",
             "# content\n"
             "v -1 -0.5 2\nv 1 -0.5 2\nv 1 0.5 2.5\nv -1 0.5 2.5\n"
             "v 100 100 100\n"
             "v 0 0 3\n"
             "f 1 2 3 4\n"
             "f -1 -5 -4\n");
  auto m = loadMeshContent(f.path());
  ASSERT_TRUE(m) << m.error().message;
  ASSERT_EQ(m->mesh.vertices.size(), 6u);
  ASSERT_EQ(m->mesh.faces.size(), 3u);
  EXPECT_EQ(m->mesh.faces[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(m->mesh.faces[1], Eigen::Vector3i(0, 2, 3));
  EXPECT_EQ(m->mesh.faces[2], Eigen::Vector3i(5, 1, 2));
  EXPECT_EQ(m->min, Vec3(-1, -0.5, 2));
  EXPECT_EQ(m->max, Vec3(1, 0.5, 3));
}

TEST(MeshContent, Refusals) {
  MeshFile empty("e.obj", "v 0 0 0\nv 1 0 0\n");
  auto r = loadMeshContent(empty.path());
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kParse);

  MeshFile bad("b.obj", "v 0 0 0\nf 1 2 9\n");
  r = loadMeshContent(bad.path());
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kParse);

  r = loadMeshContent("/nonexistent/x.obj");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kIo);
}

// What a mesh may declare or hold is bounded: refused with kTooLarge before the
// memory is taken (a PLY's declared counts are checked against the file too).
TEST(MeshContent, LimitsAreEnforced) {
  sim::MeshLimits small;
  small.vertices = 4;
  small.faces = 2;
  small.face_indices = 4;
  const std::string quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
  ASSERT_TRUE(meshContentFromBytes(quad, "q.obj", small));
  auto r = meshContentFromBytes(quad + "v 2 2 0\n", "q.obj", small);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kTooLarge);
  r = meshContentFromBytes("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3 1 2\n", "p.obj", small);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kTooLarge);  // 5 indices in one face
  r = meshContentFromBytes(quad + "f 1 2 3\n", "q.obj", small);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kTooLarge);  // 3 triangles
  const std::string ply_head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face ";
  const std::string ply_tail =
      "\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  ASSERT_TRUE(meshContentFromBytes(ply_head + "1" + ply_tail, "t.ply"));
  r = meshContentFromBytes(ply_head + "10000000000000000000" + ply_tail, "t.ply");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kParse) << r.error().message;  // more records than bytes
  r = meshContentFromBytes(ply_head + "3" + ply_tail, "t.ply", small);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kTooLarge);
  const std::string long_list =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n";
  r = meshContentFromBytes(long_list, "l.ply");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kTooLarge);
  // Declared counts add up over repeated elements; a record of no property is refused.
  std::string repeated = "ply\nformat ascii 1.0\n";
  for (int i = 0; i < 3; ++i) repeated += "element vertex 2\nproperty float x\n";
  repeated += "end_header\n" + std::string(64, ' ');
  r = meshContentFromBytes(repeated, "r.ply", small);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kTooLarge);  // 6 vertices declared, 4 allowed
  r = meshContentFromBytes(
      "ply\nformat ascii 1.0\nelement junk 5\nend_header\n" + std::string(64, ' '), "j.ply");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kParse);
}

}  // namespace
}  // namespace procam::content
