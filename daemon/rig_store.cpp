#include "rig_store.hpp"

#include <ctime>
#include <filesystem>

namespace procam::daemon {

namespace {
// A rig of 64 cameras and 64 projectors is about 100 KB of JSON.
constexpr std::uintmax_t kMaxRigBytes = 16u << 20;
// A surface or object mesh file beside an imported rig.json: [limits] file_mib's default.
constexpr std::uintmax_t kMaxMeshBytes = std::uintmax_t{256} << 20;
}  // namespace

StateFile rigStateFile(const std::string& state_dir) {
  return StateFile(state_dir, kRigFileName, [](std::string_view text) -> Result<void> {
    if (auto r = rig::rigFromText(text, kRigFileName); !r) return tl::unexpected(r.error());
    return {};
  });
}

Result<LoadedRig> loadRig(const std::string& state_dir) {
  const StateFile file = rigStateFile(state_dir);
  LoadedRig out;
  out.path = file.path();
  auto loaded = file.read();
  if (!loaded) {
    if (loaded.error().code == ErrorCode::kNotFound) return out;
    return tl::unexpected(loaded.error());
  }
  if (loaded->from_backup) out.warning = loaded->warning;
  auto parsed = rig::rigFromText(loaded->contents, out.path);  // validated by read()
  if (!parsed) return tl::unexpected(parsed.error());
  out.rig = std::move(*parsed);
  return out;
}

std::string meshFileName(const std::string& projector) {
  std::string safe;
  for (char c : projector) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '-' || c == '_';
    safe += ok ? c : '_';
  }
  return "surface-" + safe + ".ply";
}

Result<rig::RigModel> mergeIntoRig(const std::string& state_dir, const rig::RigModel& update,
                                   const std::map<std::string, std::string>& meshes) {
  auto base = loadRig(state_dir);
  if (!base) return tl::unexpected(base.error());
  for (const auto& [name, text] : meshes) {
    const StateFile mesh(state_dir, name, [](std::string_view t) -> Result<void> {
      if (t.substr(0, 4) != "ply\n") return fail(ErrorCode::kParse, "not an ASCII PLY file");
      return {};
    });
    if (auto ok = mesh.write(text); !ok) return tl::unexpected(ok.error());
  }
  rig::RigModel merged = rig::mergeRig(std::move(base->rig), update);
  if (auto ok = rigStateFile(state_dir).write(rig::rigToJson(merged).dump(2) + "\n"); !ok) {
    return tl::unexpected(ok.error());
  }
  return merged;
}

Result<rig::RigModel> importRig(const std::string& state_dir, const std::string& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    return fail(ErrorCode::kIo, file + ": not a regular file");
  }
  if (std::filesystem::file_size(file, ec) > kMaxRigBytes || ec) {
    return fail(ErrorCode::kInvalidInput, file + ": larger than a rig model can be (" +
                                              std::to_string(kMaxRigBytes >> 20) + " MiB)");
  }
  auto text = readWholeFile(file);
  if (!text) return tl::unexpected(text.error());
  auto parsed = rig::rigFromText(*text, file);
  if (!parsed) return tl::unexpected(parsed.error());
  const StateFile target = rigStateFile(state_dir);
  if (auto ok = target.ensureDirectory(); !ok) return tl::unexpected(ok.error());
  std::vector<std::string> meshes;
  for (const auto& [projector, name] : parsed->surface.meshes) meshes.push_back(name);
  if (!parsed->surface.unified_mesh.empty()) meshes.push_back(parsed->surface.unified_mesh);
  if (parsed->surface.object) meshes.push_back(parsed->surface.object->mesh);
  const std::filesystem::path beside = std::filesystem::path(file).parent_path();
  for (const std::string& name : meshes) {
    if (!rig::RigSurface::isPlainFileName(name)) {
      return fail(ErrorCode::kInvalidInput,
                  file + ": mesh '" + name + "' is not a file name beside it");
    }
    const std::filesystem::path from = beside / name;
    if (!std::filesystem::is_regular_file(from, ec)) {
      if (std::filesystem::is_regular_file(std::filesystem::path(state_dir) / name, ec)) continue;
      return fail(ErrorCode::kNotFound,
                  file + ": mesh '" + name + "' is neither beside it nor in the state directory");
    }
    if (std::filesystem::file_size(from, ec) > kMaxMeshBytes || ec) {
      return fail(ErrorCode::kInvalidInput, from.string() + ": larger than a mesh file can be");
    }
    auto bytes = readWholeFile(from.string());
    if (!bytes) return tl::unexpected(bytes.error());
    const StateFile mesh(state_dir, name, [](std::string_view) -> Result<void> { return {}; });
    if (auto ok = mesh.write(*bytes); !ok) return tl::unexpected(ok.error());
  }
  // Written as parsed (version 2), so that a later merge keeps its form.
  if (auto ok = target.write(rig::rigToJson(*parsed).dump(2) + "\n"); !ok) {
    return tl::unexpected(ok.error());
  }
  return parsed;
}

std::string utcNow() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace procam::daemon
