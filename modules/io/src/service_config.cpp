#include <initializer_list>
#include <string>
#include <utility>

#include "omnislam/io/config.hpp"
#include "yaml_fields.hpp"

namespace omnislam::io::detail {
namespace {

void read_one_of(YamlSection &section, const char *key, std::string &value,
                 std::initializer_list<const char *> choices) {
  std::string text = value;
  section.read(key, text);
  std::string list;
  for (const char *choice : choices) {
    if (text == choice) {
      value = text;
      return;
    }
    list += (list.empty() ? "" : ", ") + std::string(choice);
  }
  section.fail(key, "must be one of " + list);
}

void read_input(YamlSection &section, InputConfig &input) {
  read_one_of(section, "source", input.source, {"dataset", "directory", "camera", "video"});
  section.read("path", input.path);
  section.read("device", input.device);
  section.read("rate_hz", input.rate_hz);
  section.read("loops", input.loops);
  read_one_of(section, "odometry", input.odometry, {"dataset", "dds", "none"});
  section.read("odometry_topic", input.odometry_topic);
  section.read("odometry_max_extrapolation_s", input.odometry_max_extrapolation_s);
  section.read("odometry_max_gap_s", input.odometry_max_gap_s);
  if (input.odometry_max_extrapolation_s < 0.0) section.fail("odometry_max_extrapolation_s", "must be >= 0");
  if (!(input.odometry_max_gap_s > 0.0)) section.fail("odometry_max_gap_s", "must be positive");
  if (input.loops < 1) section.fail("loops", "must be at least 1");
  if (input.source != "camera" && input.path.empty()) section.fail("source", "needs input.path");
  if (input.odometry == "dataset" && input.source != "dataset") {
    section.fail("odometry", "dataset needs source: dataset");
  }
}

void read_pipeline(YamlSection &section, PipelineSectionConfig &pipeline) {
  read_one_of(section, "mode", pipeline.mode, {"live", "replay"});
  section.read("queue_capacity", pipeline.queue_capacity);
  section.read("map_rate_hz", pipeline.map_rate_hz);
  section.read("profile_period_s", pipeline.profile_period_s);
  section.read("profile_window", pipeline.profile_window);
  if (pipeline.queue_capacity < 1 || pipeline.queue_capacity > 1024) {
    section.fail("queue_capacity", "must be in 1..1024");
  }
  if (!(pipeline.profile_period_s > 0.0)) section.fail("profile_period_s", "must be positive");
  if (pipeline.profile_window < 1) section.fail("profile_window", "must be at least 1");
}

void read_dds(YamlSection &section, DdsSectionConfig &dds) {
  section.read("enabled", dds.enabled);
  section.read("domain_id", dds.domain_id);
  section.read("config", dds.config);
  section.read("wait_for_subscribers", dds.wait_for_subscribers);
  section.read("wait_timeout_s", dds.wait_timeout_s);
  section.read("initial_pose_topic", dds.initial_pose_topic);
  if (dds.domain_id < 0 || dds.domain_id > 232) section.fail("domain_id", "must be in 0..232");
  read_section(section, "tf", [&](YamlSection &tf) {
    tf.read("enabled", dds.tf.enabled);
    tf.read("map_frame", dds.tf.map_frame);
    tf.read("odom_frame", dds.tf.odom_frame);
    tf.read("base_frame", dds.tf.base_frame);
    tf.read("publish_odom_to_base", dds.tf.publish_odom_to_base);
    tf.read("rate_hz", dds.tf.rate_hz);
    tf.read("future_dating_s", dds.tf.future_dating_s);
    for (const auto &[key, frame] :
         {std::pair{"map_frame", &dds.tf.map_frame}, std::pair{"odom_frame", &dds.tf.odom_frame},
          std::pair{"base_frame", &dds.tf.base_frame}})
      if (frame->empty()) tf.fail(key, "must not be empty");
    if (!(dds.tf.rate_hz > 0.0) || dds.tf.rate_hz > 1000.0) tf.fail("rate_hz", "must be in (0, 1000]");
    if (!(dds.tf.future_dating_s >= 0.0) || dds.tf.future_dating_s > 10.0)
      tf.fail("future_dating_s", "must be in [0, 10]");
  });
}

}  // namespace

// The service's sections of load_config (config.cpp), kept apart from the algorithm ones.
void read_service_sections(YamlSection &top, ServiceConfig &service) {
  read_section(top, "input", [&](YamlSection &section) { read_input(section, service.input); });
  read_section(top, "pipeline", [&](YamlSection &section) { read_pipeline(section, service.pipeline); });
  read_section(top, "dds", [&](YamlSection &section) { read_dds(section, service.dds); });
  read_section(top, "service", [&](YamlSection &section) {
    section.read("output_dir", service.output_dir);
    section.read("stage_timeout_s", service.stage_timeout_s);
    if (!(service.stage_timeout_s > 0.0)) section.fail("stage_timeout_s", "must be positive");
  });
}

}  // namespace omnislam::io::detail
