#include "slice_encoding.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>

namespace tomomap::transport {
namespace {

void put16(std::vector<uint8_t>& b, uint16_t v) {
  b.push_back(static_cast<uint8_t>(v & 0xff));
  b.push_back(static_cast<uint8_t>(v >> 8));
}

/// `raster` deflated (zlib format) with `strategy`, and, when `max_chain` > 0,
/// level 9's search for earlier matches bounded to that many candidates.
std::vector<uint8_t> deflateWith(const std::vector<uint8_t>& raster, int strategy, int max_chain) {
  z_stream z{};
  if (deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, 15, 8, strategy) != Z_OK) return {};
  // Level 9's own tuning (good 32, lazy 258, nice 258), with a shorter chain.
  if (max_chain > 0) deflateTune(&z, 32, 258, 258, max_chain);
  std::vector<uint8_t> out(deflateBound(&z, static_cast<uLong>(raster.size())));
  z.next_in = const_cast<Bytef*>(raster.data());
  z.avail_in = static_cast<uInt>(raster.size());
  z.next_out = out.data();
  z.avail_out = static_cast<uInt>(out.size());
  const bool done = deflate(&z, Z_FINISH) == Z_STREAM_END;
  out.resize(z.total_out);
  deflateEnd(&z);
  return done ? out : std::vector<uint8_t>{};
}

}  // namespace

size_t rasterBytes(size_t width, size_t height) { return (width * height + 7) / 8; }

std::vector<uint8_t> deflateCells(const std::vector<uint32_t>& cells, int width, int height) {
  std::vector<uint8_t> raster(rasterBytes(static_cast<size_t>(width), static_cast<size_t>(height)), 0);
  for (uint32_t c : cells) raster[c / 8] = static_cast<uint8_t>(raster[c / 8] | (1u << (c % 8)));
  // The smaller of two encodings. Runs of empty bytes are most of a raster,
  // and matching runs alone (Z_RLE) is 150x faster than level 9's chained
  // search on the building's 123 slices (0.01 s against 1.5 s) at 1 % more
  // bytes, and 9 % fewer on the street; level 9 with its chain bounded to 256
  // is 16 % smaller on demo-room's small rooms, at 0.13 s for the building.
  // Either stream inflates alike: receivers of any version read it.
  std::vector<uint8_t> rle = deflateWith(raster, Z_RLE, 0);
  std::vector<uint8_t> searched = deflateWith(raster, Z_DEFAULT_STRATEGY, 256);
  if (rle.empty() || (!searched.empty() && searched.size() < rle.size())) return searched;
  return rle;
}

std::optional<std::vector<uint32_t>> inflateCells(const std::vector<uint8_t>& bytes, int width, int height,
                                                  size_t max_cells, bool* too_many) {
  if (too_many) *too_many = false;
  std::vector<uint8_t> raster(rasterBytes(static_cast<size_t>(width), static_cast<size_t>(height)));
  uLongf size = static_cast<uLongf>(raster.size());
  if (uncompress(raster.data(), &size, bytes.data(), static_cast<uLong>(bytes.size())) != Z_OK || size != raster.size())
    return std::nullopt;
  size_t set = 0;
  for (uint8_t b : raster) set += static_cast<size_t>(__builtin_popcount(b));
  if (set > max_cells) {
    if (too_many) *too_many = true;
    return std::nullopt;
  }
  std::vector<uint32_t> cells;
  cells.reserve(set);
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  for (size_t i = 0; i < raster.size(); ++i)
    for (uint32_t bit = 0; raster[i] >> bit; ++bit)
      if ((raster[i] >> bit) & 1u) {
        if (8 * i + bit >= n) return std::nullopt;  // bits past the raster's end
        cells.push_back(static_cast<uint32_t>(8 * i + bit));
      }
  return cells;
}

std::vector<wire::Feature> featuresToWire(const SliceFeatures& s, const SliceGrid& g) {
  std::vector<wire::Feature> out;
  out.reserve(s.keypoints.size());
  for (size_t i = 0; i < s.keypoints.size(); ++i) {
    wire::Feature w;
    const Eigen::Vector2d px = g.toPixel(s.keypoints[i].x(), s.keypoints[i].y());
    w.u(static_cast<uint16_t>(std::lround(px.x())));
    w.v(static_cast<uint16_t>(std::lround(px.y())));
    std::copy_n(s.descriptors.ptr<uint8_t>(static_cast<int>(i)), 32, w.descriptor().begin());
    out.push_back(w);
  }
  return out;
}

SliceFeatures featuresFromWire(int index, const std::vector<wire::SliceFeatures>& parts, const SliceGrid& grid) {
  SliceFeatures s;
  s.index = index;
  size_t n = 0;
  for (const auto& p : parts) n += p.features().size();
  s.descriptors = cv::Mat(static_cast<int>(n), 32, CV_8U);
  s.keypoints.reserve(n);
  int row = 0;
  for (const auto& p : parts)
    for (const auto& f : p.features()) {
      s.keypoints.push_back(grid.toMetres(f.u(), f.v()));
      std::copy(f.descriptor().begin(), f.descriptor().end(), s.descriptors.ptr<uint8_t>(row++));
    }
  return s;
}

size_t payloadBytes(const wire::SliceFeatures& x) { return x.features().size() * kFeatureBytes + x.occupancy().size(); }

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

}  // namespace tomomap::transport
