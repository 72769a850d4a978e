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
}

size_t MapSender::request(uint64_t version, const std::vector<int32_t>& slices, Clock::time_point now) {
  if (version != offer_.announcement.version()) return 0;
  std::vector<int> wanted;
  if (slices.empty())
    for (const auto& e : offer_.announcement.slices()) wanted.push_back(e.slice());
  else
    for (int32_t k : slices)
      if (offer_.samples.count(k)) wanted.push_back(k);
  for (int k : wanted) {
    const auto leaving = leaves_at_.find(k);
    if (leaving != leaves_at_.end() && now < leaving->second + grace_) continue;  // still on its way
    if (queued_.insert(k).second) queue_.push_back(k);
  }
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
    backlog_until_ = std::max(backlog_until_, now) +
                     std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(static_cast<double>(bytes) * 8 / 1000 / kbps_));
    leaves_at_[k] = backlog_until_;
    if (++next_part_ == samples.size()) {
      next_part_ = 0;
      queue_.pop_front();
      queued_.erase(k);
    }
  }
}

}  // namespace tomomap::daemon
