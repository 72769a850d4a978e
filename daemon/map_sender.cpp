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
  // Peers holding the version we offered so far will ask for the changed slices only.
  if (!offer_.announcement.slices().empty()) transport::bundleOffer(offer, &offer_.announcement);
  offer_ = std::move(offer);
  queue_.clear();
  queued_.clear();
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

size_t MapSender::bundleBytes(size_t bundle) const { return transport::Bus::serializedSize(offer_.bundles[bundle]); }

size_t MapSender::request(const std::string& requester, uint64_t version, const std::vector<int32_t>& slices,
                          Clock::duration stalled, Clock::time_point now, uint64_t received_through) {
  if (version != offer_.announcement.version()) return 0;
  informed_.insert(requester);
  // The wanted slices, in the order asked (each once).
  std::vector<int32_t> wanted;
  if (slices.empty())
    for (const auto& e : offer_.announcement.slices()) wanted.push_back(e.slice());
  else
    for (int32_t k : slices)
      if (offer_.bundles_of.count(k) && std::find(wanted.begin(), wanted.end(), k) == wanted.end()) wanted.push_back(k);

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
  std::set<size_t> carriers;  // the samples that carry the wanted slices
  for (int32_t k : wanted) {
    // A slice is on its way while its latest copy is (a sample may carry
    // pieces of several slices: a slice's last part rides in another's).
    const Written* latest = nullptr;
    for (size_t b : offer_.bundles_of.at(k)) {
      carriers.insert(b);
      const auto copy = written_.find(b);
      if (copy != written_.end() && (!latest || copy->second.sequence > latest->sequence)) latest = &copy->second;
    }
    const bool on_its_way =
        latest && latest->sequence > received_through && (!may_resend || now < latest->leaves + grace_);
    for (size_t b : offer_.bundles_of.at(k)) {
      const bool written = written_.count(b) > 0;
      if ((written && on_its_way) || !queued_.insert(b).second) continue;
      queue_.push_back(b);
      resent += written;
    }
  }
  resends_ += resent;
  if (first || resent) {
    // Everything queued leaves first; then a late reader gets the history of
    // what it asked for; losses are repaired after that (kRepairSlack).
    size_t bytes = 0;
    for (size_t k : queue_) bytes += bundleBytes(k);
    for (size_t k : carriers)
      if (!queued_.count(k)) bytes += bundleBytes(k);
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
    const size_t k = queue_.front();
    const wire::SliceFeatures& sample = offer_.bundles[k];
    const uint64_t sequence = publish(sample);
    if (!sequence) return;
    const size_t bytes = size(sample);
    bytes_sent_ += bytes;
    ++samples_sent_;
    backlog_until_ = std::max(backlog_until_, now) + leaveTime(bytes);
    written_[k] = {backlog_until_, sequence};
    queue_.pop_front();
    queued_.erase(k);
  }
  if (queue_.empty()) queued_since_.reset();
}

}  // namespace tomomap::daemon
