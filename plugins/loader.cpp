#include "loader.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <filesystem>
#include <memory>

namespace procam::plugins {

namespace {

std::string abiMismatch(const std::string& origin, uint32_t found) {
  return "plugin " + origin + " was built for driver ABI version " + std::to_string(found) +
         ", this procamd implements ABI version " + std::to_string(PROCAM_PLUGIN_ABI_VERSION) +
         "; rebuild the plugin against the matching procam_plugin.h (pkg-config procamd-plugin)";
}

struct DlCloser {
  void operator()(void* handle) const {
    if (handle) dlclose(handle);
  }
};

}  // namespace

Result<void> validateTable(const procam_plugin_table* table, const std::string& origin) {
  if (!table) return fail(ErrorCode::kInvalidInput, "plugin " + origin + " returned no table");
  if (table->abi_version != PROCAM_PLUGIN_ABI_VERSION) {
    return fail(ErrorCode::kInvalidInput, abiMismatch(origin, table->abi_version));
  }
  if (table->n_factories == 0 || !table->factories) {
    return fail(ErrorCode::kInvalidInput, "plugin " + origin + " declares no driver factories");
  }
  for (size_t i = 0; i < table->n_factories; ++i) {
    const procam_driver_factory& f = table->factories[i];
    const std::string where = "plugin " + origin + ", factory #" + std::to_string(i);
    if (!f.name || !*f.name) return fail(ErrorCode::kInvalidInput, where + " has no name");
    if (!isKnownFamily(rawFamily(f.family))) {
      return fail(ErrorCode::kInvalidInput, where + " ('" + f.name + "') has an unknown family " +
                                                std::to_string(rawFamily(f.family)));
    }
    if (!f.probe || !f.create) {
      return fail(ErrorCode::kInvalidInput,
                  where + " ('" + f.name + "') lacks probe() or create()");
    }
  }
  return {};
}

Result<std::vector<Driver>> loadSharedPlugin(const std::string& path) {
  dlerror();
  std::shared_ptr<void> handle(dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL), DlCloser{});
  if (!handle) {
    const char* why = dlerror();
    return fail(ErrorCode::kIo,
                "cannot load plugin " + path + ": " + (why ? why : "dlopen failed"));
  }
  // The version is plain data: reading it runs no plugin code.
  const auto* abi = static_cast<const uint32_t*>(dlsym(handle.get(), PROCAM_PLUGIN_ABI_SYMBOL));
  if (!abi) {
    return fail(ErrorCode::kInvalidInput,
                path + " is not a procamd plugin: no symbol " PROCAM_PLUGIN_ABI_SYMBOL);
  }
  if (*abi != PROCAM_PLUGIN_ABI_VERSION) {
    return fail(ErrorCode::kInvalidInput, abiMismatch(path, *abi));
  }
  auto entry =
      reinterpret_cast<procam_plugin_entry_fn>(dlsym(handle.get(), PROCAM_PLUGIN_ENTRY_SYMBOL));
  if (!entry) {
    return fail(ErrorCode::kInvalidInput,
                path + " is not a procamd plugin: no symbol " PROCAM_PLUGIN_ENTRY_SYMBOL);
  }
  const procam_plugin_table* table = entry();
  if (auto ok = validateTable(table, path); !ok) return tl::unexpected(ok.error());
  std::vector<Driver> drivers;
  for (size_t i = 0; i < table->n_factories; ++i) {
    drivers.push_back(Driver{&table->factories[i], path, handle});
  }
  return drivers;
}

std::vector<Driver> loadPluginDirectory(const std::string& dir, std::vector<Error>& out_errors) {
  std::vector<Driver> drivers;
  std::error_code ec;
  std::vector<std::filesystem::path> paths;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".so") paths.push_back(entry.path());
  }
  if (ec && ec != std::errc::no_such_file_or_directory) {
    out_errors.push_back(
        {ErrorCode::kIo, "cannot list plugin directory " + dir + ": " + ec.message()});
  }
  std::sort(paths.begin(), paths.end());
  for (const auto& p : paths) {
    auto loaded = loadSharedPlugin(p.string());
    if (!loaded) {
      out_errors.push_back(loaded.error());
      continue;
    }
    drivers.insert(drivers.end(), loaded->begin(), loaded->end());
  }
  return drivers;
}

Result<std::vector<Driver>> loadStaticPlugins(std::span<const StaticPlugin> plugins) {
  std::vector<Driver> drivers;
  for (const StaticPlugin& p : plugins) {
    const std::string origin = std::string("static:") + p.name;
    const procam_plugin_table* table = p.entry();
    if (auto ok = validateTable(table, origin); !ok) return tl::unexpected(ok.error());
    for (size_t i = 0; i < table->n_factories; ++i) {
      drivers.push_back(Driver{&table->factories[i], origin, nullptr});
    }
  }
  return drivers;
}

}  // namespace procam::plugins
