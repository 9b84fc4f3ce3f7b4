#include "state_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace procam::daemon {

namespace {

class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }
  int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

tl::unexpected<Error> ioError(const std::string& what, const std::string& path) {
  return fail(ErrorCode::kIo, what + " " + path + ": " + std::strerror(errno));
}

Result<void> writeAll(int fd, std::string_view data, const std::string& path) {
  while (!data.empty()) {
    const ssize_t n = ::write(fd, data.data(), data.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return ioError("cannot write", path);
    }
    data.remove_prefix(static_cast<size_t>(n));
  }
  return {};
}

Result<void> fsyncDirectory(const std::string& dir) {
  Fd fd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (fd.get() < 0) return ioError("cannot open directory", dir);
  if (::fsync(fd.get()) != 0) return ioError("cannot fsync directory", dir);
  return {};
}

}  // namespace

Result<std::string> readWholeFile(const std::string& path) {
  Fd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) {
    if (errno == ENOENT) return fail(ErrorCode::kNotFound, path + " does not exist");
    return ioError("cannot open", path);
  }
  std::string out;
  char buf[16384];
  for (;;) {
    const ssize_t n = ::read(fd.get(), buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      return ioError("cannot read", path);
    }
    if (n == 0) break;
    out.append(buf, static_cast<size_t>(n));
  }
  return out;
}

StateFile::StateFile(std::string dir, std::string name, Validator validate)
    : dir_(std::move(dir)), path_(dir_ + "/" + name), validate_(std::move(validate)) {}

Result<void> StateFile::ensureDirectory() const {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec)
    return fail(ErrorCode::kIo, "cannot create state directory " + dir_ + ": " + ec.message());
  return {};
}

Result<void> StateFile::write(std::string_view contents) const {
  const std::string tmp = path_ + ".tmp";
  {
    Fd fd(::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0640));
    if (fd.get() < 0) return ioError("cannot create", tmp);
    if (auto ok = writeAll(fd.get(), contents, tmp); !ok) return ok;
    if (::fsync(fd.get()) != 0) return ioError("cannot fsync", tmp);
    if (::close(fd.release()) != 0) return ioError("cannot close", tmp);
  }
  // Keep the current version as the backup (through a hard link, so that the
  // main file exists at every instant), unless it is corrupt.
  if (validate_) {
    if (auto current = readWholeFile(path_); current && validate_(*current)) {
      const std::string bak_tmp = backupPath() + ".tmp";
      ::unlink(bak_tmp.c_str());
      if (::link(path_.c_str(), bak_tmp.c_str()) != 0) return ioError("cannot link", bak_tmp);
      if (::rename(bak_tmp.c_str(), backupPath().c_str()) != 0) {
        return ioError("cannot rename to", backupPath());
      }
    }
  }
  if (::rename(tmp.c_str(), path_.c_str()) != 0) return ioError("cannot rename to", path_);
  return fsyncDirectory(dir_);
}

Result<StateFile::Loaded> StateFile::read() const {
  std::string problem;
  auto main = readWholeFile(path_);
  if (main) {
    auto ok = validate_ ? validate_(*main) : Result<void>{};
    if (ok) return Loaded{std::move(*main), false, {}};
    problem = path_ + " is corrupt: " + ok.error().message;
  } else if (main.error().code != ErrorCode::kNotFound) {
    problem = main.error().message;
  }
  auto backup = readWholeFile(backupPath());
  if (!backup) {
    if (problem.empty()) return tl::unexpected(main.error());  // nothing was ever saved
    if (backup.error().code == ErrorCode::kNotFound) {
      return fail(ErrorCode::kParse, problem + "; no backup " + backupPath());
    }
    return fail(ErrorCode::kParse, problem + "; " + backup.error().message);
  }
  if (auto ok = validate_ ? validate_(*backup) : Result<void>{}; !ok) {
    if (problem.empty()) problem = path_ + " is missing";
    return fail(ErrorCode::kParse,
                problem + "; backup " + backupPath() + " is corrupt too: " + ok.error().message);
  }
  if (problem.empty()) problem = path_ + " is missing";
  return Loaded{std::move(*backup), true, problem + "; using backup " + backupPath()};
}

}  // namespace procam::daemon
