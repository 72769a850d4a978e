#include "map_sender.hpp"

#include <algorithm>

#include "transport/participant.hpp"

namespace tomomap::daemon {

MapSender::MapSender(double stream_kbps, Clock::duration grace)
    : kbps_(stream_kbps * (1 - kRepairShare)), grace_(grace) {}

void MapSender::setBudget(double stream_kbps, Clock::duration grace) {
  kbps_ = stream_kbps * (1 - kRepairShare);
  grace_ = grace;
}

void MapSender::setOffer(transport::MapOffer offer) {
  offer_ = std::move(offer);
  queue_.clear();
  queued_.clear();
  next_part_ = 0;
  written_.clear();
  expected_until_.clear();
  informed_.clear();
  queued_since_.reset();
}

bool MapSender::informed(const std::set<std::string>& peers) const {
  return std::includes(informed_.begin(), informed_.end(), peers.begin(), peers.end());
}

Clock::duration MapSender::leaveTime(size_t bytes) const {
  return std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(static_cast<double>(bytes) / transport::bytesPerSecond(kbps_)));
}

size_t MapSender::sliceBytes(int slice) const {
  for (const auto& e : offer_.announcement.slices())
    if (e.slice() == slice) return e.bytes();
  return 0;
}

size_t MapSender::request(const std::string& requester, uint64_t version, const std::vector<int32_t>& slices,
                          Clock::duration stalled, Clock::time_point now, uint64_t received_through) {
  if (version != offer_.announcement.version()) return 0;
  informed_.insert(requester);
  std::vector<int> wanted;
  if (slices.empty())
    for (const auto& e : offer_.announcement.slices()) wanted.push_back(e.slice());
  else
    for (int32_t k : slices)
      if (offer_.samples.count(k)) wanted.push_back(k);

  // Within the requester's window the copies written are still on their way
  // (live, repaired, or from the history if it matched late): only slices
  // never written are queued. A first request never sends again (the
  // requester may have matched after the slices left, and then the history is
  // on its way to it). A request after the window from a requester that has
  // received nothing for kStallBeforeResend sends again what left long enough
  // ago, and opens a new window. A slice whose last copy the requester's
  // reader has passed is sent again at once: Fast DDS acknowledged it and then
  // lost it (a keyed reader that received it out of order now and then never
  // hands it on), and no window would bring it.
  auto [entry, first] = expected_until_.try_emplace(requester);
  Clock::time_point& until = entry->second;
  const bool may_resend = !first && now >= until && stalled >= kStallBeforeResend;
  size_t resent = 0;
  for (int k : wanted) {
    const auto copy = written_.find(k);
    const bool written = copy != written_.end();
    if (written && copy->second.sequence > received_through && (!may_resend || now < copy->second.leaves + grace_))
      continue;
    if (!queued_.insert(k).second) continue;
    queue_.push_back(k);
    resent += written;
  }
  resends_ += resent;
  if (first || resent) {
    // Everything queued leaves first; then a late reader gets the history of
    // what it asked for; losses are repaired after that (kRepairSlack).
    size_t bytes = 0;
    for (int k : queue_) bytes += sliceBytes(k);
    for (int k : wanted)
      if (!queued_.count(k)) bytes += sliceBytes(k);
    until = std::max(backlog_until_, now) +
            std::chrono::duration_cast<Clock::duration>(kRepairSlack * leaveTime(bytes)) + kStallBeforeResend + grace_;
  }
  return wanted.size();
}

bool MapSender::mayStart(size_t matched_readers, size_t alive_peers, Clock::time_point now) {
  if (queue_.empty()) return false;
  if (!queued_since_) queued_since_ = now;
  return matched_readers >= alive_peers || now >= *queued_since_ + kMatchWait;
}

void MapSender::pump(const std::function<uint64_t(const wire::SliceFeatures&)>& publish,
                     const std::function<size_t(const wire::SliceFeatures&)>& size, Clock::time_point now) {
  // Fed no faster than kbps_ and at most kFeedAhead ahead, the controller's
  // queue of new samples runs dry now and then; only then does it send repairs
  // and history for late readers (it serves new samples first).
  while (!queue_.empty() && backlog_until_ <= now + kFeedAhead) {
    const int k = queue_.front();
    const auto& samples = offer_.samples.at(k);
    const wire::SliceFeatures& sample = samples[next_part_];
    const uint64_t sequence = publish(sample);
    if (!sequence) return;
    const size_t bytes = size(sample);
    bytes_sent_ += bytes;
    ++samples_sent_;
    backlog_until_ = std::max(backlog_until_, now) + leaveTime(bytes);
    written_[k] = {backlog_until_, sequence};
    if (++next_part_ == samples.size()) {
      next_part_ = 0;
      queue_.pop_front();
      queued_.erase(k);
    }
  }
  if (queue_.empty()) queued_since_.reset();
}

}  // namespace tomomap::daemon
