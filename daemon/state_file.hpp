#pragma once
// One file of the state directory, written atomically: the new contents go to
// a temporary file that is fsync()ed and renamed over the old one, then the
// directory is fsync()ed. The previous valid version is kept as NAME.bak; a
// corrupt file is reported and the backup used instead.
#include <functional>
#include <string>
#include <string_view>

#include "core/error.hpp"

namespace procam::daemon {

class StateFile {
 public:
  using Validator = std::function<Result<void>(std::string_view contents)>;

  // Without a validator (nullptr) every file is valid and no backup is kept: for
  // files that are only ever replaced (camera snapshots).
  StateFile(std::string dir, std::string name, Validator validate);

  const std::string& path() const { return path_; }
  std::string backupPath() const { return path_ + ".bak"; }

  // Creates the directory (mode 0750) when missing.
  Result<void> ensureDirectory() const;

  // Atomically replaces the file. The current version becomes the backup
  // only if it is valid, so a corrupt file never overwrites a good backup.
  Result<void> write(std::string_view contents) const;

  struct Loaded {
    std::string contents;
    bool from_backup = false;
    std::string warning;  // why the main file was not used, when from_backup
  };
  // kNotFound when neither the file nor a backup exists; kParse when both are
  // corrupt (the message names both problems).
  Result<Loaded> read() const;

 private:
  std::string dir_;
  std::string path_;
  Validator validate_;
};

// Reads a whole file; kNotFound when it does not exist.
Result<std::string> readWholeFile(const std::string& path);

}  // namespace procam::daemon
