#include "egl/driver_pin.hpp"

#include <dlfcn.h>
#include <link.h>

#include <mutex>
#include <set>
#include <string>
#include <vector>

namespace procam::output::egl {
namespace {

bool looksLikeGlDriver(const std::string& path) {
  const auto slash = path.rfind('/');
  const std::string file = slash == std::string::npos ? path : path.substr(slash + 1);
  return file.find("_dri.so") != std::string::npos ||
         file.rfind("libgallium", 0) == 0;  // Mesa >= 24 ships one libgallium-*.so
}

int collect(dl_phdr_info* info, size_t, void* data) {
  if (info->dlpi_name && looksLikeGlDriver(info->dlpi_name)) {
    static_cast<std::vector<std::string>*>(data)->push_back(info->dlpi_name);
  }
  return 0;
}

}  // namespace

int pinLoadedGlDrivers() {
  static std::mutex mutex;
  static std::set<std::string> pinned;
  std::vector<std::string> loaded;
  dl_iterate_phdr(collect, &loaded);
  std::lock_guard<std::mutex> lock(mutex);
  int count = 0;
  for (const std::string& path : loaded) {
    if (pinned.count(path)) continue;
    // RTLD_NOLOAD: only take a reference to the object already mapped; the handle is
    // deliberately never closed, and RTLD_NODELETE keeps it mapped past dlclose anyway.
    if (dlopen(path.c_str(), RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE) != nullptr) {
      pinned.insert(path);
      ++count;
    }
  }
  return count;
}

}  // namespace procam::output::egl
