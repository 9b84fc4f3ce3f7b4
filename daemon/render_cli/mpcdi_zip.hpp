#pragma once
// MPCDI packages on disk: a zip archive of mpcdi.xml and its region files (libzip).
#include <filesystem>
#include <vector>

#include "blend/mpcdi.hpp"
#include "core/error.hpp"

namespace procam::render_cli {

// Written beside `file` and renamed over it: a reader never sees half a package.
Result<void> writeMpcdiZip(const std::filesystem::path& file,
                           const std::vector<blend::MpcdiFile>& files);

// Every file of the archive; kTooLarge past 1024 entries or 256 MiB in one entry
// (1 GiB in all), kIo when it is not a zip archive.
Result<std::vector<blend::MpcdiFile>> readMpcdiZip(const std::filesystem::path& file);

}  // namespace procam::render_cli
