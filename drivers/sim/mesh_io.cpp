#include "sim/mesh_io.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace procam::sim {

namespace {

tl::unexpected<Error> parseError(const std::string& origin, std::size_t line,
                                 const std::string& what) {
  return fail(ErrorCode::kParse, origin + ":" + std::to_string(line) + ": " + what);
}

Result<geom::TriangleMesh> checked(geom::TriangleMesh mesh, const std::string& origin) {
  if (mesh.faces.empty()) return fail(ErrorCode::kParse, origin + ": mesh has no faces");
  const int n = static_cast<int>(mesh.vertices.size());
  for (const auto& f : mesh.faces) {
    if (f.minCoeff() < 0 || f.maxCoeff() >= n)
      return fail(ErrorCode::kParse, origin + ": face index out of range");
  }
  for (const auto& v : mesh.vertices) {
    if (!v.allFinite()) return fail(ErrorCode::kParse, origin + ": non-finite vertex");
  }
  if (mesh.uv.size() != mesh.vertices.size()) mesh.uv.clear();  // not every vertex has one
  for (const auto& t : mesh.uv) {
    if (!t.allFinite()) return fail(ErrorCode::kParse, origin + ": non-finite vertex u v");
  }
  if (mesh.texcoord.size() != mesh.vertices.size()) mesh.texcoord.clear();
  for (const auto& t : mesh.texcoord) {
    if (!t.allFinite()) return fail(ErrorCode::kParse, origin + ": non-finite texture coordinate");
  }
  return mesh;
}

tl::unexpected<Error> tooLarge(const std::string& origin, const std::string& what,
                               std::size_t limit) {
  return fail(ErrorCode::kTooLarge,
              origin + ": more than " + std::to_string(limit) + " " + what + " (the limit)");
}

// Resolves one OBJ index (1-based, or negative from the end) to a 0-based index.
bool objNumber(std::string_view text, int count, int& out) {
  int value = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || ptr != text.data() + text.size() || value == 0) return false;
  out = value > 0 ? value - 1 : count + value;
  return true;
}

constexpr int kNoTexcoord = std::numeric_limits<int>::min();

// Resolves an OBJ face token ("7", "7/1/3", "-1//2") to a 0-based vertex index and
// texture-coordinate index (kNoTexcoord when the token has none).
bool objIndex(const std::string& token, int vertex_count, int texcoord_count, int& vertex,
              int& texcoord) {
  const std::size_t slash = token.find('/');
  if (!objNumber(std::string_view(token).substr(0, slash), vertex_count, vertex)) return false;
  texcoord = kNoTexcoord;
  if (slash == std::string::npos) return true;
  const std::size_t next = token.find('/', slash + 1);
  const std::string_view vt = std::string_view(token).substr(
      slash + 1, next == std::string::npos ? std::string::npos : next - slash - 1);
  return vt.empty() || objNumber(vt, texcoord_count, texcoord);
}

// An OBJ's texture coordinates belong to face corners, a mesh's to vertices: when every
// corner has one, each distinct (vertex, texture coordinate) pair becomes a vertex of
// its own (a vertex on a texture seam is repeated, once per side).
Result<geom::TriangleMesh> splitByTexcoord(geom::TriangleMesh mesh,
                                           const std::vector<Eigen::Vector3i>& corner_uv,
                                           const std::vector<Vec2>& texcoords,
                                           const std::string& origin, const MeshLimits& limits) {
  bool every = true;
  for (const auto& c : corner_uv) {
    for (int k = 0; k < 3; ++k) {
      if (c[k] == kNoTexcoord) {
        every = false;
      } else if (c[k] < 0 || c[k] >= static_cast<int>(texcoords.size())) {
        return fail(ErrorCode::kParse, origin + ": texture coordinate index out of range");
      }
    }
  }
  if (!every) return mesh;  // not every corner has one: the geometry alone
  std::unordered_map<std::uint64_t, int> index;
  geom::TriangleMesh out;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    Eigen::Vector3i face;
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.faces[f][k], t = corner_uv[f][k];
      if (v < 0 || v >= static_cast<int>(mesh.vertices.size()))
        return fail(ErrorCode::kParse, origin + ": face index out of range");
      const std::uint64_t key =
          (static_cast<std::uint64_t>(v) << 32) | static_cast<std::uint32_t>(t);
      auto [it, added] = index.emplace(key, static_cast<int>(out.vertices.size()));
      if (added) {
        if (out.vertices.size() >= limits.vertices)
          return tooLarge(origin, "vertices", limits.vertices);
        out.vertices.push_back(mesh.vertices[static_cast<std::size_t>(v)]);
        out.texcoord.push_back(texcoords[static_cast<std::size_t>(t)]);
      }
      face[k] = it->second;
    }
    out.faces.push_back(face);
  }
  return out;
}

}  // namespace

