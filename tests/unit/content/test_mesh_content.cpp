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

}  // namespace
}  // namespace procam::content
