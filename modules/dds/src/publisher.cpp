#include "omnislam/dds/publisher.hpp"
#include "omnislam/slam/planar_pose.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <string>
#include <thread>

#include "messages.hpp"

namespace omnislam::dds {
namespace {

using namespace detail;

constexpr uint8_t kFloat32 = 7;  // sensor_msgs/PointField constants
constexpr uint8_t kUint32 = 6;
constexpr int kBeams = 360;

void write(dds_entity_t writer, const void *sample, const char *topic) {
  const dds_return_t rc = dds_write(writer, sample);
  if (rc < 0) throw std::runtime_error(std::string("DDS: write on ") + topic + ": " + dds_strretcode(rc));
}

std_msgs_msg_dds__Header_ header(double stamp_s, const char *frame_id) {
  return {to_time(stamp_s), const_cast<char *>(frame_id)};
}

omnislam_msg_dds__StageStats_ stage_stats(std::string_view name, const pipeline::DurationStats &s,
                                          std::string &storage) {
  storage = name;
  return {storage.data(), s.count, s.mean_ms, s.p50_ms, s.p99_ms, s.max_ms, s.share};
}

}  // namespace

Publisher::Publisher(const Participant &participant) {
  const dds_entity_t p = participant.handle();
  pose_ = create_endpoint(p, geometry_msgs_msg_dds__PoseWithCovarianceStamped__desc, "rt/omnislam/pose",
                          kPoseQos, true);
  map_ = create_endpoint(p, sensor_msgs_msg_dds__PointCloud2__desc, "rt/omnislam/map", kMapQos, true);
  scan_ = create_endpoint(p, sensor_msgs_msg_dds__LaserScan__desc, "rt/omnislam/scan", kScanQos, true);
  profile_ =
      create_endpoint(p, omnislam_msg_dds__StageProfile__desc, "rt/omnislam/profile", kProfileQos, true);
  status_ = create_endpoint(p, omnislam_msg_dds__Status__desc, "rt/omnislam/status", kStatusQos, true);
  grid_ = create_endpoint(p, nav_msgs_msg_dds__OccupancyGrid__desc, "rt/map", kGridQos, true);
  grid_metadata_ = create_endpoint(p, nav_msgs_msg_dds__MapMetaData__desc, "rt/map_metadata", kGridQos, true);
}

void Publisher::grid(double stamp_s, const grid::GridImage &image) {
  nav_msgs_msg_dds__MapMetaData_ info{};
  info.map_load_time = to_time(stamp_s);
  info.resolution = static_cast<float>(image.resolution_m);
  info.width = static_cast<uint32_t>(image.width);
  info.height = static_cast<uint32_t>(image.height);
  info.origin.position = {image.origin_m.x(), image.origin_m.y(), 0.0};
  info.origin.orientation = {0.0, 0.0, 0.0, 1.0};
  nav_msgs_msg_dds__OccupancyGrid_ msg{};
  msg.header = header(stamp_s, "map");
  msg.info = info;
  std::vector<int8_t> cells(image.cells.begin(), image.cells.end());
  msg.data._buffer = cells.data();
  msg.data._length = msg.data._maximum = static_cast<uint32_t>(cells.size());
  msg.data._release = false;
  write(grid_, &msg, "rt/map");
  write(grid_metadata_, &info, "rt/map_metadata");
}

void Publisher::pose(double stamp_s, const Eigen::Isometry2d &T_map_base, const Eigen::Matrix3d &covariance) {
  geometry_msgs_msg_dds__PoseWithCovarianceStamped_ msg{};
  msg.header = header(stamp_s, "map");
  const double yaw = slam::yaw_rad_of(T_map_base);
  msg.pose.pose.position = {T_map_base.translation().x(), T_map_base.translation().y(), 0.0};
  msg.pose.pose.orientation = {0.0, 0.0, std::sin(yaw / 2.0), std::cos(yaw / 2.0)};
  // (x, y, yaw) -> rows/columns (0, 1, 5) of ROS's (x, y, z, roll, pitch, yaw).
  constexpr std::array<int, 3> kIndex = {0, 1, 5};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) msg.pose.covariance[kIndex[r] * 6 + kIndex[c]] = covariance(r, c);
  }
  write(pose_, &msg, "rt/omnislam/pose");
}

