// Content sources bench: what a shared-memory frame costs procamd at 1920x1080
// RGBA8 — the seqlock copy out of the memfd (ShmFrameReader::copyNewest), the
// whole source read (into a pooled frame buffer), and the producer's publish —
// against a plain memcpy of the same bytes (the bandwidth floor). Medians of N
// runs; writes content.csv to --out DIR.
//
//   bench_content [--out DIR] [--frames N]
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bench_timing.hpp"
#include "content/shm_frames.hpp"

using namespace procam::content;
using procam::bench::measure;

int main(int argc, char** argv) {
  std::string out = ".";
  int frames = 200;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::string(argv[i]) == "--out") out = argv[i + 1];
    if (std::string(argv[i]) == "--frames") frames = std::max(5, std::atoi(argv[i + 1]));
  }
  const cv::Size size(1920, 1080);
  const size_t bytes = shmFrameBytes(size, PixelFormat::kRgba8);
  auto producer = ShmFrameProducer::create(size, PixelFormat::kRgba8);
  if (!producer) {
    std::fprintf(stderr, "%s\n", producer.error().message.c_str());
    return 1;
  }
  std::vector<uint8_t> src(bytes, 7), dst(bytes);
  producer->publish(src.data());
  ShmFrameReader reader(producer->memory(), size, PixelFormat::kRgba8);
  auto source = openSharedFrames(::dup(producer->fd()), size, PixelFormat::kRgba8);
  if (!source) {
    std::fprintf(stderr, "%s\n", source.error().message.c_str());
    return 1;
  }
  cv::Mat copy;
  Frame frame;
  // Warm every page once.
  std::memcpy(dst.data(), src.data(), bytes);
  reader.copyNewest(copy);

  const double memcpy_ms =
      measure(frames, [&] { std::memcpy(dst.data(), src.data(), bytes); }).median_ms;
  const double copy_ms = measure(frames, [&] { reader.copyNewest(copy); }).median_ms;
  // A new frame before each read; only the read is timed. The previous frame is
  // released before the read, as procamd does once it is shown.
  auto next_frame = [&] {
    producer->publish(src.data());
    frame = Frame{};
  };
  auto read_one = [&] { (void)(*source)->read(frame); };
  const double read_only_ms = measure(frames, read_one, next_frame).median_ms;
  const double publish_ms = measure(frames, [&] { producer->publish(src.data()); }).median_ms;

  std::printf("1920x1080 RGBA8 (%.1f MB), median of %d\n", bytes / 1e6, frames);
  std::printf("  memcpy                 %7.3f ms  (%.2f GB/s)\n", memcpy_ms,
              bytes / memcpy_ms / 1e6);
  std::printf("  shm copyNewest         %7.3f ms  (%.2fx memcpy)\n", copy_ms, copy_ms / memcpy_ms);
  std::printf("  source read            %7.3f ms  (%.2fx memcpy)\n", read_only_ms,
              read_only_ms / memcpy_ms);
  std::printf("  producer publish       %7.3f ms  (%.2fx memcpy)\n", publish_ms,
              publish_ms / memcpy_ms);
  std::filesystem::create_directories(out);
  std::ofstream csv(out + "/content.csv");
  csv << "what,ms,ratio_to_memcpy\n"
      << "memcpy," << memcpy_ms << ",1\n"
      << "shm_copy_newest," << copy_ms << "," << copy_ms / memcpy_ms << "\n"
      << "shm_source_read," << read_only_ms << "," << read_only_ms / memcpy_ms << "\n"
      << "shm_publish," << publish_ms << "," << publish_ms / memcpy_ms << "\n";
  return 0;
}
