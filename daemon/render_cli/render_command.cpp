#include "render_command.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "blend/mpcdi.hpp"
#include "blend/rig_tiles.hpp"
#include "blend/tile_frames.hpp"
#include "blend/tiled_blend.hpp"
#include "content/image_header.hpp"
#include "curved_render.hpp"
#include "json_matrix.hpp"
#include "mpcdi_zip.hpp"
#include "object_render.hpp"
#include "replace_file.hpp"
#include "rig/rig_model.hpp"

namespace procam::render_cli {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr std::uintmax_t kMaxRigBytes = std::uintmax_t{16} << 20;
constexpr std::uintmax_t kMaxContentBytes = std::uintmax_t{256} << 20;
constexpr double kMaxContentPixels = 33554432;  // the daemon's default [limits] image_pixels

Result<std::vector<double>> numberList(const std::string& text, std::size_t n,
                                       const std::string& option) {
  std::vector<double> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(v))
      return fail(ErrorCode::kInvalidInput, option + ": '" + item + "' is not a number");
    out.push_back(v);
  }
  if (out.size() != n)
    return fail(ErrorCode::kInvalidInput,
                option + " takes " + std::to_string(n) + " comma-separated numbers");
  return out;
}

Result<std::string> readSmallFile(const fs::path& file, std::uintmax_t limit) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    return fail(ErrorCode::kIo, "cannot read " + file.string() + ": not a regular file");
  if (fs::file_size(file, ec) > limit)
    return fail(ErrorCode::kTooLarge,
                file.string() + " is over " + std::to_string(limit >> 20) + " MiB");
  std::ifstream in(file, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) return fail(ErrorCode::kIo, "error reading " + file.string());
  return text;
}

// The content image, decoded; its header's size checked before decoding (a small file may
// declare a huge image).
Result<cv::Mat> readContent(const fs::path& file) {
  auto bytes = readSmallFile(file, kMaxContentBytes);
  if (!bytes) return tl::unexpected(bytes.error());
  auto header = content::readImageHeader(*bytes);
  if (!header) return fail(ErrorCode::kIo, file.string() + ": " + header.error().message);
  if (double(header->size.area()) > kMaxContentPixels)
    return fail(ErrorCode::kTooLarge, file.string() + " is over 33554432 pixels");
  cv::Mat content;
  try {
    content =
        cv::imdecode(cv::Mat(1, int(bytes->size()), CV_8U, bytes->data()), cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    return fail(ErrorCode::kIo, file.string() + ": " + e.what());
  }
  if (content.empty()) return fail(ErrorCode::kIo, "cannot decode " + file.string());
  if (double(content.total()) > kMaxContentPixels)
    return fail(ErrorCode::kTooLarge, file.string() + " is over 33554432 pixels");
  if ((content.depth() != CV_8U && content.depth() != CV_16U) ||
      (content.channels() != 1 && content.channels() != 3 && content.channels() != 4))
    return fail(ErrorCode::kInvalidInput,
                file.string() + ": an 8 or 16-bit grey, RGB or RGBA image is needed");
  return content;
}

// MPCDI's date form, UTC.
std::string utcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S", &tm);
  return buf;
}

}  // namespace

