#include "blend/mpcdi.hpp"

#include <tinyxml2.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "blend/tile_frames.hpp"
#include "core/pfm.hpp"

namespace procam::blend {

bool isSafeRegionId(const std::string& id) {
  return !id.empty() && id.size() <= 128 && id.front() != '.' &&
         std::all_of(id.begin(), id.end(), [](char c) {
           return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
         });
}

namespace {

// <name>text</name> under `parent`.
void child(tinyxml2::XMLDocument& doc, tinyxml2::XMLElement* parent, const char* name,
           const std::string& text) {
  tinyxml2::XMLElement* e = doc.NewElement(name);
  e->SetText(text.c_str());
  parent->InsertEndChild(e);
}

std::string number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

const std::string* fileNamed(const std::vector<MpcdiFile>& files, const std::string& name) {
  for (const auto& f : files) {
    if (f.name == name) return &f.bytes;
  }
  return nullptr;
}

// The width and height a PNG's IHDR declares, read before anything is decoded.
std::optional<cv::Size> pngSize(const std::string& bytes) {
  if (bytes.size() < 24 || bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 ||
      bytes.compare(12, 4, "IHDR") != 0)
    return std::nullopt;
  auto be32 = [&](std::size_t at) {
    uint32_t v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
    return v;
  };
  const uint32_t w = be32(16), h = be32(20);
  if (w == 0 || h == 0 || w > 65536 || h > 65536) return std::nullopt;
  return cv::Size(int(w), int(h));
}

const char* textOf(const tinyxml2::XMLElement* parent, const char* name) {
  const tinyxml2::XMLElement* e = parent ? parent->FirstChildElement(name) : nullptr;
  return e && e->GetText() ? e->GetText() : nullptr;
}

}  // namespace

Result<std::vector<MpcdiFile>> mpcdi2d(const BlendTables& blend,
                                       std::span<const render::RenderSetup> geometry,
                                       const std::vector<std::string>& names, cv::Size content,
                                       const std::string& date) {
  const std::size_t n = geometry.size();
  if (names.size() != n || blend.weights.size() != n || blend.gamma.size() != n ||
      blend.gain.size() != n)
    return fail(ErrorCode::kInvalidInput,
                "MPCDI: one name, geometry, weight map, gamma and gain per projector");
  if (content.width < 1 || content.height < 1)
    return fail(ErrorCode::kInvalidInput, "MPCDI: empty content size");
  for (const auto& id : names) {
    if (!isSafeRegionId(id)) return fail(ErrorCode::kInvalidInput, "MPCDI: region id '" + id + "'");
  }
  tinyxml2::XMLDocument doc;
  doc.InsertEndChild(doc.NewDeclaration("xml version=\"1.0\" encoding=\"utf-8\""));
  tinyxml2::XMLElement* root = doc.NewElement("MPCDI");
  root->SetAttribute("profile", "2d");
  root->SetAttribute("geometry", "1");
  root->SetAttribute("color", "1");
  // 1.0: the 2D media profile is defined since MPCDI 1.0, which every reader takes.
  root->SetAttribute("version", "1.0");
  root->SetAttribute("date", date.c_str());
  doc.InsertEndChild(root);
  tinyxml2::XMLElement* display = doc.NewElement("display");
  root->InsertEndChild(display);
  tinyxml2::XMLElement* buffer = doc.NewElement("buffer");
  buffer->SetAttribute("id", "display");
  buffer->SetAttribute("xResolution", content.width);
  buffer->SetAttribute("yResolution", content.height);
  display->InsertEndChild(buffer);
  tinyxml2::XMLElement* files = doc.NewElement("files");
  root->InsertEndChild(files);
  std::vector<MpcdiFile> out(1);
  for (std::size_t t = 0; t < n; ++t) {
    const cv::Mat& weights = blend.weights[t];
    const cv::Size size = weights.size();
    tinyxml2::XMLElement* region = doc.NewElement("region");
    region->SetAttribute("id", names[t].c_str());
    region->SetAttribute("xResolution", size.width);
    region->SetAttribute("yResolution", size.height);
    region->SetAttribute("x", "0");
    region->SetAttribute("y", "0");
    region->SetAttribute("xsize", "1");
    region->SetAttribute("ysize", "1");
    buffer->InsertEndChild(region);

    auto content_of = shareContent(geometry[t]);
    if (!content_of) return fail(content_of.error().code, "MPCDI: " + content_of.error().message);
    cv::Mat warp(size, CV_32FC3), alpha(size, CV_16UC1);
    for (int y = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x) {
        const auto p = (*content_of)(x, y);
        const double cx = p ? p->x() : -1e9, cy = p ? p->y() : -1e9;
        const bool shown =
            p && cx >= -0.5 && cy >= -0.5 && cx < content.width - 0.5 && cy < content.height - 0.5;
        // Outside the content: a fixed position off the buffer, never a mirrored one
        // from behind the wall's horizon or a value too large for a float.
        warp.at<cv::Vec3f>(y, x) = shown ? cv::Vec3f(float((cx + 0.5) / content.width),
                                                     float((cy + 0.5) / content.height), 0.0f)
                                         : cv::Vec3f(-1.0f, -1.0f, 0.0f);
        const double a =
            shown ? std::pow(blend.gain[t] * weights.at<float>(y, x), 1.0 / blend.gamma[t]) : 0.0;
        alpha.at<uint16_t>(y, x) = uint16_t(std::lround(std::clamp(a, 0.0, 1.0) * 65535));
      }
    }
    auto pfm = encodePfm(warp);
    if (!pfm) return tl::unexpected(pfm.error());
    std::vector<uint8_t> alpha_png, beta_png;
    if (!cv::imencode(".png", alpha, alpha_png) ||
        !cv::imencode(".png", cv::Mat(size, CV_8UC1, cv::Scalar(0)), beta_png))
      return fail(ErrorCode::kInternal, "MPCDI: PNG encoding failed");
    const std::string warp_name = names[t] + ".pfm", alpha_name = names[t] + "_alpha.png",
                      beta_name = names[t] + "_beta.png";
    out.push_back({warp_name, std::move(*pfm)});
    out.push_back({alpha_name, std::string(alpha_png.begin(), alpha_png.end())});
    out.push_back({beta_name, std::string(beta_png.begin(), beta_png.end())});

    tinyxml2::XMLElement* fileset = doc.NewElement("fileset");
    fileset->SetAttribute("region", names[t].c_str());
    files->InsertEndChild(fileset);
    tinyxml2::XMLElement* g = doc.NewElement("geometryWarpFile");
    fileset->InsertEndChild(g);
    child(doc, g, "path", warp_name);
    // geometricUnit and originOf3DData are required of every warp by MPCDI readers;
    // a 2D warp's values are normalized buffer positions, origin top left.
    child(doc, g, "geometricUnit", "m");
    child(doc, g, "interpolation", "linear");
    child(doc, g, "originOf3DData", "idealEyePoint");
    child(doc, g, "componentDepth", "2");
    child(doc, g, "bitDepth", "32");
    child(doc, g, "xSamples", std::to_string(size.width));
    child(doc, g, "ySamples", std::to_string(size.height));
    tinyxml2::XMLElement* am = doc.NewElement("alphaMap");
    fileset->InsertEndChild(am);
    child(doc, am, "path", alpha_name);
    child(doc, am, "gammaEmbedded", number(blend.gamma[t]));
    child(doc, am, "componentDepth", "1");
    child(doc, am, "bitDepth", "16");
    tinyxml2::XMLElement* bm = doc.NewElement("betaMap");
    fileset->InsertEndChild(bm);
    child(doc, bm, "path", beta_name);
    child(doc, bm, "componentDepth", "1");
    child(doc, bm, "bitDepth", "8");
  }
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  out[0] = {"mpcdi.xml", std::string(printer.CStr())};
  return out;
}

