#include "replace_file.hpp"

#include <unistd.h>

#include <fstream>

namespace procam::render_cli {

namespace fs = std::filesystem;

Result<void> replaceFile(const fs::path& file,
                         const std::function<Result<void>(const fs::path&)>& write) {
  const fs::path tmp = file.string() + ".tmp-" + std::to_string(::getpid());
  std::error_code ec;
  if (auto ok = write(tmp); !ok) {
    fs::remove(tmp, ec);
    return ok;
  }
  fs::rename(tmp, file, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return fail(ErrorCode::kIo, "cannot rename onto " + file.string() + ": " + ec.message());
  }
  return {};
}

Result<void> replaceFileWith(const fs::path& file, std::string_view bytes) {
  return replaceFile(file, [&](const fs::path& tmp) -> Result<void> {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return fail(ErrorCode::kIo, "cannot write " + tmp.string());
    out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out.flush()) return fail(ErrorCode::kIo, "error writing " + tmp.string());
    return {};
  });
}

}  // namespace procam::render_cli
