#include "cli_files.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

namespace procam::cli {
namespace {

const char* kindName(sl::FrameKind k) {
  switch (k) {
    case sl::FrameKind::kWhite:
      return "white";
    case sl::FrameKind::kBlack:
      return "black";
    case sl::FrameKind::kGray:
      return "gray";
    case sl::FrameKind::kGrayInverse:
      return "gray_inverse";
    case sl::FrameKind::kPhase:
      return "phase";
  }
  return "?";
}

Result<std::vector<double>> numbers(const nlohmann::json& j, const char* key, std::size_t n,
                                    const std::string& where) {
  if (!j.contains(key) || !j[key].is_array() || j[key].size() != n)
    return fail(ErrorCode::kParse,
                where + ": '" + key + "' must be an array of " + std::to_string(n) + " numbers");
  std::vector<double> out;
  for (const auto& v : j[key]) {
    if (!v.is_number())
      return fail(ErrorCode::kParse, where + ": '" + key + "' holds a non-number");
    out.push_back(v.get<double>());
  }
  return out;
}

nlohmann::json matrixJson(const Mat3& m) {
  nlohmann::json a = nlohmann::json::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a.push_back(m(r, c));
  return a;
}

}  // namespace

Result<void> writeText(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  if (!out) return fail(ErrorCode::kIo, "cannot write " + file.string());
  out << text;
  if (!out.flush()) return fail(ErrorCode::kIo, "error writing " + file.string());
  return {};
}

Result<nlohmann::json> readJson(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return fail(ErrorCode::kIo, "cannot read " + file.string());
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    return fail(ErrorCode::kParse, file.string() + ": " + e.what());
  }
}

Result<void> writePatterns(const sl::PatternSet& set, const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return fail(ErrorCode::kIo, "cannot create " + dir.string() + ": " + ec.message());
  nlohmann::json frames = nlohmann::json::array();
  for (std::size_t i = 0; i < set.frames.size(); ++i) {
    const sl::FrameInfo& f = set.frames[i];
    const fs::path file = dir / (f.name + ".png");
    if (!cv::imwrite(file.string(), sl::renderFrame(set, i)))
      return fail(ErrorCode::kIo, "cannot write " + file.string());
    frames.push_back({{"name", f.name},
                      {"file", f.name + ".png"},
                      {"kind", kindName(f.kind)},
                      {"axis", f.axis == sl::Axis::kColumns ? "columns" : "rows"},
                      {"index", f.index}});
  }
  const sl::PatternOptions& o = set.options;
  nlohmann::json j = {{"projector", {{"width", o.width}, {"height", o.height}}},
                      {"mode", sl::toString(o.mode)},
                      {"step", o.step},
                      {"phase_steps", o.phase_steps},
                      {"phase_period", o.phase_period},
                      {"projector_gamma", o.projector_gamma},
                      {"frames", frames}};
  return writeText(dir / "sequence.json", j.dump(2) + "\n");
}

Result<sl::PatternSet> readSequence(const fs::path& dir) {
  auto j = readJson(dir / "sequence.json");
  if (!j) return tl::unexpected(j.error());
  try {
    sl::PatternOptions o;
    o.width = j->at("projector").at("width").get<int>();
    o.height = j->at("projector").at("height").get<int>();
    auto mode = sl::parseMode(j->at("mode").get<std::string>());
    if (!mode) return tl::unexpected(mode.error());
    o.mode = *mode;
    o.step = j->at("step").get<int>();
    o.phase_steps = j->at("phase_steps").get<int>();
    o.phase_period = j->at("phase_period").get<int>();
    o.projector_gamma = j->at("projector_gamma").get<double>();
    auto set = sl::makePatternSet(o);
    if (!set) return tl::unexpected(set.error());
    const auto& frames = j->at("frames");
    if (frames.size() != set->frames.size())
      return fail(ErrorCode::kParse,
                  (dir / "sequence.json").string() + " lists " + std::to_string(frames.size()) +
                      " frames, the options give " + std::to_string(set->frames.size()));
    for (std::size_t i = 0; i < frames.size(); ++i)
      if (frames[i].at("name").get<std::string>() != set->frames[i].name)
        return fail(ErrorCode::kParse, "sequence.json frame " + std::to_string(i) + " is '" +
                                           frames[i].at("name").get<std::string>() +
                                           "', expected '" + set->frames[i].name + "'");
    return set;
  } catch (const nlohmann::json::exception& e) {
    return fail(ErrorCode::kParse, (dir / "sequence.json").string() + ": " + e.what());
  }
}

Result<std::vector<cv::Mat>> readCaptures(const sl::PatternSet& set, const fs::path& dir) {
  if (!fs::is_directory(dir))
    return fail(ErrorCode::kIo, "captures directory " + dir.string() + " does not exist");
  std::vector<cv::Mat> out;
  for (const sl::FrameInfo& f : set.frames) {
    const fs::path file = dir / (f.name + ".png");
    if (!fs::exists(file)) return fail(ErrorCode::kIo, "missing frame: " + file.string());
    cv::Mat m = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
    if (m.empty()) return fail(ErrorCode::kIo, "cannot read " + file.string());
    if (!out.empty() && m.size() != out[0].size())
      return fail(ErrorCode::kInvalidInput, file.string() + " is " + std::to_string(m.cols) + "x" +
                                                std::to_string(m.rows) + ", the first capture " +
                                                std::to_string(out[0].cols) + "x" +
                                                std::to_string(out[0].rows));
    out.push_back(std::move(m));
  }
  return out;
}

