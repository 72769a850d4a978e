#include "map_sender.hpp"

#include <algorithm>

namespace tomomap::daemon {

MapSender::MapSender(double stream_kbps, Clock::duration grace) : kbps_(stream_kbps), grace_(grace) {}

void MapSender::setBudget(double stream_kbps, Clock::duration grace) {
  kbps_ = stream_kbps;
  grace_ = grace;
}

void MapSender::setOffer(transport::MapOffer offer) {
  offer_ = std::move(offer);
  queue_.clear();
  queued_.clear();
  next_part_ = 0;
  leaves_at_.clear();
  expected_until_.clear();
  slice_bytes_.clear();
}

Clock::duration MapSender::leaveTime(size_t bytes) const {
  return std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(static_cast<double>(bytes) * 8 / 1000 / kbps_));
}

size_t MapSender::request(const std::string& requester, uint64_t version, const std::vector<int32_t>& slices,
                          Clock::time_point now) {
  if (version != offer_.announcement.version()) return 0;
  std::vector<int> wanted;
  if (slices.empty())
    for (const auto& e : offer_.announcement.slices()) wanted.push_back(e.slice());
  else
    for (int32_t k : slices)
      if (offer_.samples.count(k)) wanted.push_back(k);

  // The first request from this requester since slices were written: it may
  // have matched after they left, and then gets them from the history once
  // the backlog has gone, at the stream's rate.
  size_t written_bytes = 0;
  for (int k : wanted)
    if (const auto b = slice_bytes_.find(k); b != slice_bytes_.end()) written_bytes += b->second;
  auto [expected, first] = expected_until_.try_emplace(requester);
  if (first) expected->second = std::max(backlog_until_, now) + leaveTime(written_bytes) + grace_;
  const bool overdue = now >= expected->second;

  size_t resent = 0;
  for (int k : wanted) {
    const auto left = leaves_at_.find(k);
    if (left != leaves_at_.end()) {
      if (now < left->second + grace_ || !overdue) continue;  // a copy is still on its way
      ++resent;
    }
    if (queued_.insert(k).second) queue_.push_back(k);
  }
  resends_ += resent;
  // What is sent again now is expected once it has left.
  if (resent) expected->second = std::max(backlog_until_, now) + leaveTime(written_bytes) + grace_;
  return wanted.size();
}

void MapSender::pump(const std::function<bool(const wire::SliceFeatures&)>& publish,
                     const std::function<size_t(const wire::SliceFeatures&)>& size, Clock::time_point now) {
  while (!queue_.empty()) {
    const int k = queue_.front();
    const auto& samples = offer_.samples.at(k);
    const wire::SliceFeatures& sample = samples[next_part_];
    if (!publish(sample)) return;
    const size_t bytes = size(sample);
    bytes_sent_ += bytes;
    ++samples_sent_;
    backlog_until_ = std::max(backlog_until_, now) + leaveTime(bytes);
    leaves_at_[k] = backlog_until_;
    if (next_part_ == 0) slice_bytes_[k] = 0;
    slice_bytes_[k] += bytes;
    if (++next_part_ == samples.size()) {
      next_part_ = 0;
      queue_.pop_front();
      queued_.erase(k);
    }
  }
}

}  // namespace tomomap::daemon
