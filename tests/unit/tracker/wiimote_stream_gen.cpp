// Writes the Wii Remote test stream (wiimote_stream.hpp) to the file given, normally
// tests/unit/tracker/data/wiimote_ir_stream.csv.
#include <fstream>
#include <iostream>

#include "unit/tracker/wiimote_stream.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: wiimote_stream_gen <out.csv>\n";
    return 2;
  }
  std::ofstream out(argv[1]);
  procam::tracker::wiimote::testing::write(out, procam::tracker::wiimote::testing::generate());
  return out ? 0 : 1;
}