Result<void> writeCorrespondencePfm(const sl::Decoded& d, const fs::path& file) {
  const int w = d.u.cols, h = d.u.rows;
  std::string data = "PF\n" + std::to_string(w) + " " + std::to_string(h) + "\n-1.0\n";
  const std::size_t header = data.size();
  data.resize(header + static_cast<std::size_t>(w) * h * 3 * sizeof(float));
  char* p = data.data() + header;
  for (int row = h - 1; row >= 0; --row) {  // PFM stores the bottom row first
    const float* u = d.u.ptr<float>(row);
    const float* v = d.v.ptr<float>(row);
    const float* c = d.confidence.ptr<float>(row);
    for (int x = 0; x < w; ++x)
      for (float value : {u[x], v[x], c[x]}) {
        auto bits = std::bit_cast<std::uint32_t>(value);
        if constexpr (std::endian::native == std::endian::big) bits = __builtin_bswap32(bits);
        std::memcpy(p, &bits, 4);
        p += 4;
      }
  }
  return writeText(file, data);
}

Result<std::vector<NamedCamera>> readCameras(const fs::path& file) {
  auto j = readJson(file);
  if (!j) return tl::unexpected(j.error());
  if (!j->contains("cameras") || !(*j)["cameras"].is_array() || (*j)["cameras"].empty())
    return fail(ErrorCode::kParse,
                file.string() + ": expected {\"cameras\": [ ... ]} with at least one camera");
  std::vector<NamedCamera> out;
  for (const auto& c : (*j)["cameras"]) {
    NamedCamera n;
    const std::string where = file.string() + " camera " + std::to_string(out.size());
    n.name = c.value("name", "camera" + std::to_string(out.size()));
    if (!c.contains("width") || !c.contains("height") || !c["width"].is_number_integer() ||
        !c["height"].is_number_integer())
      return fail(ErrorCode::kParse, where + ": 'width' and 'height' are required integers");
    n.model.width = c["width"].get<int>();
    n.model.height = c["height"].get<int>();
    auto K = numbers(c, "K", 9, where);
    auto R = numbers(c, "R", 9, where);
    auto t = numbers(c, "t", 3, where);
    if (!K) return tl::unexpected(K.error());
    if (!R) return tl::unexpected(R.error());
    if (!t) return tl::unexpected(t.error());
    Mat3 Km, Rm;
    for (int i = 0; i < 9; ++i) Km(i / 3, i % 3) = (*K)[i], Rm(i / 3, i % 3) = (*R)[i];
    n.model.K = geom::Intrinsics::fromMatrix(Km);
    if (c.contains("dist")) {
      auto d = numbers(c, "dist", 5, where);
      if (!d) return tl::unexpected(d.error());
      n.model.dist = {(*d)[0], (*d)[1], (*d)[2], (*d)[3], (*d)[4]};
    }
    if ((Rm.transpose() * Rm - Mat3::Identity()).norm() > 1e-6 || Rm.determinant() < 0)
      return fail(ErrorCode::kParse, where + ": 'R' is not a rotation matrix");
    n.model.pose.R = Rm;
    n.model.pose.t = Vec3((*t)[0], (*t)[1], (*t)[2]);
    out.push_back(std::move(n));
  }
  return out;
}

nlohmann::json cameraJson(const NamedCamera& c) {
  const auto& m = c.model;
  nlohmann::json j = {{"name", c.name},
                      {"width", m.width},
                      {"height", m.height},
                      {"K", matrixJson(m.K.matrix())},
                      {"dist", {m.dist.k1, m.dist.k2, m.dist.p1, m.dist.p2, m.dist.k3}},
                      {"R", matrixJson(m.pose.R)},
                      {"t", {m.pose.t.x(), m.pose.t.y(), m.pose.t.z()}}};
  if (c.rms_px >= 0) j["reprojection_rms_px"] = c.rms_px;
  return j;
}

nlohmann::json projectorJson(const NamedProjector& p) {
  const auto& c = p.calibration;
  nlohmann::json j = {{"name", p.name},
                      {"width", p.width},
                      {"height", p.height},
                      {"K", matrixJson(c.K.matrix())},
                      {"R", matrixJson(c.pose.R)},
                      {"t", {c.pose.t.x(), c.pose.t.y(), c.pose.t.z()}},
                      {"reprojection_rms_px", c.rms_px},
                      {"points", c.points}};
  if (!c.scale_known) j["translation_up_to_scale"] = true;
  return j;
}

Result<std::vector<fs::path>> listImages(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return fail(ErrorCode::kIo, dir.string() + " is not a directory");
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char ch) { return std::tolower(ch); });
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" || ext == ".tiff" ||
        ext == ".bmp")
      out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace procam::cli