Result<geom::TriangleMesh> parseObj(std::string_view text, const std::string& origin,
                                    const MeshLimits& limits) {
  geom::TriangleMesh mesh;
  std::vector<Vec2> texcoords;             // vt records
  std::vector<Eigen::Vector3i> corner_uv;  // per triangle, its corners' vt
  std::istringstream in{std::string(text)};
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream fields(line);
    std::string tag;
    if (!(fields >> tag) || tag[0] == '#') continue;
    if (tag == "v") {
      Vec3 v;
      if (!(fields >> v.x() >> v.y() >> v.z())) return parseError(origin, line_no, "bad vertex");
      if (mesh.vertices.size() >= limits.vertices)
        return tooLarge(origin, "vertices", limits.vertices);
      mesh.vertices.push_back(v);
    } else if (tag == "vt") {
      Vec2 t;
      if (!(fields >> t.x() >> t.y()) || !t.allFinite())
        return parseError(origin, line_no, "bad texture coordinate");
      if (texcoords.size() >= limits.vertices)
        return tooLarge(origin, "texture coordinates", limits.vertices);
      texcoords.push_back(t);
    } else if (tag == "f") {
      std::vector<int> idx, uv;
      std::string token;
      while (fields >> token) {
        int i = 0, t = kNoTexcoord;
        if (!objIndex(token, static_cast<int>(mesh.vertices.size()),
                      static_cast<int>(texcoords.size()), i, t))
          return parseError(origin, line_no, "bad face index '" + token + "'");
        if (idx.size() >= limits.face_indices)
          return tooLarge(origin + ":" + std::to_string(line_no), "vertices in one face",
                          limits.face_indices);
        idx.push_back(i);
        uv.push_back(t);
      }
      if (idx.size() < 3) return parseError(origin, line_no, "face with fewer than 3 vertices");
      if (mesh.faces.size() + idx.size() - 2 > limits.faces)
        return tooLarge(origin, "triangles", limits.faces);
      for (std::size_t k = 1; k + 1 < idx.size(); ++k) {
        mesh.faces.emplace_back(idx[0], idx[k], idx[k + 1]);
        corner_uv.emplace_back(uv[0], uv[k], uv[k + 1]);
      }
    }
    // vn, o, g, s, usemtl, mtllib: not needed.
  }
  if (!texcoords.empty()) {
    auto split = splitByTexcoord(std::move(mesh), corner_uv, texcoords, origin, limits);
    if (!split) return tl::unexpected(split.error());
    return checked(std::move(*split), origin);
  }
  return checked(std::move(mesh), origin);
}

namespace {

enum class PlyType { kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64, kInvalid };

PlyType plyType(const std::string& name) {
  if (name == "char" || name == "int8") return PlyType::kI8;
  if (name == "uchar" || name == "uint8") return PlyType::kU8;
  if (name == "short" || name == "int16") return PlyType::kI16;
  if (name == "ushort" || name == "uint16") return PlyType::kU16;
  if (name == "int" || name == "int32") return PlyType::kI32;
  if (name == "uint" || name == "uint32") return PlyType::kU32;
  if (name == "float" || name == "float32") return PlyType::kF32;
  if (name == "double" || name == "float64") return PlyType::kF64;
  return PlyType::kInvalid;
}

std::size_t plySize(PlyType t) {
  switch (t) {
    case PlyType::kI8:
    case PlyType::kU8:
      return 1;
    case PlyType::kI16:
    case PlyType::kU16:
      return 2;
    case PlyType::kI32:
    case PlyType::kU32:
    case PlyType::kF32:
      return 4;
    case PlyType::kF64:
      return 8;
    case PlyType::kInvalid:
      break;
  }
  return 0;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kInvalid;
  bool is_list = false;
  PlyType count_type = PlyType::kInvalid;
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> props;
};

// Reads one scalar of the given type from ascii tokens or little-endian bytes.
class PlyReader {
 public:
  PlyReader(std::string_view body, bool binary) : body_(body), binary_(binary) {
    if (!binary_) ascii_.str(std::string(body));
  }

