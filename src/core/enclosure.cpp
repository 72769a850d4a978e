#include "enclosure.hpp"

namespace tomomap {
namespace {

/// Per slice, the lowest and highest slice of its storey: the run of seen
/// slices around it (an unseen slice is a storey of its own, enclosing nothing).
std::vector<std::pair<int, int>> storeysOf(const SliceStack& s) {
  std::vector<std::pair<int, int>> out(static_cast<size_t>(s.size()));
  for (const SliceRun& run : seenRuns(s))
    for (int k = run.first; k <= run.last; ++k)
      out[static_cast<size_t>(k)] = run.seen ? std::pair{run.first, run.last} : std::pair{k, k};
  return out;
}

}  // namespace

Enclosure::Enclosure(const SliceStack& s)
    : lowest_(static_cast<size_t>(s.grid.width) * static_cast<size_t>(s.grid.height), UINT16_MAX),
      highest_(lowest_.size(), 0),
      storey_(storeysOf(s)) {
  // A stack has at most kMaxImageSide slices (makeSlices; transport's
  // validate for a peer's): they fit 16 bits.
  for (int k = 0; k < s.size(); ++k)
    for (uint32_t idx : s.cells[static_cast<size_t>(k)]) {
      lowest_[idx] = std::min(lowest_[idx], static_cast<uint16_t>(k));
      highest_[idx] = static_cast<uint16_t>(k);
    }
  // Only a column of a map of more than one storey may reach past its own.
  if (!storey_.empty() && storey_.front().second + 1 < s.size()) indexColumns(s);
}

void Enclosure::indexColumns(const SliceStack& s) {
  first_.assign(lowest_.size() + 1, 0);
  for (const auto& cells : s.cells)
    for (uint32_t idx : cells) ++first_[idx + 1];
  for (size_t p = 1; p < first_.size(); ++p) first_[p] += first_[p - 1];
  slices_.resize(first_.back());
  std::vector<uint32_t> next(first_.begin(), first_.end() - 1);
  for (int k = 0; k < s.size(); ++k)
    for (uint32_t idx : s.cells[static_cast<size_t>(k)]) slices_[next[idx]++] = static_cast<uint16_t>(k);
}

}  // namespace tomomap
