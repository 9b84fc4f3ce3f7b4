#include "sim/scene_library.hpp"

#include <filesystem>
#include <system_error>

#include "sim/embedded_scenes.hpp"

namespace procam::sim {

std::vector<std::string> builtinSceneNames() {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < detail::kEmbeddedSceneCount; ++i)
    names.emplace_back(detail::kEmbeddedScenes[i].name);
  return names;
}

std::optional<std::string_view> builtinSceneText(std::string_view name) {
  for (std::size_t i = 0; i < detail::kEmbeddedSceneCount; ++i) {
    if (detail::kEmbeddedScenes[i].name == name) return detail::kEmbeddedScenes[i].text;
  }
  return std::nullopt;
}

Result<Scene> resolveScene(std::string_view name_or_path) {
  const std::filesystem::path path(name_or_path);
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec)) return Scene::load(path);

  std::string_view name = name_or_path;
  if (name.ends_with(".toml")) name.remove_suffix(5);
  if (auto text = builtinSceneText(name)) {
    return Scene::parse(*text, std::string(name) + ".toml", {});
  }
  std::string known;
  for (const auto& n : builtinSceneNames()) known += (known.empty() ? "" : ", ") + n;
  return fail(ErrorCode::kNotFound, "no scene file or built-in scene '" +
                                        std::string(name_or_path) + "' (built-in: " + known + ")");
}

}  // namespace procam::sim