  bool read(PlyType type, double& out) {
    if (!binary_) return static_cast<bool>(ascii_ >> out);
    const std::size_t n = plySize(type);
    if (pos_ + n > body_.size()) return false;
    const char* p = body_.data() + pos_;
    pos_ += n;
    switch (type) {
      case PlyType::kI8:
        out = static_cast<std::int8_t>(p[0]);
        return true;
      case PlyType::kU8:
        out = static_cast<std::uint8_t>(p[0]);
        return true;
      case PlyType::kI16:
        return copyAs<std::int16_t>(p, out);
      case PlyType::kU16:
        return copyAs<std::uint16_t>(p, out);
      case PlyType::kI32:
        return copyAs<std::int32_t>(p, out);
      case PlyType::kU32:
        return copyAs<std::uint32_t>(p, out);
      case PlyType::kF32:
        return copyAs<float>(p, out);
      case PlyType::kF64:
        return copyAs<double>(p, out);
      case PlyType::kInvalid:
        break;
    }
    return false;
  }

 private:
  template <class T>
  static bool copyAs(const char* p, double& out) {
    T value;
    std::memcpy(&value, p, sizeof(T));  // x86/ARM hosts are little-endian, as the file
    out = static_cast<double>(value);
    return true;
  }

  std::string_view body_;
  bool binary_;
  std::size_t pos_ = 0;
  std::istringstream ascii_;
};

}  // namespace

