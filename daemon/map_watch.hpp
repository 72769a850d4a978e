#pragma once
// Notices when the map file is rewritten, with inotify on its folder: SLAM
// systems either write the file in place (seen when they close it) or write a
// temporary file and rename it over the map (seen as a move into the folder).
// The folder is watched rather than the file because a rename replaces the
// file's inode and a watch on the old inode would never fire again.
#include <string>

namespace tomomap::daemon {

class MapWatch {
 public:
  /// Starts watching; on failure (no inotify, folder missing) logs nothing and
  /// `active()` is false: the daemon still runs, SIGHUP still reloads.
  explicit MapWatch(const std::string& map_path);
  ~MapWatch();
  MapWatch(const MapWatch&) = delete;
  MapWatch& operator=(const MapWatch&) = delete;

  bool active() const { return fd_ >= 0; }
  /// True when the map file was written, replaced or created since the last
  /// call. Never blocks.
  bool changed();

 private:
  int fd_ = -1;
  std::string name_;  ///< the map's file name within the watched folder
};

}  // namespace tomomap::daemon
