#pragma once
// One peer's map at one version, collected from samples in any order and
// checked against its announcement.
#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "core/features.hpp"
#include "rejection.hpp"
#include "tomomap.h"

namespace tomomap::transport {

/// Memory the announced map needs at least while it arrives and is described:
/// its payload and one raster image [bytes].
size_t announcedMemory(const wire::MapAnnouncement& a);
/// OverBudget if announcedMemory(a) exceeds `budget`: checked before anything
/// of the map is allocated.
Rejection fitsBudget(const wire::MapAnnouncement& a, size_t budget);

/// Memory is bounded by the announcement (no part that was not announced is
/// kept, no slice may exceed its announced size) and by a budget: occupancy
/// is inflated slice by slice, and a slice whose cells would take the map over
/// the budget refuses the whole map (every later sample is refused too).
class Reassembler {
 public:
  /// `announcement` must have passed validate() and fitsBudget().
  explicit Reassembler(wire::MapAnnouncement announcement, size_t memory_budget = SIZE_MAX);

  const wire::MapAnnouncement& announcement() const { return announcement_; }
  /// Takes a sample of this agent and version. Returns a rejection for samples
  /// that contradict the announcement (never throws); duplicates are accepted.
  Rejection accept(const wire::SliceFeatures& sample);
  bool complete() const { return done_.size() == announcement_.slices().size(); }
  /// The map went over the memory budget: it will never complete.
  bool refused() const { return refused_; }
  /// Announced slices not yet complete and verified.
  std::vector<int32_t> missing() const;
  size_t sliceCount() const { return announcement_.slices().size(); }
  size_t slicesDone() const { return done_.size(); }
  size_t bytesReceived() const { return bytes_received_; }
  /// The map's features as the owner computed them: ORB runs here, with the
  /// announced settings, on the slices that came as occupancy. Only when complete().
  MapFeatures build() const;
  /// Takes over the verified slices of an earlier version of the same agent's
  /// map that this version announces unchanged (same raster, same index, size
  /// and CRC), so that a map update costs only the slices that changed.
  /// Returns how many were taken.
  size_t adopt(const Reassembler& earlier);

 private:
  struct Partial {
    std::vector<std::optional<wire::SliceFeatures>> parts;
    size_t received = 0;
  };
  wire::MapAnnouncement announcement_;
  std::map<int, size_t> entries_;  ///< slice index -> position in the announcement
  std::map<int, Partial> partial_;
  std::map<int, std::vector<wire::SliceFeatures>> done_;
  std::map<int, std::vector<uint32_t>> cells_;  ///< inflated occupancy of verified slices
  size_t bytes_received_ = 0;
  size_t budget_;
  size_t announced_memory_;  ///< announcedMemory(announcement_)
  size_t cell_bytes_ = 0;    ///< held by cells_
  bool refused_ = false;
};

}  // namespace tomomap::transport