void Publisher::map(double stamp_s, const std::vector<slam::MapPoint> &points) {
  static char kX[] = "x", kY[] = "y", kZ[] = "z", kHits[] = "hits";
  std::array<sensor_msgs_msg_dds__PointField_, 4> fields = {
      {{kX, 0, kFloat32, 1}, {kY, 4, kFloat32, 1}, {kZ, 8, kFloat32, 1}, {kHits, 12, kUint32, 1}}};
  constexpr uint32_t kPointStep = 16;
  std::vector<uint8_t> data(points.size() * kPointStep);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::array<float, 3> xyz = {static_cast<float>(points[i].position_m.x()),
                                      static_cast<float>(points[i].position_m.y()), 0.0f};
    const auto hits = static_cast<uint32_t>(points[i].hits);
    std::memcpy(&data[i * kPointStep], xyz.data(), sizeof xyz);
    std::memcpy(&data[i * kPointStep + 12], &hits, sizeof hits);
  }
  sensor_msgs_msg_dds__PointCloud2_ msg{};
  msg.header = header(stamp_s, "map");
  msg.height = 1;
  msg.width = static_cast<uint32_t>(points.size());
  msg.fields._length = msg.fields._maximum = static_cast<uint32_t>(fields.size());
  msg.fields._buffer = fields.data();
  msg.is_bigendian = false;  // x86 and ARM hosts
  msg.point_step = kPointStep;
  msg.row_step = static_cast<uint32_t>(data.size());
  msg.data._length = msg.data._maximum = static_cast<uint32_t>(data.size());
  msg.data._buffer = data.data();
  msg.is_dense = true;
  write(map_, &msg, "rt/omnislam/map");
}

void Publisher::scan(double stamp_s, const stereo::LocalScan &scan) {
  std::vector<float> ranges(kBeams, std::numeric_limits<float>::infinity());
  for (const stereo::ScanPoint &p : scan.points) {
    const int beam = static_cast<int>(p.azimuth_rad * 180.0 / std::numbers::pi) % kBeams;
    ranges[static_cast<std::size_t>(beam)] =
        std::min(ranges[static_cast<std::size_t>(beam)], static_cast<float>(p.range_m));
  }
  sensor_msgs_msg_dds__LaserScan_ msg{};
  msg.header = header(stamp_s, "base_link");
  msg.angle_min = 0.0f;
  msg.angle_increment = static_cast<float>(std::numbers::pi / 180.0);
  msg.angle_max = msg.angle_increment * (kBeams - 1);
  msg.range_min = 0.0f;
  msg.range_max = std::numeric_limits<float>::max();
  msg.ranges._length = msg.ranges._maximum = kBeams;
  msg.ranges._buffer = ranges.data();
  write(scan_, &msg, "rt/omnislam/scan");
}

void Publisher::profile(double stamp_s, const pipeline::ProfileSnapshot &profile) {
  std::array<std::string, pipeline::kStages.size() + pipeline::kQueues.size() + 1> names;
  std::array<omnislam_msg_dds__StageStats_, pipeline::kStages.size()> stages;
  std::array<omnislam_msg_dds__QueueStats_, pipeline::kQueues.size()> queues;
  std::size_t n = 0;
  for (std::size_t s = 0; s < stages.size(); ++s)
    stages[s] = stage_stats(pipeline::kStages[s], profile.stages[s], names[n++]);
  for (std::size_t q = 0; q < queues.size(); ++q) {
    queues[q].wait = stage_stats(pipeline::kQueues[q], profile.waits[q], names[n++]);
    queues[q].name = queues[q].wait.name;
    queues[q].capacity = profile.queue_capacity[q];
    queues[q].depth_max = profile.queue_depth_max[q];
  }
  omnislam_msg_dds__StageProfile_ msg{};
  msg.header = header(stamp_s, "");
  msg.frames_captured = profile.frames_captured;
  msg.frames_dropped = profile.frames_dropped;
  msg.frames_out = profile.frames_out;
  msg.stages._length = msg.stages._maximum = static_cast<uint32_t>(stages.size());
  msg.stages._buffer = stages.data();
  msg.queues._length = msg.queues._maximum = static_cast<uint32_t>(queues.size());
  msg.queues._buffer = queues.data();
  msg.latency = stage_stats("latency", profile.latency, names[n++]);
  write(profile_, &msg, "rt/omnislam/profile");
}

void Publisher::status(const StatusMessage &status) {
  static constexpr std::array<const char *, 6> kNames = {"starting", "running", "stopping",
                                                         "stopped",  "failed",  "localizing"};
  std::string state_name = kNames[static_cast<std::size_t>(status.state)];
  std::string error = status.last_error;
  omnislam_msg_dds__Status_ msg{};
  msg.header = header(status.stamp_s, "");
  msg.state = static_cast<uint8_t>(status.state);
  msg.state_name = state_name.data();
  msg.frames_in = status.frames_in;
  msg.frames_out = status.frames_out;
  msg.frames_dropped = status.frames_dropped;
  msg.last_error = error.data();
  write(status_, &msg, "rt/omnislam/status");
}

bool Publisher::wait_for_readers(int readers, double timeout_s) const {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    dds_publication_matched_status_t matched{};
    if (dds_get_publication_matched_status(pose_, &matched) == DDS_RETCODE_OK &&
        static_cast<int>(matched.current_count) >= readers) {
      return true;
    }
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

void Publisher::flush(double timeout_s) const {
  const auto timeout = static_cast<dds_duration_t>(timeout_s * 1e9);
  for (const dds_entity_t writer : {pose_, map_, profile_, status_, grid_, grid_metadata_})
    static_cast<void>(dds_wait_for_acks(writer, timeout));
}

}  // namespace omnislam::dds