Result<std::vector<MpcdiFile>> mpcdi2d(const TiledBlend& blend,
                                       const std::vector<std::string>& names, cv::Size content,
                                       const std::string& date) {
  std::vector<render::RenderSetup> geometry(blend.display.content_to_framebuffer.size());
  for (std::size_t t = 0; t < geometry.size(); ++t) {
    geometry[t].path = render::RenderPath::kHomography;
    geometry[t].homography = blend.display.content_to_framebuffer[t];
  }
  return mpcdi2d(blend, geometry, names, content, date);
}

Result<std::vector<MpcdiFile>> mpcdi2d(const CurvedBlend& blend,
                                       const std::vector<std::string>& names, cv::Size content,
                                       const std::string& date) {
  std::vector<render::RenderSetup> geometry(blend.display.lookup.size());
  for (std::size_t t = 0; t < geometry.size(); ++t) {
    geometry[t].path = render::RenderPath::kLookupWarp;
    geometry[t].lookup = blend.display.lookup[t];
  }
  return mpcdi2d(blend, geometry, names, content, date);
}

Result<MpcdiDisplay> readMpcdi2d(const std::vector<MpcdiFile>& files) {
  const std::string* xml = fileNamed(files, "mpcdi.xml");
  if (!xml) return fail(ErrorCode::kParse, "MPCDI: no mpcdi.xml");
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml->data(), xml->size()) != tinyxml2::XML_SUCCESS)
    return fail(ErrorCode::kParse, std::string("MPCDI: mpcdi.xml: ") + doc.ErrorStr());
  const tinyxml2::XMLElement* root = doc.FirstChildElement("MPCDI");
  if (!root || !root->Attribute("profile", "2d"))
    return fail(ErrorCode::kParse, "MPCDI: not a 2d profile document");
  const tinyxml2::XMLElement* display = root->FirstChildElement("display");
  const tinyxml2::XMLElement* buffer = display ? display->FirstChildElement("buffer") : nullptr;
  if (!buffer) return fail(ErrorCode::kParse, "MPCDI: no display buffer");
  MpcdiDisplay out;
  out.buffer = {buffer->IntAttribute("xResolution"), buffer->IntAttribute("yResolution")};
  if (out.buffer.width < 1 || out.buffer.height < 1)
    return fail(ErrorCode::kParse, "MPCDI: buffer without a resolution");
  const tinyxml2::XMLElement* sets = root->FirstChildElement("files");
  for (const auto* r = buffer->FirstChildElement("region"); r;
       r = r->NextSiblingElement("region")) {
    MpcdiRegion region;
    region.id = r->Attribute("id") ? r->Attribute("id") : "";
    region.size = {r->IntAttribute("xResolution"), r->IntAttribute("yResolution")};
    if (region.size.width < 1 || region.size.height < 1 || region.size.width > 16384 ||
        region.size.height > 16384)
      return fail(ErrorCode::kParse, "MPCDI: region '" + region.id + "': resolution out of range");
    if (r->DoubleAttribute("x", -1) != 0 || r->DoubleAttribute("y", -1) != 0 ||
        r->DoubleAttribute("xsize") != 1 || r->DoubleAttribute("ysize") != 1)
      return fail(ErrorCode::kParse, "MPCDI: region '" + region.id + "' is not the whole buffer");
    const tinyxml2::XMLElement* set = sets ? sets->FirstChildElement("fileset") : nullptr;
    while (set && !set->Attribute("region", region.id.c_str())) {
      set = set->NextSiblingElement("fileset");
    }
    if (!set) return fail(ErrorCode::kParse, "MPCDI: no fileset for region '" + region.id + "'");
    const tinyxml2::XMLElement* g = set->FirstChildElement("geometryWarpFile");
    const tinyxml2::XMLElement* am = set->FirstChildElement("alphaMap");
    const char* warp_path = textOf(g, "path");
    const char* alpha_path = textOf(am, "path");
    const char* gamma = textOf(am, "gammaEmbedded");
    if (!warp_path || !alpha_path || !gamma)
      return fail(ErrorCode::kParse, "MPCDI: region '" + region.id + "': incomplete fileset");
    region.gamma_embedded = std::atof(gamma);
    const std::string* warp = fileNamed(files, warp_path);
    const std::string* alpha = fileNamed(files, alpha_path);
    if (!warp || !alpha)
      return fail(ErrorCode::kParse, "MPCDI: region '" + region.id + "': a file is missing");
    auto w = decodePfm(*warp, double(region.size.area()));
    if (!w) return tl::unexpected(w.error());
    if (w->type() != CV_32FC3 || w->size() != region.size)
      return fail(ErrorCode::kParse, "MPCDI: region '" + region.id + "': warp size differs");
    region.warp = *w;
    // The alpha map's size is checked before it is decoded: a small file may declare a
    // huge image.
    if (pngSize(*alpha) != std::optional<cv::Size>(region.size))
      return fail(ErrorCode::kParse, "MPCDI: region '" + region.id + "': alpha map differs");
    const cv::Mat a =
        cv::imdecode(cv::Mat(1, int(alpha->size()), CV_8U, const_cast<char*>(alpha->data())),
                     cv::IMREAD_UNCHANGED);
    if (a.empty() || a.channels() != 1 || a.size() != region.size)
      return fail(ErrorCode::kParse, "MPCDI: region '" + region.id + "': alpha map differs");
    a.convertTo(region.alpha, CV_64F, 1.0 / (a.depth() == CV_16U ? 65535 : 255));
    out.regions.push_back(std::move(region));
  }
  if (out.regions.empty()) return fail(ErrorCode::kParse, "MPCDI: no regions");
  return out;
}

Result<cv::Mat> mpcdiFrame(const MpcdiRegion& region, const cv::Mat& content) {
  auto unit = unitContent(content);
  if (!unit) return tl::unexpected(unit.error());
  const int channels = unit->channels();
  cv::Mat out(region.size, CV_MAKETYPE(CV_16U, channels), cv::Scalar::all(0));
  double v[3];
  for (int y = 0; y < region.size.height; ++y) {
    for (int x = 0; x < region.size.width; ++x) {
      const cv::Vec3f uv = region.warp.at<cv::Vec3f>(y, x);
      const double cx = uv[0] * unit->cols - 0.5, cy = uv[1] * unit->rows - 0.5;
      if (!sampleContent(*unit, cx, cy, v)) continue;
      const double a = region.alpha.at<double>(y, x);
      for (int c = 0; c < channels; ++c) {
        out.ptr<uint16_t>(y)[x * channels + c] =
            uint16_t(std::lround(std::clamp(v[c] * a, 0.0, 1.0) * 65535));
      }
    }
  }
  return out;
}

}  // namespace procam::blend
