#include "core/error.hpp"

namespace procam {

const char* toString(ErrorCode code) {
  switch (code) {
    case ErrorCode::kInvalidInput:
      return "invalid-input";
    case ErrorCode::kTooFewPoints:
      return "too-few-points";
    case ErrorCode::kDegenerate:
      return "degenerate";
    case ErrorCode::kCoplanar:
      return "coplanar";
    case ErrorCode::kIllConditioned:
      return "ill-conditioned";
    case ErrorCode::kNoConvergence:
      return "no-convergence";
    case ErrorCode::kNotFound:
      return "not-found";
    case ErrorCode::kParse:
      return "parse";
    case ErrorCode::kIo:
      return "io";
    case ErrorCode::kNoDevice:
      return "no-device";
    case ErrorCode::kTimeout:
      return "timeout";
    case ErrorCode::kAgain:
      return "again";
    case ErrorCode::kNotSupported:
      return "not-supported";
    case ErrorCode::kEnded:
      return "ended";
    case ErrorCode::kInternal:
      return "internal";
    case ErrorCode::kTooLarge:
      return "too-large";
    case ErrorCode::kForbidden:
      return "forbidden";
    case ErrorCode::kCancelled:
      return "cancelled";
  }
  return "unknown";
}

}  // namespace procam
