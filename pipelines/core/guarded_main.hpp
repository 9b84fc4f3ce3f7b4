#pragma once
// A command-line program's main body run so that nothing escapes it: an
// exception a library throws on a bad input (an iostream failure on a directory,
// bad_alloc on a huge size, a parse error) becomes one line on stderr and exit
// status 1, never an abort with a core dump.
#include <cstdio>
#include <exception>

namespace procam {

template <class Body>
int guardedMain(const char* program, Body&& body) noexcept {
  try {
    return body();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", program, e.what());
  } catch (...) {
    std::fprintf(stderr, "%s: unexpected error\n", program);
  }
  return 1;
}

}  // namespace procam
