#include "reassembler.hpp"

#include <algorithm>

#include "map_offer.hpp"
#include "slice_encoding.hpp"

namespace tomomap::transport {

size_t announcedMemory(const wire::MapAnnouncement& a) {
  size_t bytes = static_cast<size_t>(a.width()) * a.height();  // the image ORB runs on
  for (const auto& e : a.slices()) bytes += e.bytes();
  return bytes;
}

Rejection fitsBudget(const wire::MapAnnouncement& a, size_t budget) {
  return announcedMemory(a) > budget ? Rejection{Reject::OverBudget} : Rejection{};
}

Reassembler::Reassembler(wire::MapAnnouncement announcement, size_t memory_budget)
    : announcement_(std::move(announcement)),
      budget_(memory_budget),
      announced_memory_(announcedMemory(announcement_)) {
  for (size_t i = 0; i < announcement_.slices().size(); ++i) entries_[announcement_.slices()[i].slice()] = i;
}

Rejection Reassembler::accept(const wire::SliceFeatures& x) {
  if (refused_) return {Reject::OverBudget, x.slice()};
  const auto it = entries_.find(x.slice());
  if (it == entries_.end()) return {Reject::NotAnnounced, x.slice()};
  const wire::SliceEntry& e = announcement_.slices()[it->second];
  if (x.parts() != e.parts() || x.part() >= e.parts()) return {Reject::PartNumbering, x.slice()};
  const bool cells = x.encoding() == wire::SliceEncoding::OCCUPANCY;
  if ((cells && !x.features().empty()) || (!cells && !x.occupancy().empty())) return {Reject::MixedEncoding, x.slice()};
  for (const auto& f : x.features())
    if (f.u() >= announcement_.width() || f.v() >= announcement_.height()) return {Reject::KeypointOutside, x.slice()};
  if (done_.count(x.slice())) return {};  // a duplicate of a verified slice

  Partial& p = partial_[x.slice()];
  p.parts.resize(e.parts());
  auto& slot = p.parts[x.part()];
  if (slot) return {};  // duplicate part
  const size_t bytes = payloadBytes(x);
  size_t held = 0;
  for (const auto& q : p.parts)
    if (q) held += payloadBytes(*q);
  if (held + bytes > e.bytes()) {
    partial_.erase(x.slice());
    return {Reject::LargerThanAnnounced, x.slice()};
  }
  slot = x;
  ++p.received;
  bytes_received_ += bytes;
  if (p.received < e.parts()) return {};

  std::vector<wire::SliceFeatures> parts;
  for (auto& q : p.parts) parts.push_back(std::move(*q));
  partial_.erase(x.slice());
  const auto canonical = canonicalBytes(parts);
  if (canonical.size() != e.bytes() || crcOf(canonical) != e.crc32()) return {Reject::ChecksumMismatch, x.slice()};
  if (parts.front().encoding() == wire::SliceEncoding::OCCUPANCY) {
    const size_t taken = announced_memory_ + cell_bytes_;
    const size_t room = budget_ > taken ? (budget_ - taken) / sizeof(uint32_t) : 0;
    bool too_many = false;
    auto decoded = inflateCells(canonical, announcement_.width(), announcement_.height(), room, &too_many);
    if (too_many) {
      refused_ = true;
      partial_.clear();
      done_.clear();
      cells_.clear();
      cell_bytes_ = 0;
      return {Reject::OverBudget, x.slice()};
    }
    if (!decoded) return {Reject::NotInflating, x.slice()};
    cell_bytes_ += decoded->size() * sizeof(uint32_t);
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
  size_t taken = 0;
  for (int index : unchangedSlices(announcement_, earlier.announcement_)) {
    const auto parts = earlier.done_.find(index);
    if (done_.count(index) || parts == earlier.done_.end()) continue;
    done_[index] = parts->second;
    if (const auto cells = earlier.cells_.find(index); cells != earlier.cells_.end()) {
      cells_[index] = cells->second;
      cell_bytes_ += cells->second.size() * sizeof(uint32_t);
    }
    partial_.erase(index);
    ++taken;
  }
  return taken;
}

MapFeatures Reassembler::build() const {
  const auto& a = announcement_;
  SliceStack stack;
  stack.grid = {a.grid(), a.x_min(), a.y_min(), a.z_min(), a.width(), a.height()};
  stack.cells.resize(static_cast<size_t>(a.slice_count()));
  stack.seen = seenOf(a);
  std::vector<SliceFeatures> sent_as_features;
  for (const auto& [index, parts] : done_) {
    if (parts.front().encoding() == wire::SliceEncoding::OCCUPANCY)
      stack.cells[static_cast<size_t>(index)] = cells_.at(index);
    else
      sent_as_features.push_back(featuresFromWire(index, parts, stack.grid));
  }
  stack.partial = !sent_as_features.empty();
  MapFeatures out = extractFeatures(std::move(stack), featureParamsOf(a));
  // Levelled by its sender: the transforms between the maps' own frames undo it.
  if (const Eigen::Vector3d up = upOf(a); up != Eigen::Vector3d::UnitZ()) {
    out.tilt = givenTilt(up);
    out.leveled = true;
  }
  for (auto& s : sent_as_features) out.slices.push_back(std::move(s));
  std::sort(out.slices.begin(), out.slices.end(),
            [](const SliceFeatures& x, const SliceFeatures& y) { return x.index < y.index; });
  return out;
}

}  // namespace tomomap::transport
