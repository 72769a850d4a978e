#include "bundling.hpp"

namespace tomomap::transport {
namespace {

bool mayRide(const wire::SliceFeatures& p) {
  return p.riders().empty() && p.features().size() <= wire::MAX_RIDER_FEATURES &&
         p.occupancy().size() <= wire::MAX_RIDER_OCCUPANCY;
}

wire::SlicePiece asRider(const wire::SliceFeatures& p) {
  wire::SlicePiece r;
  r.slice(p.slice());
  r.part(p.part());
  r.parts(p.parts());
  r.encoding(p.encoding());
  r.features(p.features());
  r.occupancy(p.occupancy());
  return r;
}

size_t serialized(const wire::SliceFeatures& s) { return wire::SliceFeatures::getCdrSerializedSize(s); }

}  // namespace

Bundles bundle(const std::vector<wire::SliceFeatures>& pieces, size_t max_sample_bytes,
               const std::vector<int>& group) {
  Bundles b;
  std::vector<size_t> size;       // serialized bytes of each sample so far
  std::vector<int> sample_group;  // the group of each sample's pieces
  for (size_t i = 0; i < pieces.size(); ++i) {
    const wire::SliceFeatures& p = pieces[i];
    const int g = group.empty() ? 0 : group.at(i);
    size_t at = b.samples.size();
    if (mayRide(p)) {
      const wire::SlicePiece rider = asRider(p);
      // At most 3 bytes align the rider's first field after the previous one.
      const size_t cost = wire::SlicePiece::getCdrSerializedSize(rider) + 3;
      for (size_t k = 0; k < b.samples.size() && at == b.samples.size(); ++k)
        if (sample_group[k] == g && b.samples[k].riders().size() < wire::MAX_RIDERS &&
            size[k] + cost <= max_sample_bytes)
          at = k;
      if (at < b.samples.size()) {
        b.samples[at].riders().push_back(rider);
        size[at] = serialized(b.samples[at]);
      }
    }
    if (at == b.samples.size()) {
      b.samples.push_back(p);
      size.push_back(serialized(p));
      sample_group.push_back(g);
    }
    b.home.push_back(at);
  }
  return b;
}

std::vector<wire::SliceFeatures> unbundle(wire::SliceFeatures&& sample) {
  std::vector<wire::SliceFeatures> out;
  out.reserve(1 + sample.riders().size());
  std::vector<wire::SlicePiece> riders = std::move(sample.riders());
  sample.riders().clear();
  const auto agent = sample.agent();
  const uint64_t version = sample.version();
  out.push_back(std::move(sample));
  for (auto& r : riders) {
    wire::SliceFeatures p;
    p.agent(agent);
    p.version(version);
    p.slice(r.slice());
    p.part(r.part());
    p.parts(r.parts());
    p.encoding(r.encoding());
    p.features(std::move(r.features()));
    p.occupancy(std::move(r.occupancy()));
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace tomomap::transport
