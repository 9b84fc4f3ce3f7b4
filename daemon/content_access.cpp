#include "content_access.hpp"

#include <fcntl.h>
#include <sys/stat.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>

#include "protocol.hpp"

namespace procam::daemon {

namespace fs = std::filesystem;

namespace {

std::optional<std::string> realPath(const std::string& path) {
  std::unique_ptr<char, decltype(&std::free)> real(::realpath(path.c_str(), nullptr), &std::free);
  if (!real) return std::nullopt;
  return std::string(real.get());
}

bool within(const std::string& path, const std::string& root) {
  if (root == "/") return true;
  return path == root || (path.size() > root.size() && path.compare(0, root.size(), root) == 0 &&
                          path[root.size()] == '/');
}

std::string rootList(const ContentAccess& access) {
  std::string list;
  for (const auto& r : access.roots) list += (list.empty() ? "" : ", ") + r;
  return list.empty() ? "none configured" : list;
}

}  // namespace

Result<std::string> resolveContentPath(const ContentAccess& access, const std::string& path) {
  if (path.empty() || path.size() > PATH_MAX || path.find('\0') != std::string::npos) {
    return fail(ErrorCode::kInvalidInput, "content path is empty or too long");
  }
  if (access.roots.empty()) {
    return fail(ErrorCode::kForbidden, "no content roots are configured ([content] roots)");
  }
  fs::path candidate(path);
  if (candidate.is_relative()) candidate = fs::path(access.roots.front()) / candidate;
  candidate = candidate.lexically_normal();
  const fs::path name = candidate.filename();
  if (name.empty() || name == "." || name == "..") {
    return fail(ErrorCode::kInvalidInput, "content path '" + path + "' names no file");
  }
  const auto parent = realPath(candidate.parent_path().string());
  if (!parent) {
    return fail(ErrorCode::kIo,
                path + ": " + candidate.parent_path().string() + ": " + std::strerror(errno));
  }
  for (const auto& root : access.roots) {
    const auto real_root = realPath(root);
    if (real_root && within(*parent, *real_root)) return (fs::path(*parent) / name).string();
  }
  return fail(ErrorCode::kForbidden, path + " is outside the content roots (" + rootList(access) +
                                         "): put it there or add its folder to [content] roots");
}

Result<UniqueFd> openContentFile(const ContentAccess& access, const std::string& resolved,
                                 ContentKind kind) {
  const fs::path file(resolved);
  UniqueFd dir(::open(file.parent_path().c_str(), O_PATH | O_DIRECTORY | O_CLOEXEC));
  if (!dir.valid()) return fail(ErrorCode::kIo, resolved + ": " + std::strerror(errno));
  // The folder actually opened, whatever happened to its path meanwhile.
  const auto opened = realPath("/proc/self/fd/" + std::to_string(dir.get()));
  bool inside = false;
  for (const auto& root : access.roots) {
    const auto real_root = realPath(root);
    inside = inside || (opened && real_root && within(*opened, *real_root));
  }
  if (!inside) return fail(ErrorCode::kForbidden, resolved + " is outside the content roots");
  UniqueFd fd(
      ::openat(dir.get(), file.filename().c_str(), O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_CLOEXEC));
  if (!fd.valid()) {
    if (errno == ELOOP) {
      return fail(ErrorCode::kForbidden, resolved + " is a symbolic link (not followed)");
    }
    return fail(ErrorCode::kIo, resolved + ": " + std::strerror(errno));
  }
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0)
    return fail(ErrorCode::kIo, resolved + ": " + std::strerror(errno));
  if (S_ISREG(st.st_mode)) {
    // Regular files never block: plain reads from here on.
    ::fcntl(fd.get(), F_SETFL, ::fcntl(fd.get(), F_GETFL) & ~O_NONBLOCK);
    return fd;
  }
  if (S_ISFIFO(st.st_mode) && kind == ContentKind::kRegularOrFifo) return fd;
  return fail(ErrorCode::kIo,
              resolved + ": not a regular file" +
                  std::string(kind == ContentKind::kRegularOrFifo ? " or FIFO" : ""));
}

Result<std::string> readContentFile(const ContentAccess& access, const std::string& path) {
  auto resolved = resolveContentPath(access, path);
  if (!resolved) return tl::unexpected(resolved.error());
  auto fd = openContentFile(access, *resolved, ContentKind::kRegular);
  if (!fd) return tl::unexpected(fd.error());
  struct stat st {};
  if (::fstat(fd->get(), &st) != 0) return fail(ErrorCode::kIo, path + ": " + std::strerror(errno));
  const std::uint64_t limit = access.limits.file_bytes;
  if (std::uint64_t(st.st_size) > limit) {
    return fail(ErrorCode::kTooLarge, path + ": " + std::to_string(st.st_size) +
                                          " bytes, over the " + std::to_string(limit) +
                                          "-byte limit ([limits] file_mib)");
  }
  std::string bytes;
  bytes.resize(std::size_t(st.st_size));
  std::size_t done = 0;
  // The file may grow meanwhile: what was there at fstat is read, no more.
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd->get(), bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fail(ErrorCode::kIo, path + ": " + std::strerror(errno));
    if (n == 0) break;
    done += std::size_t(n);
  }
  bytes.resize(done);
  return bytes;
}

const char* protoCode(ErrorCode code) {
  switch (code) {
    case ErrorCode::kForbidden:
      return proto::code::kForbidden;
    case ErrorCode::kTooLarge:
      return proto::code::kTooLarge;
    case ErrorCode::kIo:
    case ErrorCode::kNotFound:
    case ErrorCode::kTimeout:
    case ErrorCode::kNoDevice:
      return proto::code::kIo;
    case ErrorCode::kInternal:
      return proto::code::kInternal;
    case ErrorCode::kCancelled:
      return proto::code::kCancelled;
    default:
      return proto::code::kBadArgument;
  }
}

}  // namespace procam::daemon
