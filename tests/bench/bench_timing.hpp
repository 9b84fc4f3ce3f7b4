#pragma once
// Wall-clock timing shared by the benches: `runs` timed calls of a body, each optionally
// preceded by an untimed preparation (publishing a new frame, evicting the caches), and
// the median and fastest of them.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace procam::bench {

struct Timing {
  double median_ms = 0, min_ms = 0;
};

inline Timing measure(int runs, const std::function<void()>& body,
                      const std::function<void()>& untimed_before = {}) {
  std::vector<double> ms;
  for (int i = 0; i < std::max(1, runs); ++i) {
    if (untimed_before) untimed_before();
    const auto t0 = std::chrono::steady_clock::now();
    body();
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  return {ms[ms.size() / 2], ms.front()};
}

// The bodies timed in turn, `runs` rounds of one call each (every call preceded by
// untimed_before): a load that comes and goes on a shared machine falls on all of them
// alike, so their ratios hold better than those of back-to-back measure() calls.
inline std::vector<Timing> measureInterleaved(int runs,
                                              const std::vector<std::function<void()>>& bodies,
                                              const std::function<void()>& untimed_before = {}) {
  std::vector<std::vector<double>> ms(bodies.size());
  for (int i = 0; i < std::max(1, runs); ++i) {
    for (size_t b = 0; b < bodies.size(); ++b) {
      ms[b].push_back(measure(1, bodies[b], untimed_before).median_ms);
    }
  }
  std::vector<Timing> out;
  for (auto& m : ms) {
    std::sort(m.begin(), m.end());
    out.push_back({m[m.size() / 2], m.front()});
  }
  return out;
}

// The options every bench takes, `--out DIR` (made when missing) and `--runs N` (at least
// `min_runs`); false, with the usage on stderr, for anything else.
inline bool benchOptions(int argc, char** argv, const char* name, std::filesystem::path& out,
                         int& runs, int min_runs = 3) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else if (a == "--runs" && i + 1 < argc) {
      runs = std::max(min_runs, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: %s [--out DIR] [--runs N]\n", name);
      return false;
    }
  }
  std::filesystem::create_directories(out);
  return true;
}

}  // namespace procam::bench
