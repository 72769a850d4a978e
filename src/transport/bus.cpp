#include "bus.hpp"

#include <fastdds/rtps/common/WriteParams.h>

#include <algorithm>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <map>
#include <mutex>
#include <stdexcept>

#include "bundling.hpp"
#include "egress_pacer.hpp"
#include "senders.hpp"
#include "tomomapPubSubTypes.h"

namespace tomomap::transport {

using namespace eprosima::fastdds::dds;

namespace {

ParticipantKey prefixOf(const eprosima::fastrtps::rtps::GuidPrefix_t& p) {
  ParticipantKey out{};
  std::copy(std::begin(p.value), std::end(p.value), out.begin());
  return out;
}

// The agent each sample speaks for.
std::string claimedSender(const wire::MapAnnouncement& a) { return a.agent().to_string(); }
std::string claimedSender(const wire::SliceFeatures& s) { return s.agent().to_string(); }
std::string claimedSender(const wire::ChunkRequest& r) { return r.requester().to_string(); }
std::string claimedSender(const wire::MatchClaim& c) { return c.claimer().to_string(); }
std::string claimedSender(const wire::TransformEstimate& e) { return e.computed_by().to_string(); }

/// Takes every sample as it arrives and hands on those whose writer's
/// participant speaks for the agent the sample names.
template <typename T>
class Listener : public DataReaderListener {
 public:
  /// `on` gets each sample and its sequence number in its writer's stream.
  Listener(const SenderDirectory& senders, std::function<void(T&&, uint64_t)> on, const BusHandlers& h)
      : senders_(senders), on_(std::move(on)), impostor_(h.impostor) {}
  void on_data_available(DataReader* reader) override {
    T sample;
    SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const auto sender = senders_.agentOf(prefixOf(info.sample_identity.writer_guid().guidPrefix));
      const std::string claimed = claimedSender(sample);
      if (!sender || *sender != claimed) {
        if (impostor_) impostor_(claimed, sender.value_or(""));
        continue;
      }
      if (on_) on_(std::move(sample), info.sample_identity.sequence_number().to64long());
    }
  }

 private:
  const SenderDirectory& senders_;
  std::function<void(T&&, uint64_t)> on_;
  std::function<void(const std::string&, const std::string&)> impostor_;
};

/// Binds participants to agents (senders.hpp, Admission) and reports peers
/// coming and going. Fast DDS calls it on its own threads.
class ParticipantWatch : public DomainParticipantListener {
 public:
  ParticipantWatch(SenderDirectory& senders, bool secure, const BusHandlers& h)
      : senders_(senders), admission_(secure), peer_(h.peer), refused_(h.refused) {}

  void on_participant_discovery(DomainParticipant*,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    using S = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;
    const auto prefix = prefixOf(info.info.m_guid.guidPrefix);
    if (info.status == S::DISCOVERED_PARTICIPANT) {
      std::unique_lock<std::mutex> lock(mutex_);
      const auto b = admission_.discovered(prefix, info.info.m_participantName.to_string(), subjectOf(info.info));
      lock.unlock();
      apply(prefix, b);
    }
    if (info.status == S::REMOVED_PARTICIPANT || info.status == S::DROPPED_PARTICIPANT) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        admission_.gone(prefix);
      }
      const auto agent = senders_.agentOf(prefix);
      senders_.forget(prefix);
      if (agent && peer_) peer_(*agent, false);
    }
  }

  void onParticipantAuthentication(DomainParticipant*,
                                   eprosima::fastrtps::rtps::ParticipantAuthenticationInfo&& info) override {
    using A = eprosima::fastrtps::rtps::ParticipantAuthenticationInfo;
    const auto prefix = prefixOf(info.guid.guidPrefix);
    std::unique_lock<std::mutex> lock(mutex_);
    if (info.status == A::UNAUTHORIZED_PARTICIPANT) {
      const std::string name = admission_.failed(prefix);
      lock.unlock();
      if (refused_) refused_(name, "a handshake failed (no certificate of this fleet's CA, or no permission)");
      return;
    }
    const auto b = admission_.authenticated(prefix);
    lock.unlock();
    apply(prefix, b);
  }

 private:
  void apply(const ParticipantKey& prefix, const std::optional<Binding>& b) {
    if (!b) return;
    if (!b->agent) {
      if (refused_) refused_(b->participant, b->refusal);
      return;
    }
    senders_.bind(prefix, *b->agent);
    if (peer_) peer_(*b->agent, true);
  }

  /// The subject of the certificate the participant authenticated with: its
  /// identity token carries it, and PKI-DH fails a participant whose
  /// certificate's subject differs from its token's. Empty if absent.
  static std::string subjectOf(const eprosima::fastrtps::rtps::ParticipantProxyData& p) {
    for (const auto& property : p.identity_token_.properties())
      if (property.name() == "dds.cert.sn") return property.value();
    return "";
  }

  SenderDirectory& senders_;
  std::mutex mutex_;
  Admission admission_;  ///< under mutex_
  std::function<void(const std::string&, bool)> peer_;
  std::function<void(const std::string&, const std::string&)> refused_;
};

