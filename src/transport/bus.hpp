#pragma once
// The five tomomap topics on one participant: typed publish calls, and one
// callback per topic for what arrives (called on Fast DDS's listener thread;
// the daemon only queues the sample there).
#include <functional>
#include <memory>

#include "participant.hpp"
#include "tomomap.h"

namespace tomomap::transport {

/// Every writer's heartbeat period [s]: a lost sample is asked for again
/// after the next heartbeat, so a repair takes about one period per attempt.
/// Fast DDS sends periodic heartbeats only while a sample is unacknowledged.
constexpr double kHeartbeatS = 1.0;

struct BusHandlers {
  std::function<void(wire::MapAnnouncement&&)> announcement;
  /// `bytes`: serialised size of the sample, for transfer accounting;
  /// `sequence`: its sequence number in its writer's stream.
  std::function<void(wire::SliceFeatures&&, size_t bytes, uint64_t sequence)> slice;
  std::function<void(wire::ChunkRequest&&)> request;
  std::function<void(wire::MatchClaim&&)> claim;
  std::function<void(wire::TransformEstimate&&)> estimate;
  /// A participant speaking for `agent` appeared (true) or was lost (false).
  std::function<void(const std::string& agent, bool alive)> peer;
  /// A participant that speaks for no agent (senders.hpp): its samples are dropped.
  std::function<void(const std::string& participant, const std::string& why)> refused;
  /// A sample naming `claimed` came from a participant speaking for `sender`
  /// (empty: for none); it was dropped.
  std::function<void(const std::string& claimed, const std::string& sender)> impostor;
};

class Bus {
 public:
  /// Creates the participant and every topic, reader and writer; throws
  /// std::runtime_error if any cannot be created.
  Bus(const TransportConfig& config, BusHandlers handlers);
  ~Bus();  ///< deletes every entity and the participant
  Bus(const Bus&) = delete;
  Bus& operator=(const Bus&) = delete;

  bool publish(const wire::MapAnnouncement& a);
  /// Queues a slice sample behind the flow controller; returns its sequence
  /// number in the slice writer's stream, 0 if the writer's queue stayed full
  /// (try again later).
  uint64_t publish(const wire::SliceFeatures& s);
  bool publish(const wire::ChunkRequest& r);
  bool publish(const wire::MatchClaim& c);
  bool publish(const wire::TransformEstimate& e);
  /// Peers' slice readers matched to our slice writer now.
  size_t sliceReaders() const;
  /// Everything the participant sent, as the pacer counted it on the wire.
  struct Egress {
    uint64_t wire_bytes = 0;         ///< with IP, UDP and Ethernet headers
    uint64_t dropped_datagrams = 0;  ///< their deadline passed while they waited for the link
  };
  Egress egress() const;
  /// Serialised size of a slice sample [bytes].
  static size_t serializedSize(const wire::SliceFeatures& s);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomomap::transport
