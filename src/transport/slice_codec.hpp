#pragma once
// A map's slices as wire samples and back: encoding (features or occupancy
// runs, whichever is smaller), chunking to a sample budget, and reassembly with
// validation. Pure code on the generated wire types: no participant needed.
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/features.hpp"
#include "tomomap.h"

namespace tomomap::transport {

/// What one agent offers: the announcement and every sample of every slice.
struct MapOffer {
  wire::MapAnnouncement announcement;
  std::map<int, std::vector<wire::SliceFeatures>> samples;  ///< by slice index, parts in order
  size_t payload_bytes = 0;  ///< sum of the slices' payload bytes
};

/// Slices `features` (its occupancy must be present) into samples of at most
/// `max_sample_bytes` each. `raw_bytes` is the binary PCD size of the
/// voxel-filtered map, announced for the record. Most informative slices
/// (most features) first.
MapOffer makeOffer(const std::string& agent, const MapFeatures& features, uint64_t raw_bytes,
                   size_t max_sample_bytes);

/// Hash of a map's description and its chunking: equal maps cut for equal
/// budgets have equal versions.
uint64_t mapVersion(const wire::MapAnnouncement& a);

/// Why an announcement or sample was rejected; empty when accepted.
using Rejection = std::string;

/// Checks an announcement before anything is allocated for it.
Rejection validate(const wire::MapAnnouncement& a);

/// Collects one peer's map at one version from samples in any order.
/// Memory is bounded by the announcement: no part that was not announced is
/// kept, no slice may exceed its announced size.
class Reassembler {
 public:
  explicit Reassembler(wire::MapAnnouncement announcement);

  const wire::MapAnnouncement& announcement() const { return announcement_; }
  /// Takes a sample of this agent and version. Returns a rejection for samples
  /// that contradict the announcement (never throws); duplicates are accepted.
  Rejection accept(const wire::SliceFeatures& sample);
  bool complete() const { return done_.size() == announcement_.slices().size(); }
  /// Announced slices not yet complete and verified.
  std::vector<int32_t> missing() const;
  size_t sliceCount() const { return announcement_.slices().size(); }
  size_t slicesDone() const { return done_.size(); }
  size_t bytesReceived() const { return bytes_received_; }
  /// The map's features, as the owner computed them (ORB is run here on slices
  /// that came as occupancy). Only when complete().
  MapFeatures build(const FeatureParams& params) const;
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
};

}  // namespace tomomap::transport
