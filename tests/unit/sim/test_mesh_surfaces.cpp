// Triangle meshes from OBJ and PLY (ascii and binary) files: a wall given as a mesh
// renders exactly like the same wall given as a rectangle.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <random>

#include "sim/mesh_io.hpp"
#include "sim/renderer.hpp"
#include "sim_test_util.hpp"

namespace procam::sim {
namespace {

namespace fs = std::filesystem;

// A 4 x 3 m quad in the plane y = 2, as two triangles.
const Vec3 kQuad[4] = {{-2, 2, -0.5}, {2, 2, -0.5}, {2, 2, 2.5}, {-2, 2, 2.5}};

fs::path tempDir() {
  std::random_device rd;
  const fs::path dir = fs::temp_directory_path() / ("procam_sim_mesh_" + std::to_string(rd()));
  fs::create_directories(dir);
  return dir;
}

void writeObj(const fs::path& file) {
  std::ofstream out(file);
  out << "# quad\n";
  for (const auto& v : kQuad) out << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
  out << "vn 0 -1 0\nf 1//1 2//1 3//1 -1//1\n";  // one polygon, fanned
}

void writePlyAscii(const fs::path& file) {
  std::ofstream out(file);
  out << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
         "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& v : kQuad) out << v.x() << " " << v.y() << " " << v.z() << "\n";
  out << "3 0 1 2\n3 0 2 3\n";
}

void writePlyBinary(const fs::path& file) {
  std::ofstream out(file, std::ios::binary);
  out << "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\n"
         "property double y\nproperty double z\nproperty uchar red\nelement face 1\n"
         "property list uchar uint vertex_indices\nend_header\n";
  for (const auto& v : kQuad) {
    for (int a = 0; a < 3; ++a) {
      const double c = v[a];
      out.write(reinterpret_cast<const char*>(&c), sizeof c);
    }
    const std::uint8_t red = 200;
    out.write(reinterpret_cast<const char*>(&red), 1);
  }
  const std::uint8_t count = 4;
  out.write(reinterpret_cast<const char*>(&count), 1);
  for (std::uint32_t i = 0; i < 4; ++i) out.write(reinterpret_cast<const char*>(&i), 4);
}

std::string meshScene(const std::string& surface) {
  std::string text = testing::flatWallScene("");
  const auto pos = text.find("[[surfaces]]");
  return text.substr(0, pos) + surface;
}

TEST(SimMesh, ObjAndPlyWallsRenderLikeTheRectangle) {
  const fs::path dir = tempDir();
  writeObj(dir / "quad.obj");
  writePlyAscii(dir / "quad.ply");
  writePlyBinary(dir / "quad_bin.PLY");

  auto reference = Scene::parse(meshScene(R"([[surfaces]]
name = "wall"
type = "rectangle"
origin = [-2.0, 2.0, -0.5]
u = [4.0, 0.0, 0.0]
v = [0.0, 0.0, 3.0]
albedo = 0.7
)"),
                                "rect.toml", dir);
  ASSERT_TRUE(reference) << reference.error().message;
  const cv::Mat fb(240, 320, CV_8UC1, cv::Scalar(180));
  auto ref_r = Renderer::create(*reference, reference->at(0), {{"proj", fb}});
  ASSERT_TRUE(ref_r);
  auto expected = ref_r->cameraRadiance("cam");
  ASSERT_TRUE(expected);

  for (const char* file : {"quad.obj", "quad.ply", "quad_bin.PLY"}) {
    auto scene = Scene::parse(meshScene(std::string("[[surfaces]]\nname = \"wall\"\ntype = "
                                                    "\"mesh\"\nalbedo = 0.7\nfile = \"") +
                                        file + "\"\n"),
                              "mesh.toml", dir);
    ASSERT_TRUE(scene) << scene.error().message;
    auto r = Renderer::create(*scene, scene->at(0), {{"proj", fb}});
    ASSERT_TRUE(r);
    auto got = r->cameraRadiance("cam");
    ASSERT_TRUE(got);
    EXPECT_LT(cv::norm(*got, *expected, cv::NORM_INF), 1e-6) << file;
  }
  fs::remove_all(dir);
}

TEST(SimMesh, MeshTransformAndErrors) {
  auto mesh = parseObj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "tri.obj");
  ASSERT_TRUE(mesh);
  EXPECT_EQ(mesh->faces.size(), 1u);
  EXPECT_FALSE(parseObj("v 0 0 0\nf 1 2 7\n", "bad.obj"));
  EXPECT_FALSE(parseObj("v 0 0 0\nv 1 0 0\nf 1 2\n", "bad.obj"));
  EXPECT_FALSE(parsePly("ply\nformat binary_big_endian 1.0\nend_header\n", "bad.ply"));
  // Meshes need a directory to resolve against: embedded scenes have none.
  auto scene = Scene::parse(meshScene("[[surfaces]]\nname = \"m\"\ntype = \"mesh\"\nfile = "
                                      "\"x.obj\"\n"),
                            "embedded.toml", {});
  ASSERT_FALSE(scene);
  EXPECT_NE(scene.error().message.find("surfaces[0].file"), std::string::npos);
}

// OBJ texture coordinates belong to face corners: a vertex on a texture seam has one per
// side and becomes two vertices; without them, or with some corners lacking one, the
// vertices stay as they are and carry none.
TEST(SimMesh, ObjTextureCoordinatesSplitVerticesOnSeams) {
  const char* seam =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
      "vt 0 0\nvt 0.5 0\nvt 0.5 1\nvt 0 1\nvt 1 0\nvt 1 1\n"
      "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\nf 2/5/1 3/6/1 1/1/1\n";
  auto mesh = parseObj(seam, "seam.obj");
  ASSERT_TRUE(mesh) << mesh.error().message;
  ASSERT_EQ(mesh->faces.size(), 3u);
  // Vertices 2 and 3 appear with two texture coordinates each: 4 + 2 vertices.
  ASSERT_EQ(mesh->vertices.size(), 6u);
  ASSERT_EQ(mesh->texcoord.size(), 6u);
  EXPECT_TRUE(mesh->uv.empty());  // uv is a measured surface's projector pixels, not these
  for (const auto& f : mesh->faces) {
    for (int k = 0; k < 3; ++k) {
      const Vec3& v = mesh->vertices[f[k]];
      const Vec2& t = mesh->texcoord[f[k]];
      if (&f == &mesh->faces[2])
        EXPECT_EQ(t.x(), v.x() == 0 ? 0.0 : 1.0);  // the third face's own atlas
      else
        EXPECT_EQ(t.x(), 0.5 * v.x());
      EXPECT_EQ(t.y(), v.y());
    }
  }
  auto plain = parseObj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2 3\n", "partial.obj");
  ASSERT_TRUE(plain);
  EXPECT_EQ(plain->vertices.size(), 3u);
  EXPECT_TRUE(plain->texcoord.empty());
  EXPECT_FALSE(parseObj("v 0 0 0\nvt 0 x\nf 1 1 1\n", "bad.obj"));
  EXPECT_FALSE(parseObj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/2 2/1 3/1\n", "bad.obj"));
}

}  // namespace
}  // namespace procam::sim
