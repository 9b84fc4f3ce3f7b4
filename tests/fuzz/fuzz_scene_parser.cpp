// libFuzzer target: scene files of the virtual rig (drivers/sim/scene_toml). Any
// text must give a scene or a typed error; never a crash, a throw or a hang.
// Mesh files a scene names are looked for in a folder that does not exist.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "sim/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto scene = procam::sim::Scene::parse(text, "fuzz.toml", "/nonexistent-procam-fuzz");
  if (!scene && scene.error().message.empty()) std::abort();  // every refusal says why
  return 0;
}
