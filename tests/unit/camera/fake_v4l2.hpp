#pragma once
// A simulated V4L2 capture device behind V4l2Io: the formats and sizes it offers, the
// controls it has, and the kernel's buffer state machine (REQBUFS/QUERYBUF/mmap/QBUF/
// STREAMON/DQBUF). It refuses what the kernel refuses (a buffer queued twice, DQBUF while
// not streaming, REQBUFS while streaming) so that a driver bug shows as an error, and it
// can vanish (every call then fails with ENODEV, as after an unplug).
#include <linux/videodev2.h>
#include <poll.h>

#include <cerrno>
#include <cstring>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "camera/v4l2/v4l2_io.hpp"

namespace procam::camera::testing {

struct FakeV4l2State {
  struct Format {
    uint32_t fourcc;
    std::vector<std::pair<uint32_t, uint32_t>> sizes;
  };
  std::vector<Format> formats;
  uint32_t max_buffers = 8;  // REQBUFS grants at most this many
  uint32_t padding = 0;      // bytes added to each row (bytesperline > width * bpp)
  bool timeperframe = true;
  std::string fail_device;  // open() of this path fails with ENOENT
  std::map<uint32_t, v4l2_queryctrl> controls;
  std::map<uint32_t, int32_t> values;

  // Runtime state.
  bool open = false, vanished = false, streaming = false;
  v4l2_pix_format fmt{};
  std::vector<std::vector<uint8_t>> buffers;
  std::vector<bool> queued, mapped;
  std::deque<uint32_t> incoming;  // queued, in the order the device fills them
  std::deque<uint32_t> done;      // filled, waiting for DQBUF
  uint32_t sequence = 0;
  int qbuf_errors = 0;  // QBUF of a buffer the driver already queued
  int maps = 0, unmaps = 0;
  v4l2_fract timeperframe_set{0, 0};

  void addControl(uint32_t id, int32_t min, int32_t max, int32_t value) {
    v4l2_queryctrl q{};
    q.id = id;
    q.minimum = min;
    q.maximum = max;
    q.step = 1;
    controls[id] = q;
    values[id] = value;
  }

  uint32_t bytesPerPixel() const {
    return fmt.pixelformat == V4L2_PIX_FMT_GREY ? 1 : fmt.pixelformat == V4L2_PIX_FMT_RGB24 ? 3 : 2;
  }

  // The device fills the oldest queued buffer: pixel (x, y) of mono frames is
  // (x + y + sequence) % 251; YUYV has that as Y and neutral chroma.
  bool produce(bool corrupt = false) {
    if (!streaming || incoming.empty()) return false;
    const uint32_t i = incoming.front();
    incoming.pop_front();
    auto& b = buffers[i];
    for (uint32_t y = 0; y < fmt.height; ++y)
      for (uint32_t x = 0; x < fmt.width; ++x) {
        const uint8_t v = uint8_t((x + y + sequence) % 251);
        uint8_t* p = b.data() + y * fmt.bytesperline;
        if (fmt.pixelformat == V4L2_PIX_FMT_YUYV) {
          p[2 * x] = v;
          p[2 * x + 1] = 128;
        } else if (fmt.pixelformat == V4L2_PIX_FMT_Y16) {
          const uint16_t w = uint16_t(v * 256);
          std::memcpy(p + 2 * x, &w, 2);
        } else {
          p[x] = v;
        }
      }
    seq_of[i] = sequence++;
    corrupt_of[i] = corrupt;
    done.push_back(i);
    return true;
  }

  std::map<uint32_t, uint32_t> seq_of;
  std::map<uint32_t, bool> corrupt_of;
};

class FakeV4l2 final : public V4l2Io {
 public:
  explicit FakeV4l2(std::shared_ptr<FakeV4l2State> s) : s_(std::move(s)) {}

