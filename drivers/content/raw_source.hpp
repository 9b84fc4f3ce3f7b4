#pragma once
// Raw frames, back to back with no header, from a regular file or a FIFO:
// width x height pixels in the given format, rows packed. A FIFO is read without
// blocking (pollFd() is readable when bytes arrive); the writer closing it ends the
// stream. A file ends at its last whole frame; bytes of a partial frame at the end
// of either are an error.
#include <memory>
#include <string>

#include "content_source.hpp"
#include "core/unique_fd.hpp"

namespace procam::content {

struct RawFormat {
  cv::Size size;
  PixelFormat format = PixelFormat::kRgba8;
  // Pacing for a regular file (0: as fast as it is read); a FIFO is paced by its writer.
  double fps = 0;
};

// kInvalidInput for sizes under 2x2 or a negative fps, kIo when the path cannot be
// opened or is neither a regular file nor a FIFO.
Result<std::unique_ptr<ContentSource>> openRawFrames(const std::string& path,
                                                     const RawFormat& format);
// The same from a descriptor already open for reading (`name` for messages).
Result<std::unique_ptr<ContentSource>> openRawFrames(UniqueFd fd, const std::string& name,
                                                     const RawFormat& format);

}  // namespace procam::content
