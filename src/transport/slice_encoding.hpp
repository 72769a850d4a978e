#pragma once
// One slice on the wire: its features as raster pixels and descriptors, or its
// occupancy as a deflated bit raster, and the canonical bytes a CRC covers.
#include <cstdint>
#include <optional>
#include <vector>

#include "core/features.hpp"
#include "tomomap.h"
#include "wire_sizes.hpp"

namespace tomomap::transport {

/// Bytes of a width x height bit raster.
size_t rasterBytes(size_t width, size_t height);

/// A slice's occupied cells (pixel indices) as a bit raster, deflated (zlib,
/// best compression). Walls are long runs of set bits or one bit repeated row
/// after row, which deflate stores in a few bytes where a list of cells would
/// take 4 each. Empty on a zlib failure.
std::vector<uint8_t> deflateCells(const std::vector<uint32_t>& cells, int width, int height);

/// The inverse; nullopt when the bytes do not inflate to exactly the raster,
/// or when the raster holds more than `max_cells` set cells (checked before
/// the cell list is allocated: `*too_many` tells which).
std::optional<std::vector<uint32_t>> inflateCells(const std::vector<uint8_t>& bytes, int width, int height,
                                                  size_t max_cells = SIZE_MAX, bool* too_many = nullptr);

/// A slice's keypoints as pixels of `grid` with their descriptors. Keypoints
/// sit on pixel centres (single-level ORB), so the round trip is exact.
std::vector<wire::Feature> featuresToWire(const SliceFeatures& s, const SliceGrid& grid);

/// The slice `index` from the features of its parts, back in metres.
SliceFeatures featuresFromWire(int index, const std::vector<wire::SliceFeatures>& parts, const SliceGrid& grid);

/// Payload bytes of one sample (features or occupancy; not its header fields).
size_t payloadBytes(const wire::SliceFeatures& sample);

/// The canonical bytes of a slice's payload, over which its CRC is taken.
std::vector<uint8_t> canonicalBytes(const std::vector<wire::SliceFeatures>& parts);

uint32_t crcOf(const std::vector<uint8_t>& bytes);

}  // namespace tomomap::transport