Result<geom::TriangleMesh> parsePly(std::string_view bytes, const std::string& origin,
                                    const MeshLimits& limits) {
  const std::size_t end = bytes.find("end_header");
  if (bytes.substr(0, 3) != "ply" || end == std::string_view::npos)
    return fail(ErrorCode::kParse, origin + ": not a PLY file");
  const std::size_t body_start = bytes.find('\n', end);
  if (body_start == std::string_view::npos) return fail(ErrorCode::kParse, origin + ": truncated");

  std::istringstream header{std::string(bytes.substr(0, end))};
  std::vector<PlyElement> elements;
  std::size_t declared = 0, vertices = 0, faces = 0;
  bool binary = false;
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(header, line)) {
    ++line_no;
    std::istringstream f(line);
    std::string tag;
    f >> tag;
    if (tag == "format") {
      std::string fmt;
      f >> fmt;
      if (fmt == "binary_little_endian")
        binary = true;
      else if (fmt != "ascii")
        return parseError(origin, line_no, "unsupported PLY format " + fmt);
    } else if (tag == "element") {
      PlyElement e;
      if (!(f >> e.name >> e.count)) return parseError(origin, line_no, "bad element line");
      // What the elements may declare together: each record takes at least one byte
      // (binary) or two (ascii), so records beyond the file's size are a lie (checked
      // once the properties are known, below).
      declared += e.count;
      if (e.count > bytes.size() || declared > bytes.size()) {
        return parseError(origin, line_no,
                          "elements declare " + std::to_string(declared) +
                              " records in a file of " + std::to_string(bytes.size()) + " bytes");
      }
      if (e.name == "vertex") vertices += e.count;
      if (e.name == "face") faces += e.count;
      if (vertices > limits.vertices) return tooLarge(origin, "vertices", limits.vertices);
      if (faces > limits.faces) return tooLarge(origin, "faces", limits.faces);
      elements.push_back(e);
    } else if (tag == "property") {
      if (elements.empty()) return parseError(origin, line_no, "property before element");
      PlyProperty p;
      std::string type;
      f >> type;
      if (type == "list") {
        std::string count_type, item_type;
        f >> count_type >> item_type >> p.name;
        p.is_list = true;
        p.count_type = plyType(count_type);
        p.type = plyType(item_type);
        if (p.count_type == PlyType::kInvalid) return parseError(origin, line_no, "bad list type");
      } else {
        p.type = plyType(type);
        f >> p.name;
      }
      if (p.type == PlyType::kInvalid) return parseError(origin, line_no, "bad property type");
      elements.back().props.push_back(p);
    }
  }

  for (const auto& e : elements) {
    // A record of no property reads nothing: its count would only spin.
    if (e.props.empty() && e.count > 0) {
      return fail(ErrorCode::kParse, origin + ": element '" + e.name + "' has no properties");
    }
  }
  geom::TriangleMesh mesh;
  PlyReader reader(bytes.substr(body_start + 1), binary);
  for (const auto& e : elements) {
    // A vertex's u v (a measured surface's projector pixel) is kept when both are given.
    const auto has = [&e](const char* name) {
      return std::any_of(e.props.begin(), e.props.end(),
                         [name](const PlyProperty& p) { return !p.is_list && p.name == name; });
    };
    const bool with_uv = e.name == "vertex" && has("u") && has("v");
    // Texture coordinates: s t, or texture_u texture_v.
    const char* tex_s = has("s") && has("t") ? "s" : "texture_u";
    const char* tex_t = has("s") && has("t") ? "t" : "texture_v";
    const bool with_tex = e.name == "vertex" && has(tex_s) && has(tex_t);
    for (std::size_t i = 0; i < e.count; ++i) {
      Vec3 v = Vec3::Zero();
      Vec2 uv = Vec2::Zero(), tex = Vec2::Zero();
      for (const auto& p : e.props) {
        if (p.is_list) {
          double count = 0;
          if (!reader.read(p.count_type, count) || !(count >= 0))
            return fail(ErrorCode::kParse, origin + ": truncated " + e.name + " list");
          if (count > double(limits.face_indices))
            return tooLarge(origin, "indices in one " + e.name + " list", limits.face_indices);
          std::vector<int> idx(static_cast<std::size_t>(count));
          for (auto& k : idx) {
            double value = 0;
            if (!reader.read(p.type, value))
              return fail(ErrorCode::kParse, origin + ": truncated " + e.name + " list");
            if (!(value >= -1e9 && value <= 1e9))
              return fail(ErrorCode::kParse, origin + ": " + e.name + " index out of range");
            k = static_cast<int>(value);
          }
          if (e.name == "face" && (p.name == "vertex_indices" || p.name == "vertex_index")) {
            if (idx.size() < 3) return fail(ErrorCode::kParse, origin + ": face with < 3 vertices");
            if (mesh.faces.size() + idx.size() - 2 > limits.faces)
              return tooLarge(origin, "triangles", limits.faces);
            for (std::size_t k = 1; k + 1 < idx.size(); ++k)
              mesh.faces.emplace_back(idx[0], idx[k], idx[k + 1]);
          }
        } else {
          double value = 0;
          if (!reader.read(p.type, value))
            return fail(ErrorCode::kParse, origin + ": truncated " + e.name + " data");
          if (e.name == "vertex" && p.name.size() == 1 && p.name[0] >= 'x' && p.name[0] <= 'z')
            v[p.name[0] - 'x'] = value;
          if (with_uv && (p.name == "u" || p.name == "v")) uv[p.name == "u" ? 0 : 1] = value;
          if (with_tex && (p.name == tex_s || p.name == tex_t))
            tex[p.name == tex_s ? 0 : 1] = value;
        }
      }
      if (e.name == "vertex") {
        if (mesh.vertices.size() >= limits.vertices)
          return tooLarge(origin, "vertices", limits.vertices);
        mesh.vertices.push_back(v);
        if (with_uv) mesh.uv.push_back(uv);
        if (with_tex) mesh.texcoord.push_back(tex);
      }
    }
  }
  return checked(std::move(mesh), origin);
}

Result<geom::TriangleMesh> parseMesh(std::string_view bytes, const std::string& name,
                                     const MeshLimits& limits) {
  std::string ext = std::filesystem::path(name).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".obj") return parseObj(bytes, name, limits);
  if (ext == ".ply") return parsePly(bytes, name, limits);
  return fail(ErrorCode::kInvalidInput, "unknown mesh format (want .obj or .ply): " + name);
}

Result<geom::TriangleMesh> loadMesh(const std::filesystem::path& file, const MeshLimits& limits) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    return fail(ErrorCode::kIo, "cannot open mesh file " + file.string() + ": not a regular file");
  }
  const auto size = std::filesystem::file_size(file, ec);
  if (!ec && size > limits.file_bytes) return tooLarge(file.string(), "bytes", limits.file_bytes);
  std::ifstream in(file, std::ios::binary);
  if (!in) return fail(ErrorCode::kIo, "cannot open mesh file " + file.string());
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return parseMesh(bytes, file.string(), limits);
}

}  // namespace procam::sim