Result<RenderArgs> parseRenderArgs(const std::vector<std::string>& args) {
  RenderArgs a;
  bool object_only = false;  // an option only --object takes was given
  bool dome_fov_given = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& opt = args[i];
    const bool takes_value = opt == "--rig" || opt == "--content" || opt == "--out" ||
                             opt == "--rect" || opt == "--bit-depth" || opt == "--projector" ||
                             opt == "--mpcdi" || opt == "--viewer" || opt == "--dome" ||
                             opt == "--dome-fov" || opt == "--object" || opt == "--texture" ||
                             opt == "--off" || opt == "--light" || opt == "--specular" ||
                             opt == "--shininess" || opt == "--max-incidence" || opt == "--white";
    const auto number = [&](double lo, double hi) -> Result<double> {
      auto v = numberList(args[++i], 1, opt);
      if (!v) return tl::unexpected(v.error());
      if (!((*v)[0] >= lo && (*v)[0] <= hi))
        return fail(ErrorCode::kInvalidInput,
                    opt + " must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
      return (*v)[0];
    };
    if (takes_value && i + 1 >= args.size())
      return fail(ErrorCode::kInvalidInput, opt + " needs a value");
    object_only = object_only || opt == "--texture" || opt == "--off" || opt == "--light" ||
                  opt == "--specular" || opt == "--shininess" || opt == "--max-incidence" ||
                  opt == "--white";
    if (opt == "--rig") {
      a.rig = args[++i];
    } else if (opt == "--content") {
      a.content = args[++i];
    } else if (opt == "--out") {
      a.out = args[++i];
    } else if (opt == "--rect") {
      auto v = numberList(args[++i], 5, "--rect");
      if (!v) return tl::unexpected(v.error());
      if (!((*v)[3] > 0) || !((*v)[4] > 0))
        return fail(ErrorCode::kInvalidInput, "--rect: width and height must be positive");
      a.rect = blend::WorldRect{Vec3((*v)[0], (*v)[1], (*v)[2]), (*v)[3], (*v)[4]};
    } else if (opt == "--viewer") {
      auto v = numberList(args[++i], 3, "--viewer");
      if (!v) return tl::unexpected(v.error());
      a.viewer = Vec3((*v)[0], (*v)[1], (*v)[2]);
    } else if (opt == "--dome") {
      auto v = numberList(args[++i], 3, "--dome");
      if (!v) return tl::unexpected(v.error());
      if (!(std::hypot((*v)[0], (*v)[1]) > 1e-6 * std::max(1.0, std::abs((*v)[2]))))
        return fail(ErrorCode::kInvalidInput,
                    "--dome: the front must point away from the vertical");
      a.dome = Vec3((*v)[0], (*v)[1], (*v)[2]);
    } else if (opt == "--dome-fov") {
      auto v = number(1, 360);
      if (!v) return tl::unexpected(v.error());
      a.dome_fov_deg = *v;
      dome_fov_given = true;
    } else if (opt == "--bit-depth") {
      const std::string& v = args[++i];
      if (v != "8" && v != "16") return fail(ErrorCode::kInvalidInput, "--bit-depth is 8 or 16");
      a.bit_depth = std::stoi(v);
    } else if (opt == "--geometry-only") {
      a.geometry_only = true;
    } else if (opt == "--projector") {
      a.projectors.push_back(args[++i]);
    } else if (opt == "--mpcdi") {
      a.mpcdi = args[++i];
    } else if (opt == "--object") {
      a.object = args[++i];
    } else if (opt == "--texture") {
      a.texture = args[++i];
    } else if (opt == "--off") {
      a.off.push_back(args[++i]);
    } else if (opt == "--light") {
      auto v = numberList(args[++i], 3, "--light");
      if (!v) return tl::unexpected(v.error());
      a.light = Vec3((*v)[0], (*v)[1], (*v)[2]);
      if (!(a.light->norm() > 0))
        return fail(ErrorCode::kInvalidInput, "--light must be a non-zero direction");
    } else if (opt == "--specular") {
      auto v = number(0, 1);
      if (!v) return tl::unexpected(v.error());
      a.specular = *v;
    } else if (opt == "--shininess") {
      auto v = number(1, 10000);
      if (!v) return tl::unexpected(v.error());
      a.shininess = *v;
    } else if (opt == "--max-incidence") {
      auto v = number(1, 89);
      if (!v) return tl::unexpected(v.error());
      a.max_incidence_deg = *v;
    } else if (opt == "--white") {
      auto v = number(1e-12, 1e12);
      if (!v) return tl::unexpected(v.error());
      a.white = *v;
    } else {
      return fail(ErrorCode::kInvalidInput, "unknown option '" + opt + "'");
    }
  }
  if (!a.object.empty()) {
    if (a.rig.empty() || a.out.empty())
      return fail(ErrorCode::kInvalidInput, "--object needs --rig and --out");
    if (!a.content.empty() || !a.mpcdi.empty() || a.rect || a.geometry_only)
      return fail(ErrorCode::kInvalidInput,
                  "--object takes --texture, not --content, --mpcdi, --rect or --geometry-only");
    return a;
  }
  if (object_only)
    return fail(ErrorCode::kInvalidInput,
                "--texture, --off, --light, --specular, --shininess, --max-incidence and --white "
                "are for --object");
  if (a.rig.empty() || a.content.empty() || (a.out.empty() && a.mpcdi.empty()))
    return fail(ErrorCode::kInvalidInput, "--rig, --content and --out or --mpcdi are required");
  if (dome_fov_given && !a.dome)
    return fail(ErrorCode::kInvalidInput, "--dome-fov is the field of a dome master: give --dome");
  return a;
}

