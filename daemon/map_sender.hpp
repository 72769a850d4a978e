#pragma once
// Sending this agent's map: which slices peers asked for, in what order, and
// when a copy already written will have reached the peer that asks, so that a
// request for a slice still on its way does not send it again. Pure: the
// publish call and the time are passed in.
//
// What reaches whom (docs/protocol.md): a written sample goes to every reader
// matched at the time, is repaired by RTPS where lost, and stays in the
// writer's durable history, from which a reader that matches later gets it,
// sent to that reader alone. So a request for a slice already written is
// answered by sending it again only once the copy the requester can still
// expect is overdue.
#include <chrono>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "clock.hpp"
#include "transport/bus.hpp"
#include "transport/map_offer.hpp"

namespace tomomap::daemon {

class MapSender {
 public:
  /// `stream_kbps`: the rate the flow controller lets each written byte leave
  /// at (transport::streamKbps), of which new samples get 1 - kRepairShare;
  /// `grace`: how long after a copy's expected arrival a request for it is
  /// still taken as crossed.
  MapSender(double stream_kbps, Clock::duration grace);
  void setBudget(double stream_kbps, Clock::duration grace);

  /// A new map to offer: what was queued belongs to the old version and is
  /// dropped (peers ask again for what they need).
  void setOffer(transport::MapOffer offer);
  const transport::MapOffer& offer() const { return offer_; }
  uint64_t version() const { return offer_.announcement.version(); }

  /// Peer `requester` asked for `slices` (every announced slice when empty) of
  /// `version`, having received nothing of it for `stalled` and the writer's
  /// samples up to sequence number `received_through`. Queues those never
  /// written, those whose last copy the requester's reader has passed (it was
  /// lost inside the reader: a reliable reader delivers in order), and those
  /// whose copy is overdue at the requester; returns how many of them this
  /// map has (0 for another version: the announcement tells them).
  size_t request(const std::string& requester, uint64_t version, const std::vector<int32_t>& slices,
                 Clock::duration stalled, Clock::time_point now, uint64_t received_through = 0);

  /// Peers that asked for slices of the current version hold its
  /// announcement; `forget` one that restarted (it lost it).
  void forget(const std::string& peer) { informed_.erase(peer); }
  /// Whether every one of `peers` holds the current announcement: announcing
  /// it again would reach no one who needs it.
  bool informed(const std::set<std::string>& peers) const;

  /// Whether to start sending what is queued: once every live peer's reader
  /// has matched the writer (a reader that matches later gets the slices
  /// from the history, but only after everything else queued), or after
  /// kMatchWait.
  bool mayStart(size_t matched_readers, size_t alive_peers, Clock::time_point now);

  /// Hands queued samples to `publish` in order, paced at the stream's rate for
  /// new samples and at most kFeedAhead ahead of `now`, until it refuses one
  /// (returns 0: the writer is full): the rest goes on later calls. `publish`
  /// returns the sample's sequence number; `size` gives its bytes on the wire.
  void pump(const std::function<uint64_t(const wire::SliceFeatures&)>& publish,
            const std::function<size_t(const wire::SliceFeatures&)>& size, Clock::time_point now);

  size_t queued() const { return queue_.size(); }
  size_t bytesSent() const { return bytes_sent_; }
  size_t samplesSent() const { return samples_sent_; }
  /// Samples written again because a requester's copy was overdue.
  size_t resends() const { return resends_; }

 private:
  /// Repairs of lost samples follow the rest: a window is this many times
  /// the time its bytes take to leave, plus kStallBeforeResend.
  static constexpr double kRepairSlack = 1.5;
  /// Ten heartbeat rounds of RTPS repairs (at 30 % loss of data, heartbeats
  /// and acknowledgements alike a repair succeeds in one round one time in
  /// three; ten rounds fail for 1.5 %). A requester that received something
  /// within this time is being repaired by RTPS (a reader delivers in order:
  /// one gap holds back what follows), and a window includes it.
  static constexpr double kRepairRounds = 10;
  static constexpr Clock::duration kStallBeforeResend = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(kRepairRounds * transport::kHeartbeatS));
  /// Share of the stream's rate kept free of new samples, for RTPS repairs
  /// and for the history a late reader gets: the flow controller serves those
  /// only when no new sample waits, and a reader delivers in order, so a
  /// repair held back to the end of the map stalled everything after a loss.
  static constexpr double kRepairShare = 0.15;
  static constexpr Clock::duration kFeedAhead = std::chrono::milliseconds(500);
  static constexpr Clock::duration kMatchWait = std::chrono::seconds(5);

  Clock::duration leaveTime(size_t bytes) const;
  size_t bundleBytes(size_t bundle) const;  ///< serialized bytes of a written sample

  double kbps_;
  Clock::duration grace_;
  transport::MapOffer offer_;
  std::deque<size_t> queue_;  ///< samples to send (indices into offer_.bundles), in order
  std::set<size_t> queued_;
  /// When the flow controller will have sent everything handed to it so far,
  /// and when each written sample's last copy leaves it.
  Clock::time_point backlog_until_{};
  struct Written {
    Clock::time_point leaves{};  ///< when its last copy leaves the controller
    uint64_t sequence = 0;       ///< the writer's sequence number of its last copy
  };
  std::map<size_t, Written> written_;
  /// Per requester: until when copies already written may still be on their
  /// way to it (a late reader gets the history after the backlog).
  std::map<std::string, Clock::time_point> expected_until_;
  std::set<std::string> informed_;                 ///< peers that asked for the current version
  std::optional<Clock::time_point> queued_since_;  ///< when the queue last had something waiting to start
  size_t bytes_sent_ = 0, samples_sent_ = 0, resends_ = 0;
};

}  // namespace tomomap::daemon
