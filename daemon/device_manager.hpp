#pragma once
// The device manager: finds procamd's devices with libudev at start, follows
// hotplug through a udev monitor watched by the event loop, watches device
// fds, and closes devices that fail with PROCAM_ENODEV ("lost") and reopens
// them with back-off. Every method runs on the loop thread; driver create()
// calls for hotplugged and lost devices run on the manager's opener worker,
// tracker reads and camera captures on its reader worker (a tracker read may
// detect blobs and search poses for a hundred milliseconds) and the destroy()
// of devices it closes on its closer worker (releasing a gone camera can wait
// out the library's timeouts), so neither a slow open, a slow read nor a slow
// close blocks the loop. Tilt reads are cheap and stay on the loop.
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "device_set.hpp"
#include "event_loop.hpp"
#include "read_fence.hpp"
#include "registry.hpp"
#include "udev_device.hpp"
#include "worker_pool.hpp"

namespace procam::daemon {

class Udev;
class UdevMonitor;

// A camera frame as the manager reports it: its metadata only. The pixels
// live in the driver's buffer, valid only until the next capture, which the
// reader worker may already be running when the loop sees the frame.
struct CameraFrame {
  uint32_t width = 0;
  uint32_t height = 0;
  procam_pixel_format format{};
  uint64_t timestamp_ns = 0;  // CLOCK_MONOTONIC
};

// A tilt sample and, when the sensor's package has a gyroscope, its reading taken with
// it (read on the same worker, right after the sample).
struct TiltReading {
  procam_tilt_sample sample{};
  std::optional<procam_rate_sample> rate;
};

// What a device produced when read.
using Reading = std::variant<TiltReading, procam_pose_sample, CameraFrame>;

struct DeviceManagerOptions {
  // Enumerate with libudev and follow hotplug (off on the virtual rig, whose
  // devices are the whole rig).
  bool udev = true;
  // Tilt sensors and trackers without a poll fd that nobody polls are read
  // this often, and every camera that delivered no frame in the last half
  // interval is captured (on the reader worker), so that a device gone
  // without a udev event is noticed: a camera's fd may never become readable
  // again once it is gone, and many cameras have none.
  std::chrono::milliseconds presence_interval{1000};
};

class DeviceManager {
 public:
  using DeviceCallback = std::function<void(const DeviceEntry&)>;
  using ReadingCallback = std::function<void(const DeviceEntry&, const Reading&)>;
  using EventSink = std::function<void(const std::string& event, nlohmann::json body)>;
  using WarnSink = std::function<void(const std::string& message)>;

  // `emit` receives the watch events (device-added, device-removed) and
  // `warn` the warnings; both run on the loop thread.
  DeviceManager(EventLoop& loop, const plugins::DriverRegistry& registry, DeviceSet& devices,
                EventSink emit, WarnSink warn);
  DeviceManager(const DeviceManager&) = delete;
  DeviceManager& operator=(const DeviceManager&) = delete;
  ~DeviceManager();

  // Enumerates (synchronously, before the loop runs), starts the monitor and
  // watches the fds of every usable device already in the set. Problems with
  // udev are warnings: the daemon keeps its configured devices.
  void start(const DeviceManagerOptions& options);
  // Re-syncs the watched fds after entries were closed or opened behind the
  // manager (configuration reload).
  void sync();

  // Hooks. Added: a device became usable (discovered, hotplugged, back after
  // being lost). Removed: unplugged (udev) or lost; an operation that uses
  // the device cancels itself here. The entry is still in the set during the
  // callback; a removed one is no longer usable.
  void onDeviceAdded(DeviceCallback callback);
  void onDeviceRemoved(DeviceCallback callback);
  // Every sample or frame the manager reads: on a readable device fd, from
  // pollEvery() and from the presence reads. Always on the loop thread, also
  // for the reads done on the reader worker.
  void onReading(ReadingCallback callback);
  // Devices an operation uses on its own thread (calibrate's cameras) must not
  // be read by the manager meanwhile: while `may_read(name)` is false the
  // device is neither read nor presence-checked, and its fd is left out of
  // the loop (readable, it would wake the loop forever) until the next
  // presence check finds the gate open again.
  void setReadGate(std::function<bool(const std::string& name)> may_read);
  // Call on the loop in the same turn as the gate closes for `names` (no read
  // can start in between); wait on the fence on the operation's worker before
  // its first call on those devices: a read running on the reader worker
  // finishes first, one still queued is dropped (read_fence.hpp).
  ReadFence readFence(const std::vector<std::string>& names);

  // Reads a tilt sensor at once, or starts a tracker read or camera capture
  // (timeout 0) on the reader worker, at most one per device at a time; the
  // reading reaches the onReading hooks on the loop. False when no read was
  // done or started (gate closed, not usable, one in flight, read failed).
  bool read(const std::string& name);
  // Reads a device by timer (for devices whose poll fd is -1); returns an id
  // for stopPolling().
  Result<int> pollEvery(const std::string& name, std::chrono::nanoseconds interval);
  void stopPolling(int id);
  // For users that call a device's operations themselves: PROCAM_ENODEV
  // marks the device lost (closed, device-removed, reopened with back-off),
  // PROCAM_EEND ended (closed, device-removed, not reopened).
  void report(const std::string& name, int rc, const std::string& reason);

