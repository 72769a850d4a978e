#include "map_offer.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>

#include "bundling.hpp"
#include "core/dense_search.hpp"
#include "core/match_settings.hpp"
#include "core/threads.hpp"
#include "slice_encoding.hpp"

namespace tomomap::transport {
namespace {

/// Bytes a sample of `agent` takes besides its payload: its own fields
/// (agent, version, slice, part numbers, encoding, both sequence lengths), as
/// the generated code serializes them, plus the up to 3 bytes that align the
/// second sequence's length after a run of features.
size_t sampleHeaderBytes(const std::string& agent) {
  wire::SliceFeatures empty;
  empty.agent(agent);
  return wire::SliceFeatures::getCdrSerializedSize(empty) + 3;
}
/// Feature settings outside the settings' ranges are refused: a receiver
/// would otherwise run ORB with whatever a peer names.
constexpr int kMaxPad = 256;
bool acceptable(const wire::FeatureSettings& fs) {
  static const MatchSetting& features = matchSetting("max_features");
  static const MatchSetting& fast = matchSetting("fast_threshold");
  return features.inRange(fs.max_features()) && fast.inRange(fs.fast_threshold()) && fs.pad() <= kMaxPad;
}

/// The runs of unseen slices (SliceStack::seen), each its first and last
/// slice, as the announcement carries them: the lowest wire::MAX_UNSEEN / 2
/// runs (of a map with more, a receiver reads the rest as seen, as it reads
/// a stack that does not say).
std::vector<int32_t> unseenRuns(const SliceStack& stack) {
  std::vector<int32_t> runs;
  for (const SliceRun& run : seenRuns(stack))
    if (!run.seen && runs.size() + 2 <= wire::MAX_UNSEEN) runs.insert(runs.end(), {run.first, run.last});
  return runs;
}

template <typename T>
std::vector<std::vector<T>> split(const std::vector<T>& items, size_t per_part) {
  std::vector<std::vector<T>> parts;
  for (size_t i = 0; i < items.size(); i += per_part)
    parts.emplace_back(items.begin() + static_cast<long>(i),
                       items.begin() + static_cast<long>(std::min(items.size(), i + per_part)));
  if (parts.empty()) parts.emplace_back();
  return parts;
}

/// One slice's samples, in the cheaper encoding, or as occupancy whenever it has cells if `cells_first`.
std::vector<wire::SliceFeatures> cutSlice(const std::string& agent, const SliceFeatures& s,
                                          const std::vector<uint32_t>& cells, const SliceGrid& g,
                                          size_t features_per_part, size_t bytes_per_part, bool cells_first) {
  std::vector<wire::Feature> feats = featuresToWire(s, g);
  const std::vector<uint8_t> deflated = cells.empty() ? std::vector<uint8_t>{} : deflateCells(cells, g.width, g.height);
  const bool as_cells = !deflated.empty() && (cells_first || deflated.size() < feats.size() * kFeatureBytes);
  std::vector<wire::SliceFeatures> samples;
  auto base = [&](size_t part, size_t parts) {
    wire::SliceFeatures x;
    x.agent(agent);
    x.slice(s.index);
    x.part(static_cast<uint16_t>(part));
    x.parts(static_cast<uint16_t>(parts));
    x.encoding(as_cells ? wire::SliceEncoding::OCCUPANCY : wire::SliceEncoding::FEATURES);
    return x;
  };
  if (as_cells) {
    const auto parts = split(deflated, bytes_per_part);
    for (size_t p = 0; p < parts.size(); ++p)
      samples.push_back(base(p, parts.size())), samples.back().occupancy(parts[p]);
  } else {
    const auto parts = split(feats, features_per_part);
    for (size_t p = 0; p < parts.size(); ++p)
      samples.push_back(base(p, parts.size())), samples.back().features(parts[p]);
  }
  return samples;
}

}  // namespace

MapOffer makeOffer(const std::string& agent, const MapFeatures& f, const FeatureParams& params, uint64_t raw_bytes,
                   size_t max_sample_bytes, int threads, const EarlierOffer* earlier) {
  const SliceGrid& g = f.occupancy.grid;
  const size_t header = sampleHeaderBytes(agent);
  const size_t room = max_sample_bytes > header + kFeatureBytes ? max_sample_bytes - header : kFeatureBytes;
  const size_t features_per_part = std::clamp<size_t>(room / kFeatureBytes, 1, wire::MAX_FEATURES_PER_SAMPLE);
  const size_t bytes_per_part = std::clamp<size_t>(room, 1, wire::MAX_OCCUPANCY_PER_SAMPLE);

  MapOffer offer;
  auto& a = offer.announcement;
  a.agent(agent);
  a.grid(f.grid);
  a.x_min(g.x_min);
  a.y_min(g.y_min);
  a.z_min(f.z_min);
  const Eigen::Vector3d up = f.slicedUp();
  a.up({up.x(), up.y(), up.z()});
  a.width(static_cast<uint16_t>(g.width));
  a.height(static_cast<uint16_t>(g.height));
  a.slice_count(f.slice_count);
  a.unseen(unseenRuns(f.occupancy));
  a.raw_bytes(raw_bytes);
  a.features().max_features(static_cast<uint16_t>(params.max_features));
  a.features().fast_threshold(static_cast<uint16_t>(params.fast_threshold));
  a.features().pad(static_cast<uint16_t>(params.pad));

  // Most informative first: a receiver that gets only part of the map early
  // holds the slices most likely to match.
  std::vector<const SliceFeatures*> order;
  for (const auto& s : f.slices) order.push_back(&s);
  std::stable_sort(order.begin(), order.end(), [](const SliceFeatures* x, const SliceFeatures* y) {
    return x->keypoints.size() > y->keypoints.size();
  });
  if (order.size() > wire::MAX_SLICES) order.resize(wire::MAX_SLICES);

  // A map small enough for the dense search travels as occupancy throughout,
  // so that the receiver can search it too (it rebuilds the same features
  // from the cells); such maps are a few kilobytes either way.
  const bool cells_first = denseSearchable(f.occupancy);
  offer.cells_first = cells_first;
  // The earlier version's samples of a slice whose cells and features are
  // unchanged are this one's: cut alike from the same raster, settings and budget.
  const bool alike = earlier && earlier->offer.sample_bytes == max_sample_bytes &&
                     earlier->offer.cells_first == cells_first && earlier->features.occupancy.grid == g &&
                     earlier->offer.announcement.agent() == agent &&
                     featureParamsOf(earlier->offer.announcement) == params;
  std::map<int, const SliceFeatures*> earlier_slices;
  if (alike)
    for (const auto& s : earlier->features.slices) earlier_slices[s.index] = &s;
  const auto unchanged = [&](const SliceFeatures& s) {
    const auto was = earlier_slices.find(s.index);
    if (was == earlier_slices.end() || !earlier->offer.samples.count(s.index)) return false;
    const auto k = static_cast<size_t>(s.index);
    return earlier->features.occupancy.cells.size() > k &&
           earlier->features.occupancy.cells[k] == f.occupancy.cells.at(k) && was->second->keypoints == s.keypoints &&
           cv::norm(was->second->descriptors, s.descriptors, cv::NORM_HAMMING) == 0.0;
  };
  // Deflating each slice twice (slice_encoding.cpp) is most of the work: in
  // parallel over slices, then put together in order.
  std::vector<std::vector<wire::SliceFeatures>> cut(order.size());
  std::vector<char> taken(order.size(), 0);
#pragma omp parallel for schedule(dynamic) num_threads(resolvedThreads(threads))
  for (size_t i = 0; i < order.size(); ++i) {
    taken[i] = unchanged(*order[i]);
    cut[i] = taken[i] ? earlier->offer.samples.at(order[i]->index)
                      : cutSlice(agent, *order[i], f.occupancy.cells.at(static_cast<size_t>(order[i]->index)), g,
                                 features_per_part, bytes_per_part, cells_first);
  }
  offer.encoded_slices = static_cast<size_t>(std::count(taken.begin(), taken.end(), 0));
  for (size_t i = 0; i < order.size(); ++i) {
    const SliceFeatures* s = order[i];
    auto& samples = cut[i];
    const auto bytes = canonicalBytes(samples);
    wire::SliceEntry e;
    e.slice(s->index);
    e.parts(static_cast<uint16_t>(samples.size()));
    e.bytes(static_cast<uint32_t>(bytes.size()));
    e.crc32(crcOf(bytes));
    a.slices().push_back(e);
    offer.payload_bytes += bytes.size();
    offer.samples[s->index] = std::move(samples);
  }
  a.version(mapVersion(a));
  for (auto& [k, samples] : offer.samples)
    for (auto& x : samples) x.version(a.version());
  offer.sample_bytes = max_sample_bytes;
  bundleOffer(offer);
  return offer;
}

void bundleOffer(MapOffer& offer, const wire::MapAnnouncement* previous) {
  const std::set<int> kept = previous ? unchangedSlices(offer.announcement, *previous) : std::set<int>{};
  std::vector<wire::SliceFeatures> pieces;
  std::vector<int> slice_of, group;
  for (const auto& e : offer.announcement.slices()) {
    const auto it = offer.samples.find(e.slice());
    if (it == offer.samples.end()) continue;
    for (const auto& p : it->second)
      pieces.push_back(p), slice_of.push_back(e.slice()), group.push_back(kept.count(e.slice()) ? 1 : 0);
  }
  Bundles b = bundle(pieces, offer.sample_bytes, group);
  offer.bundles = std::move(b.samples);
  offer.bundles_of.clear();
  for (size_t i = 0; i < pieces.size(); ++i) {
    auto& homes = offer.bundles_of[slice_of[i]];
    if (std::find(homes.begin(), homes.end(), b.home[i]) == homes.end()) homes.push_back(b.home[i]);
  }
}

std::set<int> unchangedSlices(const wire::MapAnnouncement& now, const wire::MapAnnouncement& then) {
  std::set<int> kept;
  const bool same_raster = now.agent() == then.agent() && now.grid() == then.grid() && now.x_min() == then.x_min() &&
                           now.y_min() == then.y_min() && now.z_min() == then.z_min() && now.width() == then.width() &&
                           now.height() == then.height() && now.features() == then.features();
  if (!same_raster) return kept;  // every cell index (or feature) means something else now
  std::map<int, const wire::SliceEntry*> before;
  for (const auto& e : then.slices()) before[e.slice()] = &e;
  for (const auto& e : now.slices()) {
    const auto old = before.find(e.slice());
    if (old != before.end() && old->second->crc32() == e.crc32() && old->second->bytes() == e.bytes() &&
        old->second->parts() == e.parts())
      kept.insert(e.slice());
  }
  return kept;
}

uint64_t mapVersion(const wire::MapAnnouncement& a) {
  // FNV-1a over the raster geometry, the feature settings, every slice's
  // index, CRC and part count and the unseen runs: the same content cut for another bandwidth
  // budget (a reload) is another version, so a receiver never mixes parts of
  // two chunkings.
  uint64_t h = 1469598103934665603ull;
  auto mix = [&h](uint64_t v) {
    for (int i = 0; i < 8; ++i) {
      h ^= (v >> (8 * i)) & 0xff;
      h *= 1099511628211ull;
    }
  };
  auto bits = [](double d) {
    uint64_t u;
    std::memcpy(&u, &d, sizeof u);
    return u;
  };
  mix(bits(a.grid()));
  mix(bits(a.x_min()));
  mix(bits(a.y_min()));
  mix(bits(a.z_min()));
  for (double u : a.up()) mix(bits(u));
  mix((uint64_t{a.width()} << 16) | a.height());
  const auto& fs = a.features();
  mix((uint64_t{fs.max_features()} << 32) | (uint64_t{fs.fast_threshold()} << 16) | fs.pad());
  for (const auto& e : a.slices()) {
    mix((uint64_t{static_cast<uint32_t>(e.slice())} << 32) | e.crc32());
    mix(e.parts());
  }
  for (int32_t k : a.unseen()) mix(static_cast<uint32_t>(k));
  return h;
}

std::vector<bool> seenOf(const wire::MapAnnouncement& a) {
  std::vector<bool> seen(static_cast<size_t>(std::max(a.slice_count(), 0)), true);
  for (size_t i = 0; i + 1 < a.unseen().size(); i += 2)
    for (int32_t k = std::max(a.unseen()[i], 0); k <= a.unseen()[i + 1] && k < a.slice_count(); ++k)
      seen[static_cast<size_t>(k)] = false;
  return seen;
}

Eigen::Vector3d upOf(const wire::MapAnnouncement& a) { return {a.up()[0], a.up()[1], a.up()[2]}; }

FeatureParams featureParamsOf(const wire::MapAnnouncement& a) {
  FeatureParams p;
  p.max_features = a.features().max_features();
  p.fast_threshold = a.features().fast_threshold();
  p.pad = a.features().pad();
  return p;
}

Rejection validate(const wire::MapAnnouncement& a) {
  if (!(a.grid() > 0) || !std::isfinite(a.grid()) || !std::isfinite(a.x_min()) || !std::isfinite(a.y_min()) ||
      !std::isfinite(a.z_min()))
    return {Reject::BadGridOrOrigin};
  if (!levelableUp(upOf(a))) return {Reject::BadUp};
  if (a.width() == 0 || a.height() == 0 || a.width() > kMaxImageSide || a.height() > kMaxImageSide)
    return {Reject::BadRaster};
  // No more slices than makeSlices makes: their indices fit 16 bits where a pose is judged.
  if (a.slice_count() <= 0 || a.slice_count() > kMaxImageSide) return {Reject::BadSliceCount};
  const auto& fs = a.features();
  if (!acceptable(fs)) return {Reject::BadFeatureSettings};
  // A slice can never need more than its deflated raster or its announced features.
  const size_t cap = std::max<size_t>(compressBound(static_cast<uLong>(rasterBytes(a.width(), a.height()))),
                                      size_t{fs.max_features()} * kFeatureBytes);
  std::set<int> listed;
  for (const auto& e : a.slices()) {
    if (e.slice() < 0 || e.slice() >= a.slice_count() || !listed.insert(e.slice()).second)
      return {Reject::SliceOutOfRange, e.slice()};
    if (e.parts() == 0 || e.parts() > 1024) return {Reject::BadPartCount, e.slice()};
    if (e.bytes() > cap) return {Reject::OversizedSlice, e.slice()};
  }
  // Unseen runs in pairs, in range, ascending and apart, over no slice it sends (a slice with cells was seen).
  const auto& unseen = a.unseen();
  if (unseen.size() % 2 != 0) return {Reject::UnpairedUnseen};
  for (size_t i = 0; i < unseen.size(); i += 2) {
    const int32_t first = unseen[i], last = unseen[i + 1];
    const bool apart = i == 0 || first > unseen[i - 1] + 1;
    if (first < 0 || first > last || last >= a.slice_count() || !apart ||
        listed.lower_bound(first) != listed.upper_bound(last))
      return {Reject::BadUnseen, first};
  }
  if (a.version() != mapVersion(a)) return {Reject::VersionMismatch};
  return {};
}

}  // namespace tomomap::transport
