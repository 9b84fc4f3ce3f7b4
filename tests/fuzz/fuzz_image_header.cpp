// libFuzzer target: image headers (drivers/content/image_header), read before any
// decoder runs. Any bytes must give a positive size or an error; never a read past
// the end, a crash or a throw.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "content/image_header.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // A copy of exactly `size` bytes: ASan sees any read past the end.
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  auto header = procam::content::readImageHeader(std::string_view(bytes));
  if (header && (header->size.width <= 0 || header->size.height <= 0 || !header->format[0])) {
    std::abort();
  }
  return 0;
}
