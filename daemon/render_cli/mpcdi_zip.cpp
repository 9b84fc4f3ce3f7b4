#include "mpcdi_zip.hpp"

#include <zip.h>

#include <memory>

#include "replace_file.hpp"

namespace procam::render_cli {

namespace fs = std::filesystem;

namespace {

constexpr zip_int64_t kMaxEntries = 1024;
constexpr zip_uint64_t kMaxEntryBytes = zip_uint64_t{256} << 20;
constexpr zip_uint64_t kMaxTotalBytes = zip_uint64_t{1} << 30;

struct ArchiveDiscard {
  void operator()(zip_t* z) const { zip_discard(z); }
};
using Archive = std::unique_ptr<zip_t, ArchiveDiscard>;
struct EntryClose {
  void operator()(zip_file_t* f) const { zip_fclose(f); }
};
using Entry = std::unique_ptr<zip_file_t, EntryClose>;

std::string zipError(int code) {
  zip_error_t e;
  zip_error_init_with_code(&e, code);
  std::string text = zip_error_strerror(&e);
  zip_error_fini(&e);
  return text;
}

}  // namespace

Result<void> writeMpcdiZip(const fs::path& file, const std::vector<blend::MpcdiFile>& files) {
  return replaceFile(file, [&](const fs::path& tmp) -> Result<void> {
    int code = 0;
    Archive z(zip_open(tmp.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &code));
    if (!z) return fail(ErrorCode::kIo, "cannot create " + tmp.string() + ": " + zipError(code));
    for (const auto& f : files) {
      // The bytes stay with `files` until zip_close has written them.
      zip_source_t* src = zip_source_buffer(z.get(), f.bytes.data(), f.bytes.size(), 0);
      const zip_int64_t index =
          src ? zip_file_add(z.get(), f.name.c_str(), src, ZIP_FL_ENC_UTF_8) : -1;
      if (index < 0) {
        if (src) zip_source_free(src);
        return fail(ErrorCode::kIo, "cannot add " + f.name + ": " + zip_strerror(z.get()));
      }
      // Stored, not deflated: PNGs are compressed already, and deflating four 1280x800
      // float warps took 14 s on this project's 2-core machine to halve them (0.6 s stored).
      if (!f.name.ends_with(".xml") &&
          zip_set_file_compression(z.get(), zip_uint64_t(index), ZIP_CM_STORE, 0) != 0) {
        return fail(ErrorCode::kIo, "cannot store " + f.name + ": " + zip_strerror(z.get()));
      }
    }
    if (zip_close(z.get()) != 0) {
      return fail(ErrorCode::kIo, "cannot write " + tmp.string() + ": " + zip_strerror(z.get()));
    }
    (void)z.release();  // closed
    return {};
  });
}

Result<std::vector<blend::MpcdiFile>> readMpcdiZip(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    return fail(ErrorCode::kIo, "cannot read " + file.string() + ": not a regular file");
  int code = 0;
  Archive z(zip_open(file.c_str(), ZIP_RDONLY, &code));
  if (!z) return fail(ErrorCode::kIo, file.string() + ": " + zipError(code));
  const zip_int64_t n = zip_get_num_entries(z.get(), 0);
  if (n < 0 || n > kMaxEntries)
    return fail(ErrorCode::kTooLarge, file.string() + ": more than 1024 entries");
  std::vector<blend::MpcdiFile> out;
  zip_uint64_t total = 0;
  for (zip_int64_t i = 0; i < n; ++i) {
    zip_stat_t st;
    if (zip_stat_index(z.get(), zip_uint64_t(i), 0, &st) != 0 || !(st.valid & ZIP_STAT_SIZE) ||
        !(st.valid & ZIP_STAT_NAME))
      return fail(ErrorCode::kIo, file.string() + ": unreadable entry");
    total += st.size;
    if (st.size > kMaxEntryBytes || total > kMaxTotalBytes)
      return fail(ErrorCode::kTooLarge, file.string() + ": entry " + st.name + " too large");
    Entry f(zip_fopen_index(z.get(), zip_uint64_t(i), 0));
    if (!f) return fail(ErrorCode::kIo, file.string() + ": cannot open " + st.name);
    blend::MpcdiFile entry{st.name, std::string(st.size, '\0')};
    if (zip_fread(f.get(), entry.bytes.data(), st.size) != zip_int64_t(st.size))
      return fail(ErrorCode::kIo, file.string() + ": cannot read " + st.name);
    out.push_back(std::move(entry));
  }
  return out;
}

}  // namespace procam::render_cli
