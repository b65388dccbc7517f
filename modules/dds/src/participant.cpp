#include "omnislam/dds/participant.hpp"

#include <dds/dds.h>

#include <stdexcept>

namespace omnislam::dds {

Participant::Participant(const DdsConfig &config) {
  const auto domain = static_cast<dds_domainid_t>(config.domain_id);
  if (!config.config.empty()) {
    const bool is_xml = config.config.front() == '<';
    const bool is_uri = config.config.rfind("file://", 0) == 0;
    const std::string uri = is_xml || is_uri ? config.config : "file://" + config.config;
    const dds_entity_t created = dds_create_domain(domain, uri.c_str());
    if (created < 0 && created != DDS_RETCODE_PRECONDITION_NOT_MET) {  // not met: the domain exists
      throw std::runtime_error("DDS: cannot create domain " + std::to_string(config.domain_id) + " with " +
                               config.config + ": " + dds_strretcode(created));
    }
  }
  participant_ = dds_create_participant(domain, nullptr, nullptr);
  if (participant_ < 0) {
    throw std::runtime_error("DDS: cannot create a participant on domain " +
                             std::to_string(config.domain_id) + ": " + dds_strretcode(participant_));
  }
}

Participant::~Participant() {
  if (participant_ > 0) dds_delete(participant_);
}

}  // namespace omnislam::dds
