#pragma once
// Output files of procam-render replaced whole: each is written beside its target under
// a temporary name and renamed over it, so a reader never sees half a file and a failed
// run leaves the previous file as it was.
#include <filesystem>
#include <functional>
#include <string_view>

#include "core/error.hpp"

namespace procam::render_cli {

// Calls `write` with the temporary path; renames it onto `file` when it succeeds and
// removes it otherwise.
Result<void> replaceFile(const std::filesystem::path& file,
                         const std::function<Result<void>(const std::filesystem::path&)>& write);

// replaceFile with `bytes` as the contents.
Result<void> replaceFileWith(const std::filesystem::path& file, std::string_view bytes);

}  // namespace procam::render_cli
