// libFuzzer target: procamd.toml parsing. Any text must give a configuration
// or an error message naming the file, never crash or throw.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto cfg = procam::daemon::parseConfig(text, "fuzz.toml");
  if (cfg) {
    if (cfg->max_clients < 1 || cfg->client_queue_kib < 64) std::abort();
    for (const auto& d : cfg->devices) {
      if (d.name.empty()) std::abort();
    }
  } else if (cfg.error().message.rfind("fuzz.toml:", 0) != 0) {
    std::abort();  // every message starts with the source name
  }
  return 0;
}