namespace {

Result<json> runCurved(const RenderArgs& args, const rig::RigModel& rig) {
  if (args.rect) return fail(ErrorCode::kInvalidInput, "--rect is for a planar display");
  auto content = readContent(args.content);
  if (!content) return tl::unexpected(content.error());
  std::error_code ec;
  if (!args.out.empty()) {
    fs::create_directories(args.out, ec);
    if (ec) return fail(ErrorCode::kIo, "cannot create " + args.out.string() + ": " + ec.message());
  }
  CurvedRenderInput in;
  in.rig = &rig;
  in.rig_file = args.rig;
  in.projectors = args.projectors;
  in.viewer = args.viewer;
  in.dome_front = args.dome;
  in.dome_fov_deg = args.dome_fov_deg;
  in.content = *content;
  in.out = args.out;
  in.mpcdi = args.mpcdi;
  in.date = utcNow();
  in.bit_depth = args.bit_depth;
  in.geometry_only = args.geometry_only;
  auto doc = renderCurved(in);
  if (!doc) return tl::unexpected(doc.error());
  (*doc)["rig"] = args.rig.string();
  (*doc)["content"] = {{"path", args.content.string()}, {"size", {content->cols, content->rows}}};
  (*doc)["bit_depth"] = args.bit_depth;
  (*doc)["geometry_only"] = args.geometry_only;
  if (!args.mpcdi.empty()) (*doc)["mpcdi"] = args.mpcdi.string();
  if (!args.out.empty()) {
    if (auto ok = replaceFileWith(args.out / "display.json", doc->dump(2) + "\n"); !ok)
      return tl::unexpected(ok.error());
  }
  return doc;
}

Result<json> runObject(const RenderArgs& args, const rig::RigModel& rig) {
  ObjectRenderInput in;
  in.rig = &rig;
  in.object = args.object;
  if (!args.texture.empty()) {
    auto texture = readContent(args.texture);
    if (!texture) return tl::unexpected(texture.error());
    in.texture = *texture;
  }
  in.projectors = args.projectors;
  in.off = args.off;
  in.viewer = args.viewer;
  in.light = args.light;
  in.specular = args.specular;
  in.shininess = args.shininess;
  in.max_incidence_deg = args.max_incidence_deg;
  in.white = args.white;
  in.out = args.out;
  in.bit_depth = args.bit_depth;
  auto doc = renderObject(in);
  if (!doc) return tl::unexpected(doc.error());
  (*doc)["rig"] = args.rig.string();
  if (!args.texture.empty()) (*doc)["object"]["texture"] = args.texture.string();
  (*doc)["bit_depth"] = args.bit_depth;
  if (auto ok = replaceFileWith(args.out / "display.json", doc->dump(2) + "\n"); !ok)
    return tl::unexpected(ok.error());
  return doc;
}

}  // namespace

