#include "cli_files.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "commands.hpp"
#include "core/pfm.hpp"

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

}  // namespace

Result<void> writeText(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  if (!out) return fail(ErrorCode::kIo, "cannot write " + file.string());
  out << text;
  if (!out.flush()) return fail(ErrorCode::kIo, "error writing " + file.string());
  return {};
}

Result<nlohmann::json> readJson(const fs::path& file) {
  // Reading a directory throws from the stream buffer; a FIFO would block.
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    return fail(ErrorCode::kIo, "cannot read " + file.string() + ": not a regular file");
  }
  if (fs::file_size(file, ec) > (std::uintmax_t{64} << 20)) {
    return fail(ErrorCode::kTooLarge, file.string() + " is over 64 MiB");
  }
  std::ifstream in(file);
  if (!in) return fail(ErrorCode::kIo, "cannot read " + file.string());
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    return fail(ErrorCode::kParse, file.string() + ": " + e.what());
  } catch (const std::exception& e) {
    return fail(ErrorCode::kIo, file.string() + ": " + e.what());
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
  cv::Mat uvc;
  cv::merge(std::vector<cv::Mat>{d.u, d.v, d.confidence}, uvc);
  auto data = encodePfm(uvc);
  if (!data) return tl::unexpected(data.error());
  return writeText(file, *data);
}

Result<std::vector<NamedCamera>> readCameras(const fs::path& file) {
  auto j = readJson(file);
  if (!j) return tl::unexpected(j.error());
  return rig::camerasFromJson(*j, file.string());
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

Result<sl::Decoded> decodeDir(const sl::PatternSet& set, const std::string& dir, std::size_t i,
                              std::size_t n) {
  progress("decoding captures " + std::to_string(i + 1) + "/" + std::to_string(n) + " (" + dir +
           ", " + std::to_string(set.frames.size()) + " frames)");
  auto frames = readCaptures(set, dir);
  if (!frames) return tl::unexpected(frames.error());
  auto d = sl::decode(set, *frames);
  if (!d) return d;
  progress("  " + std::to_string(d->decoded) + " camera pixels decoded");
  if (d->decoded == 0)
    return fail(ErrorCode::kTooFewPoints, "no camera pixel of " + dir +
                                              " could be decoded (projector not visible, or "
                                              "captures in the wrong order?)");
  return d;
}

}  // namespace procam::cli
