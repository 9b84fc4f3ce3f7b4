#pragma once
// Loading driver plugins: shared objects through dlopen, in-tree drivers
// through the static registration table. The ABI version is checked before
// any plugin code runs.
#include <span>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "driver.hpp"
#include "procamd/procam_plugin.h"

namespace procam::plugins {

// Checks a plugin table: ABI version, factory count, every field of every
// factory. `origin` names the plugin in messages.
Result<void> validateTable(const procam_plugin_table* table, const std::string& origin);

// dlopen()s `path`, reads `procam_plugin_abi_version` and refuses a mismatch
// before calling procam_plugin_entry(); returns the plugin's drivers, which
// keep the library loaded.
Result<std::vector<Driver>> loadSharedPlugin(const std::string& path);

// Every *.so in `dir`, in name order. A plugin that fails to load does not
// stop the others; its error is appended to `out_errors`.
std::vector<Driver> loadPluginDirectory(const std::string& dir, std::vector<Error>& out_errors);

// One in-tree driver library linked into the binary.
struct StaticPlugin {
  const char* name;
  procam_plugin_entry_fn entry;
};

// The in-tree drivers built into this binary (generated at configure time
// from the drivers that were found; see plugins/CMakeLists.txt).
std::span<const StaticPlugin> staticPlugins();

// The drivers of a list of static plugins.
Result<std::vector<Driver>> loadStaticPlugins(std::span<const StaticPlugin> plugins);

}  // namespace procam::plugins
