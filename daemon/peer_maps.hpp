#pragma once
// The peers' maps as they arrive: one reassembler per peer at its latest
// announced version, the requests for what is still missing, and the history
// of finished transfers. Everything about one peer is one PeerState, so a
// peer dropped from the config leaves nothing behind. No DDS: requests are
// returned for the caller to send.
#include <chrono>
#include <deque>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <vector>

#include "clock.hpp"
#include "log.hpp"
#include "transport/participant.hpp"
#include "transport/reassembler.hpp"

namespace tomomap::daemon {

class PeerMaps {
 public:
  /// `memory_budget`: bytes one peer's map may take (peer_memory_mb).
  PeerMaps(std::string me, const Log& log, size_t memory_budget)
      : me_(std::move(me)), log_(log), memory_budget_(memory_budget) {}
  void setMemoryBudget(size_t bytes) { memory_budget_ = bytes; }
  size_t memoryBudget() const { return memory_budget_; }

  /// What a new announcement led to.
  struct Announced {
    bool new_version = false;                   ///< false: a version we know already (nothing else happened)
    bool complete = false;                      ///< every slice was kept from the previous version
    std::optional<wire::ChunkRequest> request;  ///< to send to the owner
  };
  /// A validated announcement of a peer's map.
  Announced announce(wire::MapAnnouncement a, Clock::time_point now);

  struct Received {
    transport::Rejection rejection;
    bool completed = false;  ///< this sample completed the map: features() holds it now
    bool first = false;      ///< the first sample of this version
  };
  /// A slice sample from its owner (`bytes` on the wire, `sequence` its
  /// number in the owner's slice writer's stream). Samples of a version not
  /// announced yet are held until it is (holdEarly); samples of maps already
  /// complete are ignored.
  Received receive(const wire::SliceFeatures& s, size_t bytes, uint64_t sequence, Clock::time_point now);

  /// Requests for the maps still incomplete that have made no progress for
  /// `interval`. Each request without progress since doubles the wait before
  /// the next (up to 16 x): on a thin link a transfer that is merely slow must
  /// not be asked for again and again, since every resend reaches every
  /// receiver. And, to a live peer whose announcement has not come within
  /// kAnnouncementWait (durability misses a late reader now and then, Fast
  /// DDS #3822, and a restarted peer lost it), a request of version 0: "your
  /// announcement, please", backing off alike.
  std::vector<wire::ChunkRequest> due(Clock::duration interval, Clock::time_point now);
  /// The version a request names when the requester holds no announcement of the owner's.
  static constexpr uint64_t kNoVersion = 0;
  /// The request for `owner`'s map at once, if we still lack some of it: its
  /// participant has just come, so what we asked it before may never have
  /// reached it. Not the other owners: they heard us, and a request reaches
  /// every receiver.
  std::optional<wire::ChunkRequest> askNow(const std::string& owner, Clock::time_point now);

  std::shared_ptr<const MapFeatures> features(const std::string& peer) const;
  /// The latest version `peer` announced, held or not.
  std::optional<uint64_t> version(const std::string& peer) const;

  /// Discovery: a peer's participant came (true) or went; returns whether
  /// that changed anything. Either way its writer's sequence numbers start
  /// anew (a restarted peer has a new participant).
  bool setAlive(const std::string& peer, bool alive);
  size_t aliveCount() const;
  std::set<std::string> alive() const;
  /// A sample from `peer` arrived (wall time, for status).
  void seen(const std::string& peer, uint64_t wall_ms) { peers_[peer].last_seen_ms = wall_ms; }
  /// Drops everything about every peer `keep` rejects (a reload removed it
  /// from the config): its PeerState, whole.
  template <typename Keep>
  void retain(Keep keep) {
    for (auto it = peers_.begin(); it != peers_.end();) it = keep(it->first) ? std::next(it) : peers_.erase(it);
  }
  /// Every peer gone (this agent left the network): sequence numbers start anew too.
  void clearAlive();

