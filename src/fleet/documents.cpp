#include "documents.hpp"

namespace tomomap::fleet {
namespace {

// The DDS domain ids a participant can use (Fast DDS: 0-232 with UDPv4 ports).
constexpr const char* kDomains = "<domains><id_range><min>0</min><max>232</max></id_range></domains>";

}  // namespace

// Fast DDS reads the elements in the order of the OMG schema: keep it.
std::string governanceXml() {
  return std::string(R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      )") +
         kDomains + R"(
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>NONE</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
)";
}
// Every submessage of every topic (data, heartbeats, acknowledgements) is
// encrypted and authenticated on its own (metadata_protection_kind ENCRYPT;
// the payload is inside it, so data_protection_kind adds nothing but bytes).
// Not rtps_protection_kind: Fast DDS 2.9 fills a message to its size limit
// before sealing it whole, and then aborts on an assertion when the sealed
// message has no room left for its statistics submessage (seen here).

std::string permissionsXml(const std::string& agent, const std::string& subject, const std::string& not_before,
                           const std::string& not_after) {
  const std::string topics = std::string("<topics><topic>") + kTopicPrefix + "*</topic></topics>";
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name=")" +
         agent + R"(">
      <subject_name>)" +
         subject + R"(</subject_name>
      <validity>
        <not_before>)" +
         not_before + R"(</not_before>
        <not_after>)" +
         not_after + R"(</not_after>
      </validity>
      <allow_rule>
        )" +
         kDomains +
         R"(
        <publish>)" +
         topics + R"(</publish>
        <subscribe>)" +
         topics + R"(</subscribe>
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
)";
}

}  // namespace tomomap::fleet
