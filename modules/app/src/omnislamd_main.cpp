// omnislamd: the real-time service (architecture.md "Service"): the staged pipeline from
// the configured input to DDS topics and, at shutdown, the run files.

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <memory>
#include <optional>

#include "frame_record.hpp"
#include "omnislam/dds/odometry_reader.hpp"
#include "omnislam/dds/publisher.hpp"
#include "omnislam/io/config.hpp"
#include "omnislam/pipeline/pipeline.hpp"
#include "run_outputs.hpp"
#include "service_input.hpp"

namespace {

using namespace omnislam;
using namespace omnislam::app;

double system_time_s() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// SIGINT/SIGTERM are blocked in every thread and taken here, on the main thread, which
// then drains the pipeline.
bool wait_for_signal_or(const pipeline::Pipeline &pipeline, const sigset_t &signals) {
  const timespec tick{0, 100'000'000};
  while (!pipeline.finished()) {
    const int signal = sigtimedwait(&signals, nullptr, &tick);
    if (signal > 0) {
      spdlog::info("signal {}: draining the pipeline", signal);
      return true;
    }
  }
  return false;
}

pipeline::PipelineConfig pipeline_config(const io::PipelineSectionConfig &section, double rate_hz) {
  pipeline::PipelineConfig config;
  config.mode = section.mode == "replay" ? pipeline::Mode::kReplay : pipeline::Mode::kLive;
  config.queue_capacity = static_cast<std::size_t>(section.queue_capacity);
  config.input_rate_hz = rate_hz;
  config.map_period_s = section.map_rate_hz > 0.0 ? 1.0 / section.map_rate_hz : 0.0;
  config.profile_period_s = section.profile_period_s;
  config.profile_window = static_cast<std::size_t>(section.profile_window);
  return config;
}

int run_service(const std::string &config_file) {
  io::Config config = io::load_config(config_file);
  const io::ServiceConfig &service = config.service;

  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);  // before any thread (DDS, pipeline) starts

  std::optional<dds::Participant> participant;
  std::optional<dds::Publisher> publisher;
  std::shared_ptr<dds::OdometryReader> odometry;
  if (service.dds.enabled) {
    participant.emplace(dds::DdsConfig{service.dds.domain_id, service.dds.config});
    publisher.emplace(*participant);
    if (service.input.odometry == "dds") {
      odometry = std::make_shared<dds::OdometryReader>(*participant, service.input.odometry_topic);
    }
  }
  dds::StatusMessage status{system_time_s(), dds::ServiceState::kStarting, 0, 0, 0, ""};
  if (publisher) publisher->status(status);

  const ServiceInput input = make_service_input(config, odometry);
  spdlog::info("input: {}, {} Hz, mode {}, DDS domain {}", input.description, input.rate_hz,
               service.pipeline.mode, service.dds.enabled ? std::to_string(service.dds.domain_id) : "off");
  if (publisher && service.dds.wait_for_subscribers > 0 &&
      !publisher->wait_for_readers(service.dds.wait_for_subscribers, service.dds.wait_timeout_s)) {
    spdlog::warn("fewer than {} pose subscribers after {} s; starting anyway",
                 service.dds.wait_for_subscribers, service.dds.wait_timeout_s);
  }

  RunRecord run;
  pipeline::Sinks sinks;
  sinks.frame = [&](const pipeline::Frame &frame) {
    if (frame.skipped()) spdlog::warn("frame {} skipped: {}", frame.sequence, frame.error);
    if (frame.dropped_before > 0)
      spdlog::debug("{} frames dropped before frame {}", frame.dropped_before, frame.sequence);
    if (publisher) {
      publisher->pose(frame.stamp_s, frame.estimate.T_map_base, frame.estimate.covariance);
      publisher->scan(frame.stamp_s, frame.scan);
      if (frame.map) publisher->map(frame.stamp_s, *frame.map);
    }
    if (!service.output_dir.empty()) run.frames.push_back(frame_record(frame));
  };
  sinks.profile = [&](const pipeline::ProfileSnapshot &profile) {
    if (publisher) publisher->profile(system_time_s(), profile);
    spdlog::info("frames in {} out {} dropped {}; latency p50 {:.1f} ms p99 {:.1f} ms",
                 profile.frames_captured, profile.frames_out, profile.frames_dropped, profile.latency.p50_ms,
                 profile.latency.p99_ms);
  };

  pipeline::Pipeline pipeline(config.scan, config.slam, pipeline_config(service.pipeline, input.rate_hz),
                              std::move(sinks));
  pipeline.start(input.source);
  status.state = dds::ServiceState::kRunning;
  status.stamp_s = system_time_s();
  if (publisher) publisher->status(status);

  if (wait_for_signal_or(pipeline, signals)) {
    status.state = dds::ServiceState::kStopping;
    status.stamp_s = system_time_s();
    if (publisher) publisher->status(status);
  }
  pipeline.stop();
  pipeline.join();

  status.stamp_s = system_time_s();
  status.frames_in = pipeline.frames_captured();
  status.frames_out = pipeline.frames_out();
  status.frames_dropped = pipeline.frames_dropped();
  status.last_error = pipeline.error();
  status.state = pipeline.error().empty() ? dds::ServiceState::kStopped : dds::ServiceState::kFailed;
  const double last_stamp = run.frames.empty() ? status.stamp_s : run.frames.back().t_s;
  if (publisher) {
    publisher->map(last_stamp, pipeline.slam().map().points());  // the final state
    publisher->status(status);
    publisher->flush(2.0);
  }
  if (!service.output_dir.empty()) {
    io::DatasetInfo info;
    info.name = "omnislamd";
    for (const FrameRecord &f : run.frames)
      run.odometry_map.push_back(run.frames.front().T_odom_base.inverse() * f.T_odom_base);
    OutputWriter(service.output_dir).write_all(run, pipeline.slam().map(), info);
  }
  spdlog::info("stopped: {} frames in, {} out, {} dropped", status.frames_in, status.frames_out,
               status.frames_dropped);
  if (!pipeline.error().empty()) {
    spdlog::error("{}", pipeline.error());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char **argv) {
  CLI::App app{"omnislamd: omnidirectional stereo SLAM service"};
  std::string config_file;
  app.add_option("--config", config_file, "YAML configuration (deploy/omnislamd.yaml)")->required();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError &error) {
    return app.exit(error);
  }
  try {
    return run_service(config_file);
  } catch (const io::ConfigError &error) {
    spdlog::critical("configuration error: {}", error.what());
    return 2;
  } catch (const std::exception &error) {
    spdlog::critical("{}", error.what());
    return 1;
  }
}
