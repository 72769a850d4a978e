#include "map_watch.hpp"

#include <sys/inotify.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>

namespace tomomap::daemon {

MapWatch::MapWatch(const std::string& map_path) {
  const std::filesystem::path p(map_path);
  name_ = p.filename().string();
  fd_ = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (fd_ < 0) return;
  const std::string folder = p.has_parent_path() ? p.parent_path().string() : ".";
  if (inotify_add_watch(fd_, folder.c_str(), IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE) < 0) {
    ::close(fd_);
    fd_ = -1;
  }
}

MapWatch::~MapWatch() {
  if (fd_ >= 0) ::close(fd_);
}

bool MapWatch::changed() {
  if (fd_ < 0) return false;
  bool hit = false;
  alignas(inotify_event) char buf[16 * 1024];
  for (;;) {
    const ssize_t n = ::read(fd_, buf, sizeof buf);
    if (n <= 0) break;  // EAGAIN: nothing more
    for (ssize_t at = 0; at < n;) {
      const auto* e = reinterpret_cast<const inotify_event*>(buf + at);
      if (e->len > 0 && name_ == e->name) hit = true;
      if (e->mask & IN_Q_OVERFLOW) hit = true;  // events were lost: assume ours was one
      at += static_cast<ssize_t>(sizeof(inotify_event) + e->len);
    }
  }
  return hit;
}

}  // namespace tomomap::daemon
