#pragma once
// Where clients may take content from, and how much: the files of `content
// load`/`stream` lie under configured roots ([content] roots, default the state
// directory's content/), are opened without following a final symlink and
// without blocking, and must be of the kind asked for; every size a client
// controls has a bound ([limits]). Refusals are typed: kForbidden (outside the
// roots, not allowed), kTooLarge (over a limit), kIo (cannot be read).
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/unique_fd.hpp"

namespace procam::daemon {

// [limits] of procamd.toml.
struct ContentLimits {
  std::uint64_t file_bytes = std::uint64_t{256} << 20;  // an image or mesh file
  std::uint64_t image_pixels = std::uint64_t{1} << 25;  // 32 Mpx: 8192 x 4096
  std::uint64_t frame_pixels = std::uint64_t{1} << 25;  // a streamed or shared frame
  std::uint64_t mesh_vertices = 2'000'000;
  std::uint64_t mesh_faces = 2'000'000;  // triangles
  std::uint64_t face_indices = 64;       // vertices of one polygon
  std::uint64_t client_jobs = 64;        // one client's queued worker jobs
};

struct ContentAccess {
  std::vector<std::string> roots;  // absolute; the first takes relative paths
  ContentLimits limits;
  bool allow_pipeline = false;  // raw gst-launch text from clients (trusted set-ups only)
};

// The path a client gave, made absolute (a relative one lies under the first
// root) and checked to lie under a root once its directories' symlinks are
// resolved; the final component stays as given (it is opened with O_NOFOLLOW).
Result<std::string> resolveContentPath(const ContentAccess& access, const std::string& path);

enum class ContentKind { kRegular, kRegularOrFifo };

// Opens a resolved path for reading: its folder is opened and checked again to
// lie under a root (a folder swapped for a symlink since it was resolved is
// caught), the file opened in it O_NONBLOCK|O_NOFOLLOW, and its type checked on
// the descriptor (a FIFO only when allowed, never a device or directory). A
// regular file's descriptor is left blocking; a FIFO's stays non-blocking.
Result<UniqueFd> openContentFile(const ContentAccess& access, const std::string& resolved,
                                 ContentKind kind);

// A regular file's bytes, at most access.limits.file_bytes of them.
Result<std::string> readContentFile(const ContentAccess& access, const std::string& path);

// The protocol's error code (PROTOCOL.md) for a refusal of content: forbidden,
// too-large, io-error; bad-argument for what the file or request got wrong.
const char* protoCode(ErrorCode code);

}  // namespace procam::daemon
