#pragma once

#include <cstdint>
#include <string>

/// @file
/// A DDS domain participant (Cyclone DDS), the root of every reader and writer.

namespace omnislam::dds {

struct DdsConfig {
  int domain_id = 0;
  /// Cyclone configuration: a file (path or file:// URI) or an XML fragment; empty uses
  /// CYCLONEDDS_URI or Cyclone's defaults.
  std::string config;
};

/// Owns a participant (and with it every entity created under it). Throws
/// std::runtime_error naming the domain when Cyclone cannot create it. Not copyable.
class Participant {
 public:
  explicit Participant(const DdsConfig &config);
  Participant(const Participant &) = delete;
  Participant &operator=(const Participant &) = delete;
  ~Participant();

  /// Cyclone's entity handle (dds_entity_t), for the readers and writers of this module.
  [[nodiscard]] std::int32_t handle() const { return participant_; }

 private:
  std::int32_t participant_ = 0;
};

}  // namespace omnislam::dds