  // One udev event ("add"/"remove"; others are ignored). The monitor feeds
  // it; tests call it directly.
  void handleUdevEvent(const UdevRecord& record);
  bool monitoring() const { return monitor_ != nullptr; }
  // The wait before reopen attempt `attempt` (0-based): 1, 2, 4, 8, then 10 s.
  static std::chrono::seconds retryDelay(int attempt);

 private:
  void enumerate();
  void openDiscovered(plugins::DeviceDescription desc, bool async);
  void addDiscovered(DeviceEntry entry);
  void removeUnplugged(const std::string& name);
  void markLost(const std::string& name, const std::string& reason);
  void markEnded(const std::string& name, const std::string& reason);
  void scheduleRetry(const std::string& name);
  void retry(const std::string& name, uint64_t token);
  void finishRetry(const std::string& name, uint64_t token, DeviceEntry fresh);
  void cancelRetry(const std::string& name);
  void watchFd(const DeviceEntry& entry);
  void unwatchFd(const std::string& name);
  bool readEntry(const std::string& name);
  struct ReadResult {
    int rc = PROCAM_ENOTSUP;
    std::string reason;  // the driver's message when rc is not PROCAM_OK
    Reading reading;
    bool withdrawn = false;  // fenced before it started: nothing was read
  };
  // One driver call; on the loop for tilt sensors, on the reader worker otherwise.
  static ReadResult readOnce(const procam_device& raw, procam_family family);
  // A camera's liveness check (procam_camera_ops::check) on the reader worker.
  static ReadResult checkOnce(const procam_device& raw);
  void startRead(DeviceEntry& entry, bool check_only = false);
  // The presence check of a camera without recent frames: its driver's check
  // when it has one, else a capture.
  void checkCamera(const std::string& name);
  void finishRead(const std::string& name, const std::shared_ptr<ReadTicket>& ticket,
                  const std::shared_ptr<plugins::Device>& device, const ReadResult& result);
  bool deliver(const std::string& name, const ReadResult& result);
  bool gateOpen(const std::string& name) const { return !may_read_ || may_read_(name); }
  // Cameras due for a liveness capture: usable, not being read, gate open, no
  // frame delivered within the last half presence interval.
  std::vector<std::string> silentCameras() const;
  void presenceCheck();
  // Hands a reference to a closed device to the closer worker, so that the
  // driver's destroy() runs there when it is the last one, not on the loop.
  void retire(std::shared_ptr<plugins::Device> device);
  void added(const std::string& name);
  void removed(const std::string& name);
  // Posts `fn` to the loop unless the manager was destroyed meanwhile.
  std::function<void()> guarded(std::function<void()> fn) const;

  EventLoop& loop_;
  const plugins::DriverRegistry& registry_;
  DeviceSet& devices_;
  EventSink emit_;
  WarnSink warn_;
  std::vector<DeviceCallback> on_added_, on_removed_;
  std::vector<ReadingCallback> on_reading_;
  std::function<bool(const std::string&)> may_read_;

  std::unique_ptr<Udev> udev_;
  std::unique_ptr<UdevMonitor> monitor_;
  std::map<std::string, int> watched_;  // device name -> its poll fd in the loop
  std::map<int, std::string> polls_;    // pollEvery timer id -> device name
  std::set<std::string> gated_;         // fds taken out of the loop by the read gate
  std::set<std::string> pending_;       // syspaths being opened on the worker
  // Devices with a read on the reader worker: their fds are out of the loop
  // (level-triggered, a readable fd would wake it over and over) until the
  // result is back.
  std::map<std::string, std::shared_ptr<ReadTicket>> reading_;
  struct Retry {
    uint64_t token = 0;
    int timer = -1;  // -1 while the attempt runs on the worker
  };
  std::map<std::string, Retry> retries_;
  uint64_t next_token_ = 1;
  int presence_timer_ = -1;
  std::chrono::milliseconds presence_interval_{1000};
  // When each camera last delivered a frame (on the loop's clock).
  std::map<std::string, std::chrono::steady_clock::time_point> last_frame_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
  std::unique_ptr<WorkerPool> opener_;  // joined first on destruction
  // One thread: reads of different devices queue behind each other, which
  // costs at most one slow read of latency on two cores and keeps every
  // driver single-threaded.
  std::unique_ptr<WorkerPool> reader_;
  // One thread for destroy(): a camera released after it died may block for
  // seconds, which must hold up neither the loop nor the reads of the others.
  std::unique_ptr<WorkerPool> closer_;
};

}  // namespace procam::daemon
