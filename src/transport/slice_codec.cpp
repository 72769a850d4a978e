#include "slice_codec.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace tomomap::transport {
namespace {

constexpr size_t kFeatureBytes = 4 + 32;  // u, v, descriptor
constexpr size_t kMaxFeaturesPerSample = 4096, kMaxOccupancyPerSample = 60000;  // the IDL bounds
constexpr size_t kMaxSlices = 4096;
/// Room a sample's own fields take besides its payload (agent, version, slice,
/// part numbers, encoding, sequence lengths), with margin.
constexpr size_t kSampleHeaderBytes = 256;

void put16(std::vector<uint8_t>& b, uint16_t v) {
  b.push_back(static_cast<uint8_t>(v & 0xff));
  b.push_back(static_cast<uint8_t>(v >> 8));
}

/// The canonical bytes of a slice's payload, over which the CRC is taken.
std::vector<uint8_t> canonicalBytes(const std::vector<wire::SliceFeatures>& parts) {
  std::vector<uint8_t> b;
  for (const auto& p : parts) {
    for (const auto& f : p.features()) {
      put16(b, f.u());
      put16(b, f.v());
      b.insert(b.end(), f.descriptor().begin(), f.descriptor().end());
    }
    b.insert(b.end(), p.occupancy().begin(), p.occupancy().end());
  }
  return b;
}

uint32_t crcOf(const std::vector<uint8_t>& bytes) {
  return static_cast<uint32_t>(crc32(crc32(0L, Z_NULL, 0), bytes.data(), static_cast<uInt>(bytes.size())));
}

size_t rasterBytes(size_t width, size_t height) { return (width * height + 7) / 8; }

/// A slice's occupied cells as a bit raster, deflated (zlib, best compression).
/// Walls are long runs of set bits or one bit repeated row after row, which
/// deflate stores in a few bytes where a list of cells would take 4 each.
std::vector<uint8_t> deflateCells(const std::vector<uint32_t>& cells, int width, int height) {
  std::vector<uint8_t> raster(rasterBytes(static_cast<size_t>(width), static_cast<size_t>(height)), 0);
  for (uint32_t c : cells) raster[c / 8] = static_cast<uint8_t>(raster[c / 8] | (1u << (c % 8)));
  uLongf size = compressBound(static_cast<uLong>(raster.size()));
  std::vector<uint8_t> out(size);
  if (compress2(out.data(), &size, raster.data(), static_cast<uLong>(raster.size()), Z_BEST_COMPRESSION) != Z_OK)
    return {};
  out.resize(size);
  return out;
}

/// The inverse; nullopt when the bytes do not inflate to exactly the raster.
std::optional<std::vector<uint32_t>> inflateCells(const std::vector<uint8_t>& bytes, int width, int height) {
  std::vector<uint8_t> raster(rasterBytes(static_cast<size_t>(width), static_cast<size_t>(height)));
  uLongf size = static_cast<uLongf>(raster.size());
  if (uncompress(raster.data(), &size, bytes.data(), static_cast<uLong>(bytes.size())) != Z_OK ||
      size != raster.size())
    return std::nullopt;
  std::vector<uint32_t> cells;
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  for (size_t i = 0; i < raster.size(); ++i)
    for (uint32_t bit = 0; raster[i] >> bit; ++bit)
      if ((raster[i] >> bit) & 1u) {
        if (8 * i + bit >= n) return std::nullopt;  // bits past the raster's end
        cells.push_back(static_cast<uint32_t>(8 * i + bit));
      }
  return cells;
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

}  // namespace

MapOffer makeOffer(const std::string& agent, const MapFeatures& f, uint64_t raw_bytes, size_t max_sample_bytes) {
  const SliceGrid& g = f.occupancy.grid;
  const size_t room =
      max_sample_bytes > kSampleHeaderBytes + kFeatureBytes ? max_sample_bytes - kSampleHeaderBytes : kFeatureBytes;
  const size_t features_per_part = std::clamp<size_t>(room / kFeatureBytes, 1, kMaxFeaturesPerSample);
  const size_t bytes_per_part = std::clamp<size_t>(room, 1, kMaxOccupancyPerSample);

  MapOffer offer;
  auto& a = offer.announcement;
  a.agent(agent);
  a.grid(f.grid);
  a.x_min(g.x_min);
  a.y_min(g.y_min);
  a.z_min(f.z_min);
  a.width(static_cast<uint16_t>(g.width));
  a.height(static_cast<uint16_t>(g.height));
  a.slice_count(f.slice_count);
  a.raw_bytes(raw_bytes);

  // Most informative first: a receiver that gets only part of the map early
  // holds the slices most likely to match.
  std::vector<const SliceFeatures*> order;
  for (const auto& s : f.slices) order.push_back(&s);
  std::stable_sort(order.begin(), order.end(), [](const SliceFeatures* x, const SliceFeatures* y) {
    return x->keypoints.size() > y->keypoints.size();
  });
  if (order.size() > kMaxSlices) order.resize(kMaxSlices);

  for (const SliceFeatures* s : order) {
    std::vector<wire::Feature> feats;
    feats.reserve(s->keypoints.size());
    for (size_t i = 0; i < s->keypoints.size(); ++i) {
      wire::Feature w;
      // Keypoints sit on pixel centres (single-level ORB): exact round trip.
      w.u(static_cast<uint16_t>(std::lround((s->keypoints[i].x() - g.x_min) / g.cell - 0.5)));
      w.v(static_cast<uint16_t>(std::lround((s->keypoints[i].y() - g.y_min) / g.cell - 0.5)));
      std::copy_n(s->descriptors.ptr<uint8_t>(static_cast<int>(i)), 32, w.descriptor().begin());
      feats.push_back(w);
    }
    const auto& cells = f.occupancy.cells.at(static_cast<size_t>(s->index));
    const std::vector<uint8_t> deflated = cells.empty() ? std::vector<uint8_t>{} : deflateCells(cells, g.width, g.height);
    const bool as_cells = !deflated.empty() && deflated.size() < feats.size() * kFeatureBytes;

    std::vector<wire::SliceFeatures> samples;
    auto base = [&](size_t part, size_t parts) {
      wire::SliceFeatures x;
      x.agent(agent);
      x.slice(s->index);
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
  return offer;
}

uint64_t mapVersion(const wire::MapAnnouncement& a) {
  // FNV-1a over the raster geometry and every slice's index, CRC and part
  // count: the same content cut for another bandwidth budget (a reload) is
  // another version, so a receiver never mixes parts of two chunkings.
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
  mix((uint64_t{a.width()} << 16) | a.height());
  for (const auto& e : a.slices()) {
    mix((uint64_t{static_cast<uint32_t>(e.slice())} << 32) | e.crc32());
    mix(e.parts());
  }
  return h;
}

Rejection validate(const wire::MapAnnouncement& a) {
  if (!(a.grid() > 0) || !std::isfinite(a.grid()) || !std::isfinite(a.x_min()) || !std::isfinite(a.y_min()) ||
      !std::isfinite(a.z_min()))
    return "announcement with a bad grid or origin";
  if (a.width() == 0 || a.height() == 0 || a.width() > kMaxImageSide || a.height() > kMaxImageSide)
    return "announcement with a bad raster size";
  if (a.slice_count() <= 0 || a.slice_count() > 100000) return "announcement with a bad slice count";
  std::set<int> seen;
  for (const auto& e : a.slices()) {
    if (e.slice() < 0 || e.slice() >= a.slice_count() || !seen.insert(e.slice()).second)
      return "announcement lists slice " + std::to_string(e.slice()) + " out of range or twice";
    if (e.parts() == 0 || e.parts() > 1024) return "announcement with a bad part count";
    // A slice can never need more than its deflated raster or ORB's cap in features.
    const size_t cap = std::max<size_t>(compressBound(static_cast<uLong>(rasterBytes(a.width(), a.height()))),
                                        100000 * kFeatureBytes);
    if (e.bytes() > cap) return "announcement with an oversized slice";
  }
  if (a.version() != mapVersion(a)) return "announcement whose version does not match its content";
  return {};
}

Reassembler::Reassembler(wire::MapAnnouncement announcement) : announcement_(std::move(announcement)) {
  for (size_t i = 0; i < announcement_.slices().size(); ++i) entries_[announcement_.slices()[i].slice()] = i;
}

Rejection Reassembler::accept(const wire::SliceFeatures& x) {
  const auto it = entries_.find(x.slice());
  if (it == entries_.end()) return "slice " + std::to_string(x.slice()) + " was not announced";
  const wire::SliceEntry& e = announcement_.slices()[it->second];
  if (x.parts() != e.parts() || x.part() >= e.parts()) return "part numbering differs from the announcement";
  const bool cells = x.encoding() == wire::SliceEncoding::OCCUPANCY;
  if ((cells && !x.features().empty()) || (!cells && !x.occupancy().empty())) return "sample mixes encodings";
  for (const auto& f : x.features())
    if (f.u() >= announcement_.width() || f.v() >= announcement_.height()) return "keypoint outside the raster";
  if (done_.count(x.slice())) return {};  // a duplicate of a verified slice

  Partial& p = partial_[x.slice()];
  p.parts.resize(e.parts());
  auto& slot = p.parts[x.part()];
  if (slot) return {};  // duplicate part
  const size_t bytes = x.features().size() * kFeatureBytes + x.occupancy().size();
  size_t held = 0;
  for (const auto& q : p.parts)
    if (q) held += q->features().size() * kFeatureBytes + q->occupancy().size();
  if (held + bytes > e.bytes()) {
    partial_.erase(x.slice());
    return "slice larger than announced";
  }
  slot = x;
  ++p.received;
  bytes_received_ += bytes;
  if (p.received < e.parts()) return {};

  std::vector<wire::SliceFeatures> parts;
  for (auto& q : p.parts) parts.push_back(std::move(*q));
  partial_.erase(x.slice());
  const auto canonical = canonicalBytes(parts);
  if (canonical.size() != e.bytes() || crcOf(canonical) != e.crc32()) return "slice checksum mismatch";
  if (parts.front().encoding() == wire::SliceEncoding::OCCUPANCY) {
    auto decoded = inflateCells(canonical, announcement_.width(), announcement_.height());
    if (!decoded) return "occupancy does not inflate to the announced raster";
    cells_[x.slice()] = std::move(*decoded);
  }
  done_[x.slice()] = std::move(parts);
  return {};
}

std::vector<int32_t> Reassembler::missing() const {
  std::vector<int32_t> out;
  for (const auto& e : announcement_.slices())
    if (!done_.count(e.slice())) out.push_back(e.slice());
  return out;
}

size_t Reassembler::adopt(const Reassembler& earlier) {
  const auto& a = announcement_;
  const auto& b = earlier.announcement_;
  const bool same_raster = a.agent() == b.agent() && a.grid() == b.grid() && a.x_min() == b.x_min() &&
                           a.y_min() == b.y_min() && a.z_min() == b.z_min() && a.width() == b.width() &&
                           a.height() == b.height();
  if (!same_raster) return 0;  // every cell index means something else now
  size_t taken = 0;
  for (const auto& [index, position] : entries_) {
    const auto old = earlier.entries_.find(index);
    const auto parts = earlier.done_.find(index);
    if (done_.count(index) || old == earlier.entries_.end() || parts == earlier.done_.end()) continue;
    const wire::SliceEntry& now = a.slices()[position];
    const wire::SliceEntry& then = b.slices()[old->second];
    if (now.crc32() != then.crc32() || now.bytes() != then.bytes() || now.parts() != then.parts()) continue;
    done_[index] = parts->second;
    if (const auto cells = earlier.cells_.find(index); cells != earlier.cells_.end()) cells_[index] = cells->second;
    partial_.erase(index);
    ++taken;
  }
  return taken;
}

MapFeatures Reassembler::build(const FeatureParams& params) const {
  const auto& a = announcement_;
  SliceStack stack;
  stack.grid = {a.grid(), a.x_min(), a.y_min(), a.z_min(), a.width(), a.height()};
  stack.cells.resize(static_cast<size_t>(a.slice_count()));
  std::vector<SliceFeatures> sent_as_features;
  for (const auto& [index, parts] : done_) {
    if (parts.front().encoding() == wire::SliceEncoding::OCCUPANCY) {
      stack.cells[static_cast<size_t>(index)] = cells_.at(index);
    } else {
      SliceFeatures s;
      s.index = index;
      size_t n = 0;
      for (const auto& p : parts) n += p.features().size();
      s.descriptors = cv::Mat(static_cast<int>(n), 32, CV_8U);
      int row = 0;
      for (const auto& p : parts)
        for (const auto& f : p.features()) {
          s.keypoints.push_back(stack.grid.toMetres(f.u(), f.v()));
          std::copy(f.descriptor().begin(), f.descriptor().end(), s.descriptors.ptr<uint8_t>(row++));
        }
      sent_as_features.push_back(std::move(s));
    }
  }
  MapFeatures out = extractFeatures(std::move(stack), params);
  for (auto& s : sent_as_features) out.slices.push_back(std::move(s));
  std::sort(out.slices.begin(), out.slices.end(),
            [](const SliceFeatures& x, const SliceFeatures& y) { return x.index < y.index; });
  return out;
}

}  // namespace tomomap::transport
