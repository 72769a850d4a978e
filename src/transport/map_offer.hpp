#pragma once
// What one agent offers of its map: the announcement (raster, feature
// settings, every slice's size and CRC, and a version hashed over all of it)
// and every slice cut into samples that fit the bandwidth budget.
#include <map>
#include <set>
#include <vector>

#include "core/features.hpp"
#include "rejection.hpp"
#include "tomomap.h"

namespace tomomap::transport {

struct MapOffer {
  wire::MapAnnouncement announcement;
  std::map<int, std::vector<wire::SliceFeatures>> samples;  ///< by slice index, parts in order
  size_t payload_bytes = 0;                                 ///< sum of the slices' payload bytes
  /// What is written: every part above, small ones riding in others' spare
  /// room (bundling.hpp), in the announcement's order; and the ones that carry
  /// each slice's parts.
  std::vector<wire::SliceFeatures> bundles;
  std::map<int, std::vector<size_t>> bundles_of;
  size_t sample_bytes = 0;    ///< the most a sample may take, serialized
  bool cells_first = false;   ///< every slice as occupancy (a map small enough for the dense search)
  size_t encoded_slices = 0;  ///< slices cut anew; the rest were taken from an earlier version
};

/// An earlier version of the same map, described and offered.
struct EarlierOffer {
  const MapFeatures& features;
  const MapOffer& offer;
};

/// Fills `offer.bundles` and `offer.bundles_of` from its samples. With the
/// `previous` version's announcement, pieces of slices a holder of it keeps
/// (unchangedSlices) and pieces of the others never share a sample: after a
/// map update peers ask for the changed slices only, and a sample mixing both
/// would send kept slices again (a demo-room update that changed a third of
/// the slices resent more than the whole first transfer).
void bundleOffer(MapOffer& offer, const wire::MapAnnouncement* previous = nullptr);

/// The slices of `now` that a holder of `then` keeps: both of the same agent,
/// raster and feature settings, and the slice's index, bytes, parts and CRC
/// unchanged (docs/protocol.md, "A map that changes").
std::set<int> unchangedSlices(const wire::MapAnnouncement& now, const wire::MapAnnouncement& then);

/// Slices `features` (its occupancy must be present; `params` are the ones it
/// was extracted with) into samples of at most `max_sample_bytes` each. Each
/// slice travels as features or as deflated occupancy, whichever is smaller;
/// every slice as occupancy when the map is small enough for the dense search.
/// `raw_bytes` is the binary PCD size of the voxel-filtered map, announced for
/// the record. Most informative slices (most features) first. Encodes on
/// `threads` threads (0: every core). With `earlier`, a slice whose cells and
/// features are its slice's there, on the same raster, settings and budget,
/// takes its samples instead of being cut again: the same bytes.
MapOffer makeOffer(const std::string& agent, const MapFeatures& features, const FeatureParams& params,
                   uint64_t raw_bytes, size_t max_sample_bytes, int threads = 0, const EarlierOffer* earlier = nullptr);

/// Hash of a map's raster, feature settings, slices and chunking: equal maps
/// described alike and cut for equal budgets have equal versions.
uint64_t mapVersion(const wire::MapAnnouncement& a);

/// The feature settings an announcement carries, as the core takes them.
FeatureParams featureParamsOf(const wire::MapAnnouncement& a);
/// Per slice of the announced map, whether it had any point at that height
/// (SliceStack::seen).
std::vector<bool> seenOf(const wire::MapAnnouncement& a);
/// The up direction the announced map's slices are level to, in its own frame.
Eigen::Vector3d upOf(const wire::MapAnnouncement& a);

/// Checks an announcement before anything is allocated for it.
Rejection validate(const wire::MapAnnouncement& a);

}  // namespace tomomap::transport
