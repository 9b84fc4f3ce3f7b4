#pragma once
// A fake IIO device tree in a temporary directory (the kernel's file names), removed
// on destruction.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace procam::tilt::testing {

namespace fs = std::filesystem;

class FakeIioTree {
 public:
  FakeIioTree() {
    root_ = fs::temp_directory_path() /
            ("procam-iio-" + std::to_string(::getpid()) + "-" + std::to_string(counter_++));
    fs::create_directories(root_ / "iio:device0");
  }
  ~FakeIioTree() { fs::remove_all(root_); }
  fs::path root() const { return root_; }  // the sysfs_root of iio:device0
  fs::path dir() const { return root_ / "iio:device0"; }
  void set(const std::string& rel, const std::string& value) {
    fs::create_directories((dir() / rel).parent_path());
    std::ofstream(dir() / rel) << value << "\n";
  }
  std::string get(const std::string& rel) {
    std::string s;
    std::getline(std::ifstream(dir() / rel), s);
    return s;
  }

 private:
  fs::path root_;
  static inline int counter_ = 0;
};

}  // namespace procam::tilt::testing
