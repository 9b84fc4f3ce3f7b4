#pragma once
// Typed errors returned by every pipeline: a code a caller can branch on and a
// message a user can read. Pipelines never throw across their API.
#include <string>
#include <tl/expected.hpp>
#include <utility>

namespace procam {

enum class ErrorCode {
  kInvalidInput,    // malformed argument: wrong sizes, NaN/Inf, negative counts
  kTooFewPoints,    // fewer correspondences than the model needs
  kDegenerate,      // configuration admits no unique solution (collinear, duplicates)
  kCoplanar,        // 3D points (near) coplanar: projection matrix undetermined
                    // ([Raskar02] §4.1.1)
  kIllConditioned,  // system too badly conditioned to trust the result
  kNoConvergence,   // iterative solver did not reach its tolerance
  kNotFound,        // requested item absent (no intersection, unknown name)
  kParse,           // text input could not be parsed (scene files, JSON)
  // Used only outside pipelines (tools, drivers, the daemon). The device outcomes after
  // kIo are each one status of the plugin ABI (plugins/support: statusOf, codeOf).
  kIo,            // the device or file reported an error (PROCAM_EIO)
  kNoDevice,      // the device is gone or not present (PROCAM_ENODEV)
  kTimeout,       // nothing arrived within the time asked for (PROCAM_ETIMEDOUT)
  kAgain,         // nothing new yet: poll the device again (PROCAM_EAGAIN)
  kNotSupported,  // the device or driver has no such operation or control (PROCAM_ENOTSUP)
  kEnded,         // the stream ended for good, e.g. a finished recording (PROCAM_EEND)
  kInternal,      // a driver failed where it did not expect to (PROCAM_EINTERNAL)
  kTooLarge,      // an input over a configured bound (pixels, faces, bytes, queued work)
  kForbidden,     // outside what the caller may reach (a file outside the content roots)
  kCancelled,     // the caller asked the work to stop (PROCAM_ECANCELED)
};

const char* toString(ErrorCode code);

struct Error {
  ErrorCode code;
  std::string message;
};

template <class T>
using Result = tl::expected<T, Error>;

inline tl::unexpected<Error> fail(ErrorCode code, std::string message) {
  return tl::unexpected<Error>(Error{code, std::move(message)});
}

}  // namespace procam