  /// Progress over every peer: maps complete, slices received and announced.
  struct Totals {
    size_t maps = 0, slices_done = 0, slices_all = 0;
  };
  Totals totals() const;
  /// status.json's entry for one configured peer.
  nlohmann::json status(const transport::PeerAddress& peer) const;

 private:
  /// The transfer of a peer's latest announced version.
  struct Peer {
    std::optional<transport::Reassembler> incoming;  ///< the latest announced version
    std::shared_ptr<const MapFeatures> features;     ///< once complete
    Clock::time_point last_progress{}, last_request{};
    Clock::time_point requested{};  ///< when this version was first asked for: the transfer's start
    Clock::time_point first_slice{}, last_slice{};
    size_t bytes = 0, samples = 0;
    size_t reused = 0;   ///< slices kept from the previous version
    int unanswered = 0;  ///< requests since the last progress
  };
  /// A finished transfer of one version of a peer's map.
  struct Transfer {
    uint64_t version = 0;
    size_t slices = 0, reused = 0, bytes = 0;
    double seconds = 0;
  };
  /// Slices that came before their version's announcement. Announcements and
  /// slices travel on different topics, so a receiver may hear a stream that
  /// started for another peer before it hears what it belongs to; dropped,
  /// those samples counted as delivered for RTPS and were resent only after
  /// a long stall. Held per owner for one version, up to the memory budget.
  struct Early {
    uint64_t version = 0;
    Clock::time_point since{};  ///< first sample held
    struct Held {
      wire::SliceFeatures sample;
      size_t bytes = 0;       ///< on the wire
      uint64_t sequence = 0;  ///< in the owner's slice writer's stream
    };
    std::vector<Held> samples;
    size_t bytes = 0;
  };
  /// Live peers whose announcement has not come: since when (or since the
  /// last ask), and how many times asked.
  struct Unannounced {
    Clock::time_point since{};
    int asked = 0;
  };
  /// Everything this agent knows of one peer.
  struct PeerState {
    Peer map;  ///< its latest announced version, as it arrives
    Early early;
    /// The highest sequence number of its slice writer among the samples
    /// taken in (wire::ChunkRequest::received_through); 0: none since its
    /// participant appeared.
    uint64_t received_through = 0;
    std::deque<Transfer> transfers;  ///< finished transfers, latest last
    bool alive = false;
    std::optional<Unannounced> unannounced;  ///< while alive and its announcement has not come
    std::optional<uint64_t> last_seen_ms;
  };
  /// A sample numbered `sequence` of `owner`'s stream was taken in.
  static void noteTaken(PeerState& owner, uint64_t sequence);
  /// Counts an accepted sample of `bytes` as progress; returns whether it is the version's first.
  static bool tally(Peer& p, size_t bytes, Clock::time_point now);
  /// Holds a sample of an unannounced version of `owner`'s map.
  void holdEarly(PeerState& owner, const wire::SliceFeatures& s, size_t bytes, uint64_t sequence,
                 Clock::time_point now) const;
  /// Takes in the held samples of the version just announced; returns how many.
  size_t takeEarly(const std::string& id, PeerState& owner, Clock::time_point now);
  /// Builds a peer's map once every slice is in, and records the transfer.
  void complete(const std::string& id, PeerState& owner);
  wire::ChunkRequest requestFor(const std::string& id, const PeerState& owner, bool everything,
                                Clock::time_point now) const;
  /// Whether `p`'s map is announced, still incomplete, and not refused.
  static bool waiting(const Peer& p);
  /// The request for what `p` still lacks, counted as unanswered until progress.
  wire::ChunkRequest askAgain(const std::string& id, PeerState& owner, Clock::time_point now);
  /// Transfer rate so far [kbit/s]: bytes over the flow-control periods they
  /// took (the first period's budget leaves at once, so the time from the first
  /// to the last sample is one period short).
  static double rateKbps(const Peer& p);

  std::string me_;
  const Log& log_;
  size_t memory_budget_;
  std::map<std::string, PeerState> peers_;
};

}  // namespace tomomap::daemon
