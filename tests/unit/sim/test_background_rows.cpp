// The virtual rig's background rendering: every row once, on threads below the
// caller's priority, failures passed back, images the same as OpenCV's pool gives.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "sim/background_rows.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"

namespace procam::sim {
namespace {

// Restores the process-wide switch whatever a test did with it.
struct BackgroundSwitch {
  explicit BackgroundSwitch(bool on) { setBackgroundRendering(on); }
  ~BackgroundSwitch() { setBackgroundRendering(false); }
};

TEST(BackgroundRows, EveryRowOnceOnNicedThreads) {
  const int rows = 1000;
  std::vector<std::atomic<int>> visits(rows);
  std::mutex mutex;
  std::set<pid_t> threads;
  std::vector<int> nice_values;
  const pid_t caller = gettid();
  const int caller_nice = getpriority(PRIO_PROCESS, static_cast<id_t>(caller));
  forEachRowInBackground(rows, [&](int y) {
    visits[static_cast<std::size_t>(y)].fetch_add(1);
    const int nice = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
    std::lock_guard lock(mutex);
    threads.insert(gettid());
    nice_values.push_back(nice);
  });
  for (int y = 0; y < rows; ++y) EXPECT_EQ(visits[static_cast<std::size_t>(y)].load(), 1) << y;
  EXPECT_EQ(threads.count(caller), 0u);  // the caller waits
  EXPECT_LE(threads.size(), std::max(1u, std::thread::hardware_concurrency()));
  ASSERT_EQ(nice_values.size(), static_cast<std::size_t>(rows));
  for (int nice : nice_values) EXPECT_GE(nice, std::max(10, caller_nice));
  // The caller's own priority is left as it was.
  EXPECT_EQ(getpriority(PRIO_PROCESS, static_cast<id_t>(caller)), caller_nice);
}

TEST(BackgroundRows, AFailureStopsTheRowsAndIsRethrown) {
  std::atomic<int> done{0};
  // Each other row takes 10 us: all of them would take half a second on two cores,
  // a failure stops them within the time an exception takes to be caught.
  EXPECT_THROW(forEachRowInBackground(100000,
                                      [&](int y) {
                                        if (y == 10) throw std::runtime_error("row 10");
                                        std::this_thread::sleep_for(std::chrono::microseconds(10));
                                        done.fetch_add(1);
                                      }),
               std::runtime_error);
  EXPECT_LT(done.load(), 100000 - 1);  // the rows after the failure were not all run
  int calls = 0;
  forEachRowInBackground(0, [&](int) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(BackgroundRows, CameraImagesAreTheSameAsOnOpenCvsPool) {
  auto scene = resolveScene("wall_oblique");
  ASSERT_TRUE(scene) << scene.error().message;
  // The projector lights the wall with a ramp, so the rows differ.
  const ProjectorSpec& projector = scene->projectors().front();
  cv::Mat ramp(projector.height, projector.width, CV_8UC3);
  for (int y = 0; y < ramp.rows; ++y)
    ramp.row(y).setTo(cv::Scalar::all(255.0 * y / std::max(1, ramp.rows - 1)));
  auto renderer = Renderer::create(*scene, scene->at(0.0), {{projector.name, ramp}});
  ASSERT_TRUE(renderer) << renderer.error().message;
  const std::string camera = scene->cameras().front().name;
  auto pool = renderer->renderCamera(camera);
  ASSERT_TRUE(pool) << pool.error().message;
  cv::Mat background;
  {
    BackgroundSwitch on(true);
    EXPECT_TRUE(backgroundRendering());
    auto image = renderer->renderCamera(camera);
    ASSERT_TRUE(image) << image.error().message;
    background = *image;
  }
  EXPECT_FALSE(backgroundRendering());
  ASSERT_EQ(background.size(), pool->size());
  ASSERT_EQ(background.type(), pool->type());
  EXPECT_GT(cv::norm(*pool, cv::NORM_INF), 0.0);  // lit
  EXPECT_EQ(cv::norm(background, *pool, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace procam::sim
