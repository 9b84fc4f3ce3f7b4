#include "event_loop.hpp"

#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/signalfd.h>
#include <sys/timerfd.h>

#include <cerrno>
#include <csignal>
#include <cstring>

#include "log.hpp"

namespace procam::daemon {

namespace {
tl::unexpected<Error> sysError(const char* what) {
  return fail(ErrorCode::kIo, std::string(what) + ": " + std::strerror(errno));
}
}  // namespace

Result<std::unique_ptr<EventLoop>> EventLoop::create() {
  std::unique_ptr<EventLoop> loop(new EventLoop());
  loop->epoll_.reset(::epoll_create1(EPOLL_CLOEXEC));
  if (!loop->epoll_.valid()) return sysError("epoll_create1");
  loop->wake_.reset(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
  if (!loop->wake_.valid()) return sysError("eventfd");
  EventLoop* self = loop.get();
  if (auto ok = loop->add(loop->wake_.get(), EPOLLIN, [self](uint32_t) { self->drainPosted(); });
      !ok) {
    return tl::unexpected(ok.error());
  }
  return loop;
}

Result<void> EventLoop::add(int fd, uint32_t events, Handler handler) {
  const uint32_t gen = next_generation_++;
  epoll_event ev{};
  ev.events = events;
  ev.data.u64 = (static_cast<uint64_t>(gen) << 32) | static_cast<uint32_t>(fd);
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, fd, &ev) != 0) return sysError("epoll_ctl(ADD)");
  handlers_[fd] = Entry{gen, std::make_shared<Handler>(std::move(handler))};
  return {};
}

Result<void> EventLoop::modify(int fd, uint32_t events) {
  auto it = handlers_.find(fd);
  if (it == handlers_.end()) return fail(ErrorCode::kNotFound, "fd not watched");
  epoll_event ev{};
  ev.events = events;
  ev.data.u64 = (static_cast<uint64_t>(it->second.generation) << 32) | static_cast<uint32_t>(fd);
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_MOD, fd, &ev) != 0) return sysError("epoll_ctl(MOD)");
  return {};
}

void EventLoop::remove(int fd) {
  if (handlers_.erase(fd) > 0) ::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, fd, nullptr);
}

Result<int> EventLoop::addTimer(std::chrono::nanoseconds interval, bool repeat,
                                std::function<void()> callback) {
  UniqueFd tfd(::timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC | TFD_NONBLOCK));
  if (!tfd.valid()) return sysError("timerfd_create");
  const auto ns = std::max<int64_t>(interval.count(), 1);
  itimerspec spec{};
  spec.it_value.tv_sec = ns / 1000000000;
  spec.it_value.tv_nsec = ns % 1000000000;
  if (repeat) spec.it_interval = spec.it_value;
  if (::timerfd_settime(tfd.get(), 0, &spec, nullptr) != 0) return sysError("timerfd_settime");
  const int id = tfd.get();
  auto ok = add(id, EPOLLIN, [this, id, repeat, cb = std::move(callback)](uint32_t) {
    uint64_t expirations = 0;
    if (::read(id, &expirations, sizeof expirations) != sizeof expirations) return;
    if (!repeat) removeTimer(id);  // run() holds a reference: this lambda stays alive
    cb();
  });
  if (!ok) return tl::unexpected(ok.error());
  timers_.emplace(id, std::move(tfd));
  return id;
}

void EventLoop::removeTimer(int id) {
  auto it = timers_.find(id);
  if (it == timers_.end()) return;
  // The handler (and so the callback) may be running: keep it alive until
  // the dispatch that holds a reference returns.
  remove(id);
  timers_.erase(it);
}

Result<void> EventLoop::watchSignals(const std::vector<int>& signals,
                                     std::function<void(int)> callback) {
  sigset_t mask;
  sigemptyset(&mask);
  for (int s : signals) sigaddset(&mask, s);
  if (::sigprocmask(SIG_BLOCK, &mask, nullptr) != 0) return sysError("sigprocmask");
  signal_fd_.reset(::signalfd(-1, &mask, SFD_CLOEXEC | SFD_NONBLOCK));
  if (!signal_fd_.valid()) return sysError("signalfd");
  const int fd = signal_fd_.get();
  return add(fd, EPOLLIN, [fd, cb = std::move(callback)](uint32_t) {
    signalfd_siginfo info{};
    while (::read(fd, &info, sizeof info) == sizeof info) cb(static_cast<int>(info.ssi_signo));
  });
}

void EventLoop::post(std::function<void()> fn) {
  {
    std::lock_guard lock(posted_mutex_);
    posted_.push_back(std::move(fn));
  }
  const uint64_t one = 1;
  ssize_t rc = ::write(wake_.get(), &one, sizeof one);
  (void)rc;  // EAGAIN only when the counter is saturated: a wake-up is pending anyway
}

void EventLoop::drainPosted() {
  uint64_t count = 0;
  ssize_t rc = ::read(wake_.get(), &count, sizeof count);
  (void)rc;
  std::vector<std::function<void()>> batch;
  {
    std::lock_guard lock(posted_mutex_);
    batch.swap(posted_);
  }
  for (auto& fn : batch) fn();
}

int EventLoop::run() {
  running_ = true;
  epoll_event events[64];
  while (running_) {
    const int n = ::epoll_wait(epoll_.get(), events, 64, -1);
    if (n < 0) {
      if (errno == EINTR) continue;
      logError(std::string("epoll_wait: ") + std::strerror(errno));
      return 1;
    }
    for (int i = 0; i < n && running_; ++i) {
      const int fd = static_cast<int>(events[i].data.u64 & 0xffffffffu);
      const auto gen = static_cast<uint32_t>(events[i].data.u64 >> 32);
      auto it = handlers_.find(fd);
      // Skip events of an fd removed (and maybe reused) earlier in this batch.
      if (it == handlers_.end() || it->second.generation != gen) continue;
      std::shared_ptr<Handler> handler = it->second.handler;
      (*handler)(events[i].events);
    }
  }
  return exit_code_;
}

void EventLoop::stop(int code) {
  exit_code_ = code;
  running_ = false;
  post([] {});  // wake epoll_wait when called from another thread
}

}  // namespace procam::daemon