  int open(const std::string& path) override {
    if (s_->vanished || path == s_->fail_device) return -ENOENT;
    s_->open = true;
    return 42;
  }
  void close(int) override { s_->open = false; }
  void* mmap(int, std::size_t length, int64_t offset, int* error) override {
    const auto i = std::size_t(offset / kOffsetStep);
    if (s_->vanished || i >= s_->buffers.size() || length != s_->buffers[i].size()) {
      *error = s_->vanished ? ENODEV : EINVAL;
      return nullptr;
    }
    s_->mapped[i] = true;
    ++s_->maps;
    return s_->buffers[i].data();
  }
  void munmap(void* address, std::size_t) override {
    for (std::size_t i = 0; i < s_->buffers.size(); ++i)
      if (s_->buffers[i].data() == address) s_->mapped[i] = false;
    ++s_->unmaps;
  }
  int poll(int, int, bool* hangup) override {
    *hangup = s_->vanished;
    return s_->vanished || !s_->done.empty() ? 1 : 0;
  }
  int ioctl(int, unsigned long request, void* arg) override {
    if (s_->vanished) return -ENODEV;
    switch (request) {
      case VIDIOC_QUERYCAP: {
        auto* c = static_cast<v4l2_capability*>(arg);
        std::strcpy(reinterpret_cast<char*>(c->driver), "fake");
        std::strcpy(reinterpret_cast<char*>(c->card), "Fake Camera");
        std::strcpy(reinterpret_cast<char*>(c->bus_info), "usb-0000:00:14.0-1");
        c->capabilities = V4L2_CAP_DEVICE_CAPS | V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
        c->device_caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
        return 0;
      }
      case VIDIOC_ENUM_FMT: {
        auto* d = static_cast<v4l2_fmtdesc*>(arg);
        if (d->index >= s_->formats.size()) return -EINVAL;
        d->pixelformat = s_->formats[d->index].fourcc;
        return 0;
      }
      case VIDIOC_ENUM_FRAMESIZES: {
        auto* e = static_cast<v4l2_frmsizeenum*>(arg);
        const auto* f = find(e->pixel_format);
        if (!f || e->index >= f->sizes.size()) return -EINVAL;
        e->type = V4L2_FRMSIZE_TYPE_DISCRETE;
        e->discrete = {f->sizes[e->index].first, f->sizes[e->index].second};
        return 0;
      }
      case VIDIOC_S_FMT: {
        if (s_->streaming || !s_->buffers.empty()) return -EBUSY;
        auto& p = static_cast<v4l2_format*>(arg)->fmt.pix;
        // Like a driver: an unknown format becomes the first, an unknown size the first.
        const auto* f = find(p.pixelformat);
        if (!f) f = &s_->formats.front();
        auto size = f->sizes.front();
        for (auto sz : f->sizes)
          if (sz == std::make_pair(p.width, p.height)) size = sz;
        s_->fmt = {};
        s_->fmt.pixelformat = f->fourcc;
        s_->fmt.width = size.first;
        s_->fmt.height = size.second;
        s_->fmt.bytesperline = size.first * s_->bytesPerPixel() + s_->padding;
        s_->fmt.sizeimage = s_->fmt.bytesperline * size.second;
        p = s_->fmt;
        return 0;
      }
      case VIDIOC_G_FMT:
        static_cast<v4l2_format*>(arg)->fmt.pix = s_->fmt;
        return 0;
      case VIDIOC_G_PARM: {
        auto* p = static_cast<v4l2_streamparm*>(arg);
        p->parm.capture.capability = s_->timeperframe ? V4L2_CAP_TIMEPERFRAME : 0;
        return 0;
      }
      case VIDIOC_S_PARM:
        s_->timeperframe_set = static_cast<v4l2_streamparm*>(arg)->parm.capture.timeperframe;
        return 0;
      case VIDIOC_REQBUFS: {
        auto* r = static_cast<v4l2_requestbuffers*>(arg);
        if (s_->streaming || r->memory != V4L2_MEMORY_MMAP) return -EBUSY;
        for (bool m : s_->mapped)
          if (m && r->count > 0) return -EBUSY;
        r->count = std::min(r->count, s_->max_buffers);
        s_->buffers.assign(r->count, std::vector<uint8_t>(s_->fmt.sizeimage));
        s_->queued.assign(r->count, false);
        s_->mapped.assign(r->count, false);
        s_->incoming.clear();
        s_->done.clear();
        return 0;
      }
      case VIDIOC_QUERYBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= s_->buffers.size()) return -EINVAL;
        b->length = uint32_t(s_->buffers[b->index].size());
        b->m.offset = b->index * kOffsetStep;
        return 0;
      }
      case VIDIOC_QBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= s_->buffers.size()) return -EINVAL;
        if (s_->queued[b->index]) {
          ++s_->qbuf_errors;
          return -EINVAL;
        }
        s_->queued[b->index] = true;
        s_->incoming.push_back(b->index);
        return 0;
      }
      case VIDIOC_DQBUF: {
        if (!s_->streaming) return -EINVAL;
        if (s_->done.empty()) return -EAGAIN;
        auto* b = static_cast<v4l2_buffer*>(arg);
        const uint32_t i = s_->done.front();
        s_->done.pop_front();
        s_->queued[i] = false;
        b->index = i;
        b->bytesused = uint32_t(s_->buffers[i].size());
        b->sequence = s_->seq_of[i];
        b->flags =
            V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | (s_->corrupt_of[i] ? V4L2_BUF_FLAG_ERROR : 0);
        // 30 fps from t = 5 s.
        const uint64_t us = 5'000'000 + uint64_t(b->sequence) * 33'333;
        b->timestamp.tv_sec = long(us / 1'000'000);
        b->timestamp.tv_usec = long(us % 1'000'000);
        return 0;
      }
      case VIDIOC_STREAMON:
        if (s_->buffers.empty()) return -EINVAL;
        s_->streaming = true;
        return 0;
      case VIDIOC_STREAMOFF:
        s_->streaming = false;
        for (std::size_t i = 0; i < s_->queued.size(); ++i) s_->queued[i] = false;
        s_->incoming.clear();
        s_->done.clear();
        return 0;
      case VIDIOC_QUERYCTRL: {
        auto* q = static_cast<v4l2_queryctrl*>(arg);
        auto it = s_->controls.find(q->id);
        if (it == s_->controls.end()) return -EINVAL;
        *q = it->second;
        return 0;
      }
      case VIDIOC_G_CTRL: {
        auto* c = static_cast<v4l2_control*>(arg);
        if (!s_->controls.count(c->id)) return -EINVAL;
        c->value = s_->values[c->id];
        return 0;
      }
      case VIDIOC_S_CTRL: {
        auto* c = static_cast<v4l2_control*>(arg);
        if (!s_->controls.count(c->id)) return -EINVAL;
        s_->values[c->id] = c->value;
        return 0;
      }
      default:
        return -ENOTTY;
    }
  }

 private:
  static constexpr int64_t kOffsetStep = 1 << 20;
  const FakeV4l2State::Format* find(uint32_t fourcc) const {
    for (const auto& f : s_->formats)
      if (f.fourcc == fourcc) return &f;
    return nullptr;
  }
  std::shared_ptr<FakeV4l2State> s_;
};

}  // namespace procam::camera::testing
