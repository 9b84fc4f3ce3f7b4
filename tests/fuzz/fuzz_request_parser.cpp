// libFuzzer target: the control protocol's framing and request parser. Any
// byte stream must frame into lines without exceeding the limit and parse
// into a request or a failure carrying a code, never crash or throw.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "protocol.hpp"

using namespace procam::daemon::proto;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  // A small limit exercises the oversized path with small inputs.
  LineFramer framer(size % 2 ? 64 : kMaxRequestBytes);
  const size_t half = size / 2;
  framer.feed(bytes.substr(0, half));
  framer.feed(bytes.substr(half));
  LineFramer::Item item;
  while (framer.next(item)) {
    if (item.oversized) continue;
    auto req = parseRequest(item.line);
    if (req) {
      if (req->cmd.empty()) std::abort();
      if (!(req->id.is_null() || req->id.is_string() || req->id.is_number_integer())) std::abort();
      (void)reply("STATUS", req->id, req->body);
    } else {
      if (req.error().code.empty()) std::abort();
      (void)error(req.error().id, req.error().code, req.error().message);
    }
  }
  if (framer.buffered() > kMaxRequestBytes + 1) std::abort();
  return 0;
}