/// A handler of samples that has no use for their sequence numbers.
template <typename T>
std::function<void(T&&, uint64_t)> bySample(std::function<void(T&&)> on) {
  if (!on) return {};
  return [on = std::move(on)](T&& sample, uint64_t) { on(std::move(sample)); };
}

/// QoS shared by the small control topics.
struct TopicQos {
  bool transient_local = false;
  bool keep_all = false;
  int depth = 1;
  int max_samples = 1024;
  int max_instances = 1024;
  bool best_effort = false;
};

/// The latest sample of each of `instances` instances (keep last 1),
/// reliable; kept for late joiners where `for_late_joiners` (transient local).
TopicQos latestOfEach(int instances, bool for_late_joiners) {
  TopicQos t;
  t.transient_local = for_late_joiners;
  t.max_instances = instances;
  return t;
}

/// Up to `samples` samples of one instance, best effort, none kept for late joiners.
TopicQos everySampleBestEffort(int samples) {
  TopicQos t;
  t.keep_all = true;
  t.max_samples = samples;
  t.max_instances = 1;
  t.best_effort = true;
  return t;
}

/// What writer and reader of a topic agree on: reliable, durability, history
/// and its limits, and samples allocated at their real size (not the IDL bound).
template <typename EndpointQos>
EndpointQos endpointQos(EndpointQos q, const TopicQos& t) {
  q.reliability().kind = t.best_effort ? BEST_EFFORT_RELIABILITY_QOS : RELIABLE_RELIABILITY_QOS;
  q.durability().kind = t.transient_local ? TRANSIENT_LOCAL_DURABILITY_QOS : VOLATILE_DURABILITY_QOS;
  q.history().kind = t.keep_all ? KEEP_ALL_HISTORY_QOS : KEEP_LAST_HISTORY_QOS;
  q.history().depth = t.depth;
  q.resource_limits().max_instances = t.max_instances;
  q.resource_limits().max_samples_per_instance = t.keep_all ? t.max_samples : t.depth;
  q.resource_limits().max_samples = t.keep_all ? t.max_samples : t.max_instances * t.depth;
  q.endpoint().history_memory_policy = eprosima::fastrtps::rtps::DYNAMIC_REUSABLE_MEMORY_MODE;
  return q;
}

DataWriterQos writerQos(const TopicQos& t) {
  DataWriterQos q = endpointQos(DATAWRITER_QOS_DEFAULT, t);
  q.reliability().max_blocking_time = eprosima::fastrtps::Duration_t(0, 200000000);
  // Repairs follow heartbeats (every 3 s by default): ask often, so a lost
  // sample is sent again within a second or two. With 10 % loss an estimate
  // lost on its way took 6 s more to reach one of two peers with the default.
  q.reliable_writer_qos().times.heartbeatPeriod = eprosima::fastrtps::Duration_t(kHeartbeatS);
  return q;
}

/// Slice parts (instances: owner, slice, part) a writer or reader keeps: the
/// writer one map's worth, the reader every peer's. 65,536 parts are 64 MB of
/// payload at the smallest sample size, far above any map sent so far.
constexpr int kSliceInstances = 1 << 16;

constexpr double kNackSuppressionMs = 500;  ///< longer than a link's round trip plus a queue's wait

}  // namespace

struct Bus::Impl {
  std::shared_ptr<EgressPacer> pacer;
  DomainParticipant* participant = nullptr;
  Publisher* publisher = nullptr;
  Subscriber* subscriber = nullptr;
  SenderDirectory senders;
  BusHandlers handlers;
  std::unique_ptr<ParticipantWatch> watch;
  std::vector<std::unique_ptr<DataReaderListener>> listeners;
  DataWriter *announcements = nullptr, *slices = nullptr, *requests = nullptr, *claims = nullptr, *estimates = nullptr;

  template <typename PubSub, typename T>
  DataWriter* addTopic(const std::string& name, const TopicQos& tq, std::function<void(T&&, uint64_t)> on,
                       bool flow_controlled = false) {
    TypeSupport type(new PubSub());
    if (type.register_type(participant) != ReturnCode_t::RETCODE_OK)
      throw std::runtime_error("cannot register type for " + name);
    Topic* topic = participant->create_topic(name, type.get_type_name(), TOPIC_QOS_DEFAULT);
    if (!topic) throw std::runtime_error("cannot create topic " + name);
    DataWriterQos wq = writerQos(tq);
    if (flow_controlled) {
      wq.publish_mode().kind = ASYNCHRONOUS_PUBLISH_MODE;
      wq.publish_mode().flow_controller_name = kFlowControllerName;
      // A reader repeats its negative acknowledgement with every heartbeat
      // until the repair arrives; with a link delay and a queue in front of
      // the repair, each repeat sent the sample again (10 % loss and 50 ms
      // delay: up to 11 x the map on the wire). Repeats within this time of a
      // repair's departure are ignored.
      wq.reliable_writer_qos().times.nackSupressionDuration =
          eprosima::fastrtps::Duration_t(kNackSuppressionMs / 1000.0);
    }
    DataWriter* w = publisher->create_datawriter(topic, wq);
    if (!w) throw std::runtime_error("cannot create the writer of " + name);
    listeners.push_back(std::make_unique<Listener<T>>(senders, std::move(on), handlers));
    if (!subscriber->create_datareader(topic, endpointQos(DATAREADER_QOS_DEFAULT, tq), listeners.back().get()))
      throw std::runtime_error("cannot create the reader of " + name);
    return w;
  }
};