Result<json> runRender(const RenderArgs& args) {
  auto text = readSmallFile(args.rig, kMaxRigBytes);
  if (!text) return tl::unexpected(text.error());
  auto rig = rig::rigFromText(*text, args.rig.string());
  if (!rig) return tl::unexpected(rig.error());
  if (!args.object.empty()) return runObject(args, *rig);

  // The projectors of the display, in rig order.
  std::vector<const rig::RigProjector*> chosen;
  for (const std::string& name : args.projectors) {
    const auto it = std::find_if(rig->projectors.begin(), rig->projectors.end(),
                                 [&](const rig::RigProjector& p) { return p.name == name; });
    if (it == rig->projectors.end())
      return fail(ErrorCode::kNotFound, "no projector '" + name + "' in " + args.rig.string());
  }
  // A rig with surface meshes (route (a) on a curved surface), or a viewer given: one
  // display for the viewer.
  const bool meshed = !rig->surface.meshes.empty() || !rig->surface.unified_mesh.empty();
  if (args.viewer || args.dome || (meshed && !rig->surface.plane)) return runCurved(args, *rig);

  std::vector<blend::DisplayTile> tiles;
  std::vector<std::optional<blend::ProjectorResponse>> responses;
  std::vector<std::string> skipped;
  for (const rig::RigProjector& p : rig->projectors) {
    const bool asked =
        std::find(args.projectors.begin(), args.projectors.end(), p.name) != args.projectors.end();
    if (!args.projectors.empty() && !asked) continue;
    // Names become file names in --out and the package: nothing that leaves the folder.
    if (!blend::isSafeRegionId(p.name))
      return fail(
          ErrorCode::kInvalidInput,
          "projector name '" + p.name + "' cannot name a file (1-128 of A-Z a-z 0-9 . _ -)");
    auto tile = blend::displayTile(p, rig->surface);
    if (!tile) {
      if (asked) return tl::unexpected(tile.error());
      skipped.push_back(p.name + ": " + tile.error().message);
      continue;
    }
    chosen.push_back(&p);
    tiles.push_back(*tile);
    responses.push_back(blend::projectorResponse(p));
  }
  if (tiles.empty()) {
    std::string why;
    for (const auto& s : skipped) why += "; " + s;
    return fail(ErrorCode::kNotFound,
                "no projector of " + args.rig.string() + " maps onto a display plane" + why);
  }

  auto decoded = readContent(args.content);
  if (!decoded) return tl::unexpected(decoded.error());
  const cv::Mat& content = *decoded;

  blend::TiledDisplayOptions options;
  options.world_rect = args.rect;
  auto made = blend::makeTiledBlend(tiles, responses, content.size(), options);
  if (!made) return tl::unexpected(made.error());

  std::error_code ec;
  if (!args.out.empty()) {
    fs::create_directories(args.out, ec);
    if (ec) return fail(ErrorCode::kIo, "cannot create " + args.out.string() + ": " + ec.message());
  }
  const blend::TiledDisplay& d = made->display;
  json projectors = json::array();
  std::vector<std::string> names;
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    names.push_back(chosen[t]->name);
    const std::string file = chosen[t]->name + ".png";
    if (!args.out.empty()) {
      auto frame = blend::tileFrame(content, *made, t, {args.bit_depth, args.geometry_only});
      if (!frame) return tl::unexpected(frame.error());
      std::vector<uint8_t> png;
      if (!cv::imencode(".png", *frame, png))
        return fail(ErrorCode::kIo, "cannot encode " + chosen[t]->name + "'s frame");
      if (auto ok = replaceFileWith(args.out / file, std::string(png.begin(), png.end())); !ok)
        return tl::unexpected(ok.error());
    }
    json footprint = json::array();
    for (const Vec2& q : d.footprints[t])
      footprint.push_back(daemon::vectorJson(d.basis.toWorld(q)));
    projectors.push_back({{"name", chosen[t]->name},
                          {"output", chosen[t]->output},
                          {"file", file},
                          {"size", {tiles[t].width, tiles[t].height}},
                          {"path", "homography"},
                          {"homography", daemon::rowMajor(d.content_to_framebuffer[t])},
                          {"footprint_world", footprint},
                          {"response_gamma", made->gamma[t]},
                          {"gain", made->gain[t]}});
  }
  json doc = {
      {"rig", args.rig.string()},
      {"content", {{"path", args.content.string()}, {"size", {content.cols, content.rows}}}},
      {"bit_depth", args.bit_depth},
      {"geometry_only", args.geometry_only},
      {"display",
       {{"centre_world", daemon::vectorJson(d.basis.toWorld(d.rect.centre))},
        {"size_m", {2 * d.rect.half_width, 2 * d.rect.half_height}},
        {"rect_source", args.rect ? "given" : "largest"},
        {"basis",
         {{"origin", daemon::vectorJson(d.basis.origin)},
          {"u", daemon::vectorJson(d.basis.u)},
          {"v", daemon::vectorJson(d.basis.v)}}},
        {"rect_in_basis", {{"centre", daemon::vectorJson(d.rect.centre)}}},
        {"union_area_m2", d.union_area_m2}}},
      {"blend",
       {{"weights", args.geometry_only ? "none" : "feathered"},
        {"response", args.geometry_only ? "none"
                     : made->measured   ? "measured"
                                        : "assumed gamma 2.2"},
        {"photometric",
         args.geometry_only ? json{{"matching", "none"}} : blend::matchingJson(*made)}}},
      {"projectors", projectors}};
  if (!skipped.empty()) doc["skipped"] = skipped;
  if (!args.mpcdi.empty()) {
    auto package = blend::mpcdi2d(*made, names, content.size(), utcNow());
    if (!package) return tl::unexpected(package.error());
    if (auto ok = writeMpcdiZip(args.mpcdi, *package); !ok) return tl::unexpected(ok.error());
    doc["mpcdi"] = args.mpcdi.string();
  }
  if (!args.out.empty()) {
    if (auto ok = replaceFileWith(args.out / "display.json", doc.dump(2) + "\n"); !ok)
      return tl::unexpected(ok.error());
  }
  return doc;
}

}  // namespace procam::render_cli
