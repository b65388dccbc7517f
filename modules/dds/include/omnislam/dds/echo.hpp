#pragma once

#include <atomic>
#include <cstdio>
#include <string>

#include "omnislam/dds/participant.hpp"

/// @file
/// `omnislam echo TOPIC`: subscribe to one of omnislam's topics and print each sample as
/// one line of text.

namespace omnislam::dds {

struct EchoOptions {
  long max_messages = 0;   ///< stop after this many; 0 = no limit
  double timeout_s = 0.0;  ///< stop after this long; 0 = no limit
};

/// The DDS topic of a name given as "rt/omnislam/pose", "/omnislam/pose" or "omnislam/pose".
[[nodiscard]] std::string dds_topic_name(const std::string &name);

/// Prints samples of `topic` (pose, map, scan, profile, status, rt/odom) to `out` until
/// `stop`, max_messages or timeout_s. Returns the number printed. Throws
/// std::invalid_argument on a topic it does not know.
long echo(const Participant &participant, const std::string &topic, const EchoOptions &options,
          const std::atomic<bool> &stop, std::FILE *out);

}  // namespace omnislam::dds