Bus::Bus(const TransportConfig& config, BusHandlers h) : impl_(std::make_unique<Impl>()) {
  auto& i = *impl_;
  i.handlers = h;
  i.watch = std::make_unique<ParticipantWatch>(i.senders, config.security.enabled(), i.handlers);
  i.pacer = std::make_shared<EgressPacer>(bytesPerSecond(pacedKbps(config)));
  i.participant = createParticipant(config, i.pacer, i.watch.get());
  i.senders.bind(prefixOf(i.participant->guid().guidPrefix), config.agent);  // our own samples
  try {
    i.publisher = i.participant->create_publisher(PUBLISHER_QOS_DEFAULT);
    i.subscriber = i.participant->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
    if (!i.publisher || !i.subscriber) throw std::runtime_error("cannot create publisher/subscriber");
    // Announcements and estimates: one per agent / pair, kept for late joiners.
    i.announcements = i.addTopic<wire::MapAnnouncementPubSubType, wire::MapAnnouncement>(
        "tomomap/announcements", latestOfEach(256, true), bySample(h.announcement));
    i.slices = i.addTopic<wire::SliceFeaturesPubSubType, wire::SliceFeatures>(
        "tomomap/slices", latestOfEach(kSliceInstances, true),
        [on = h.slice](wire::SliceFeatures&& s, uint64_t sequence) {
          if (!on) return;
          for (auto& piece : unbundle(std::move(s))) {
            const size_t bytes = serializedSize(piece);
            on(std::move(piece), bytes, sequence);
          }
        },
        /*flow_controlled=*/true);
    // Requests: best effort, since a receiver repeats them while it lacks
    // something, and a reliable one delivered after a dropout was stale.
    i.requests = i.addTopic<wire::ChunkRequestPubSubType, wire::ChunkRequest>(
        "tomomap/requests", everySampleBestEffort(256), bySample(h.request));
    // Claims: only the current one matters, and only to those listening now.
    i.claims = i.addTopic<wire::MatchClaimPubSubType, wire::MatchClaim>("tomomap/claims", latestOfEach(1024, false),
                                                                        bySample(h.claim));
    i.estimates = i.addTopic<wire::TransformEstimatePubSubType, wire::TransformEstimate>(
        "tomomap/estimates", latestOfEach(1024, true), bySample(h.estimate));
  } catch (...) {
    i.participant->delete_contained_entities();
    DomainParticipantFactory::get_instance()->delete_participant(i.participant);
    throw;
  }
}

Bus::~Bus() {
  auto& i = *impl_;
  i.participant->set_listener(nullptr);
  i.participant->delete_contained_entities();
  DomainParticipantFactory::get_instance()->delete_participant(i.participant);
}

bool Bus::publish(const wire::MapAnnouncement& a) {
  return impl_->announcements->write(const_cast<wire::MapAnnouncement*>(&a));
}
uint64_t Bus::publish(const wire::SliceFeatures& s) {
  eprosima::fastrtps::rtps::WriteParams params;
  if (!impl_->slices->write(const_cast<wire::SliceFeatures*>(&s), params)) return 0;
  return params.sample_identity().sequence_number().to64long();
}
bool Bus::publish(const wire::ChunkRequest& r) { return impl_->requests->write(const_cast<wire::ChunkRequest*>(&r)); }
bool Bus::publish(const wire::MatchClaim& c) { return impl_->claims->write(const_cast<wire::MatchClaim*>(&c)); }
bool Bus::publish(const wire::TransformEstimate& e) {
  return impl_->estimates->write(const_cast<wire::TransformEstimate*>(&e));
}

Bus::Egress Bus::egress() const { return {impl_->pacer->sentBytes(), impl_->pacer->refusedDatagrams()}; }

size_t Bus::sliceReaders() const {
  PublicationMatchedStatus status;
  if (impl_->slices->get_publication_matched_status(status) != ReturnCode_t::RETCODE_OK) return 0;
  // Our own reader matches our writer too.
  return status.current_count > 0 ? static_cast<size_t>(status.current_count - 1) : 0;
}

size_t Bus::serializedSize(const wire::SliceFeatures& s) { return wire::SliceFeatures::getCdrSerializedSize(s) + 4; }

}  // namespace tomomap::transport
