#include "omnislam/io/snapshot.hpp"
#include "omnislam/slam/planar_pose.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <optional>
#include <string_view>
#include <system_error>

namespace omnislam::io {
namespace {

constexpr std::string_view kMagic = "OMNISNAP";
constexpr std::size_t kHeaderBytes = 24;           // magic, version, payload size, CRC
constexpr std::size_t kOdometryBytes = 8 + 3 * 8;  // version 2 only
constexpr std::size_t kFixedPayloadBytesV1 = 8 + 8 * 4 + 8 * 9 + 8 * 5 + 8 + 8;
constexpr std::size_t kPointBytes = 8 + 8 + 4 + 4;
constexpr std::size_t kGridHeaderBytes = 4 + 4 + 8 + 8 + 8;  // version 3, when has_grid is 1
// Version 4's graph section, when has_graph is 1: its fixed fields, and the least bytes
// each counted item takes (a keyframe without scans, a scan without points, ...).
constexpr std::size_t kGraphHeaderBytes = 8 + 3 * 8;
constexpr std::size_t kKeyframeBytes = 4 * 8 + 8;
constexpr std::size_t kKeyframeCovarianceBytes = 9 * 8;  // version 6
constexpr std::size_t kOdometryScaleBytes = 8 + 2 * 8;   // version 7: has, factor, sigma
constexpr std::size_t kScanBytes = 8;
constexpr std::size_t kScanPointBytes = 8 + 8;
constexpr std::size_t kIntegrationBytes = 4 + 4;
constexpr std::size_t kEdgeBytes = 4 + 4 + 8 + 3 * 8 + 9 * 8;

class ByteWriter {
 public:
  void u32(std::uint32_t v) { little_endian(v, 4); }
  void u64(std::uint64_t v) { little_endian(v, 8); }
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void i8(std::int8_t v) { bytes.push_back(static_cast<std::uint8_t>(v)); }
  std::vector<std::uint8_t> bytes;

 private:
  void little_endian(std::uint64_t v, int size) {
    for (int i = 0; i < size; ++i) bytes.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
};

// Reads fields in order; the caller has checked the total size first, so running past
// the end is a bug in this file, reported rather than read.
class ByteReader {
 public:
  ByteReader(std::span<const std::uint8_t> bytes, const std::string &name) : bytes_(bytes), name_(name) {}
  std::uint32_t u32() { return static_cast<std::uint32_t>(little_endian(4)); }
  std::uint64_t u64() { return little_endian(8); }
  std::int32_t i32() { return static_cast<std::int32_t>(u32()); }
  std::int64_t i64() { return static_cast<std::int64_t>(u64()); }
  std::int8_t i8() { return static_cast<std::int8_t>(little_endian(1)); }
  [[nodiscard]] std::size_t remaining() const { return bytes_.size() - offset_; }
  double f64(const char *field) {
    const double v = std::bit_cast<double>(u64());
    if (!std::isfinite(v)) throw SnapshotError(name_ + ": " + field + " is not a finite number");
    return v;
  }

 private:
  std::uint64_t little_endian(std::size_t size) {
    if (bytes_.size() - offset_ < size) throw SnapshotError(name_ + ": truncated");
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < size; ++i) v |= static_cast<std::uint64_t>(bytes_[offset_ + i]) << (8 * i);
    offset_ += size;
    return v;
  }
  std::span<const std::uint8_t> bytes_;
  const std::string &name_;
  std::size_t offset_ = 0;
};

std::uint32_t checksum(std::span<const std::uint8_t> header_fields, std::span<const std::uint8_t> payload) {
  uLong crc = crc32(0L, Z_NULL, 0);
  crc = crc32(crc, header_fields.data(), static_cast<uInt>(header_fields.size()));
  // zlib takes uInt lengths: feed large payloads in pieces.
  for (std::size_t done = 0; done < payload.size();) {
    const std::size_t piece = std::min<std::size_t>(payload.size() - done, 1u << 30);
    crc = crc32(crc, payload.data() + done, static_cast<uInt>(piece));
    done += piece;
  }
  return static_cast<std::uint32_t>(crc);
}

std::string system_error(const std::string &what, const std::filesystem::path &file) {
  return what + " " + file.string() + ": " + std::strerror(errno);
}

void write_all(int fd, std::span<const std::uint8_t> bytes, const std::filesystem::path &file) {
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(system_error("write", file));
    done += static_cast<std::size_t>(n);
  }
}

void fsync_directory(const std::filesystem::path &dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error(system_error("open directory", dir));
  const int status = ::fsync(fd);
  ::close(fd);
  if (status != 0) throw std::runtime_error(system_error("fsync directory", dir));
}

// The version-3 grid section: u64 has_grid, then (when 1) the trinary grid and, from version
// 5, a byte per cell marking what stood above the floor; followed by `trailing` more bytes at
// least (version 4's graph section) or, with 0, nothing.
std::optional<grid::GridImage> decode_grid(ByteReader &in, const std::string &name, std::size_t trailing,
                                           bool with_above_floor) {
  const std::uint64_t has_grid = in.u64();
  if (has_grid > 1) throw SnapshotError(name + ": has_grid is " + std::to_string(has_grid));
  if (has_grid == 0) return std::nullopt;
  if (in.remaining() < kGridHeaderBytes) throw SnapshotError(name + ": truncated occupancy grid");
  grid::GridImage g;
  g.width = in.i32();
  g.height = in.i32();
  g.resolution_m = in.f64("grid resolution_m");
  g.origin_m.x() = in.f64("grid origin x_m");
  g.origin_m.y() = in.f64("grid origin y_m");
  if (g.width <= 0 || g.height <= 0 || !(g.resolution_m > 0.0)) {
    throw SnapshotError(name + ": occupancy grid of " + std::to_string(g.width) + " x " +
                        std::to_string(g.height) + " cells at " + std::to_string(g.resolution_m) + " m");
  }
  const std::uint64_t cells = static_cast<std::uint64_t>(g.width) * static_cast<std::uint64_t>(g.height);
  const std::uint64_t bytes = with_above_floor ? 2 * cells : cells;
  const std::uint64_t available = in.remaining() >= trailing ? in.remaining() - trailing : 0;
  if (trailing == 0 ? available != bytes : available < bytes) {
    throw SnapshotError(name + ": the occupancy grid announces " + std::to_string(cells) + " cells (" +
                        std::to_string(bytes) + " bytes), the file holds " + std::to_string(available) +
                        " bytes");
  }
  g.cells.resize(cells);
  for (std::uint64_t i = 0; i < cells; ++i) {
    g.cells[i] = in.i8();
    if (g.cells[i] != -1 && g.cells[i] != 0 && g.cells[i] != 100) {
      throw SnapshotError(name + ": occupancy grid cell " + std::to_string(i) + " is " +
                          std::to_string(g.cells[i]) + " (not -1, 0 or 100)");
    }
  }
  if (!with_above_floor) return g;
  g.above_floor.resize(cells);
  for (std::uint64_t i = 0; i < cells; ++i) {
    const std::int8_t flag = in.i8();
    if (flag != 0 && flag != 1) {
      throw SnapshotError(name + ": occupancy grid cell " + std::to_string(i) + " has above-floor flag " +
                          std::to_string(flag) + " (not 0 or 1)");
    }
    g.above_floor[i] = static_cast<std::uint8_t>(flag);
  }
  return g;
}

void encode_pose(ByteWriter &out, const slam::PlanarPose &pose) {
  out.f64(pose.x_m);
  out.f64(pose.y_m);
  out.f64(pose.yaw_rad);
}

// An (x, y, yaw) covariance or information matrix, 9 f64 row-major.
void encode_matrix(ByteWriter &out, const Eigen::Matrix3d &m) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.f64(m(r, c));
}

// The version-4 graph section: u64 has_graph, then (when 1) the keyframe graph.
void encode_graph(ByteWriter &out, const std::optional<slam::KeyframeGraphState> &graph) {
  out.u64(graph ? 1 : 0);
  if (!graph) return;
  out.f64(graph->path_m);
  encode_pose(out, graph->last_frame);
  out.u64(graph->keyframes.size());
  for (const slam::KeyframeGraphState::SavedKeyframe &keyframe : graph->keyframes) {
    encode_pose(out, keyframe.T_map_keyframe);
    out.f64(keyframe.path_m);
    encode_matrix(out, keyframe.covariance);
    out.u64(keyframe.scans_keyframe.size());
    for (const auto &scan : keyframe.scans_keyframe) {
      out.u64(scan->size());
      for (const slam::Point2 &p : *scan) {
        out.f64(p.x());
        out.f64(p.y());
      }
    }
  }
  out.u64(graph->integration_order.size());
  for (const auto &[keyframe, scan] : graph->integration_order) {
    out.u32(static_cast<std::uint32_t>(keyframe));
    out.u32(static_cast<std::uint32_t>(scan));
  }
  out.u64(graph->edges.size());
  for (const slam::KeyframeGraphState::SavedEdge &edge : graph->edges) {
    out.u32(static_cast<std::uint32_t>(edge.from));
    out.u32(static_cast<std::uint32_t>(edge.to));
    out.u64(edge.loop ? 1 : 0);
    encode_pose(out, edge.T_from_to);
    encode_matrix(out, edge.information);
  }
}

slam::PlanarPose decode_pose(ByteReader &in, const std::string &what) {
  slam::PlanarPose pose;
  pose.x_m = in.f64((what + " x_m").c_str());
  pose.y_m = in.f64((what + " y_m").c_str());
  pose.yaw_rad = in.f64((what + " yaw_rad").c_str());
  return pose;
}

Eigen::Matrix3d decode_matrix(ByteReader &in, const std::string &what) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = in.f64(what.c_str());
  return m;
}

// A count of items of at least `item_bytes` each, checked against what is left before
// anything is allocated for them.
std::size_t decode_count(ByteReader &in, const std::string &name, const std::string &what,
                         std::size_t item_bytes) {
  const std::uint64_t count = in.u64();
  if (count > in.remaining() / item_bytes) {
    throw SnapshotError(name + ": the keyframe graph announces " + std::to_string(count) + " " + what +
                        ", the " + std::to_string(in.remaining()) + " bytes left cannot hold them");
  }
  return static_cast<std::size_t>(count);
}

int decode_index(ByteReader &in, const std::string &name, const std::string &what) {
  const std::uint32_t index = in.u32();
  if (index > static_cast<std::uint32_t>(std::numeric_limits<int>::max()))
    throw SnapshotError(name + ": keyframe graph " + what + " " + std::to_string(index) + " out of range");
  return static_cast<int>(index);
}

slam::KeyframeGraphState::SavedKeyframe decode_keyframe(ByteReader &in, const std::string &name,
                                                        std::size_t k, bool with_covariance) {
  const std::string which = "keyframe " + std::to_string(k);
  slam::KeyframeGraphState::SavedKeyframe keyframe;
  keyframe.T_map_keyframe = decode_pose(in, which);
  keyframe.path_m = in.f64((which + " path_m").c_str());
  if (with_covariance) keyframe.covariance = decode_matrix(in, which + " covariance");
  const std::size_t scans = decode_count(in, name, "scans of " + which, kScanBytes);
  const std::string x_field = which + " scan point x_m", y_field = which + " scan point y_m";
  for (std::size_t i = 0; i < scans; ++i) {
    const std::size_t points =
        decode_count(in, name, "points of " + which + " scan " + std::to_string(i), kScanPointBytes);
    auto scan = std::make_shared<slam::Points2>();
    scan->reserve(points);
    for (std::size_t j = 0; j < points; ++j) {
      const double x = in.f64(x_field.c_str());
      scan->emplace_back(x, in.f64(y_field.c_str()));
    }
    keyframe.scans_keyframe.push_back(std::move(scan));
  }
  return keyframe;
}

slam::KeyframeGraphState::SavedEdge decode_edge(ByteReader &in, const std::string &name, std::size_t e) {
  const std::string which = "edge " + std::to_string(e);
  slam::KeyframeGraphState::SavedEdge edge;
  edge.from = decode_index(in, name, which + " from");
  edge.to = decode_index(in, name, which + " to");
  const std::uint64_t loop = in.u64();
  if (loop > 1) throw SnapshotError(name + ": keyframe graph " + which + " loop is " + std::to_string(loop));
  edge.loop = loop == 1;
  edge.T_from_to = decode_pose(in, which);
  edge.information = decode_matrix(in, which + " information");
  return edge;
}

// The version-4 graph section, checked as a whole once read (indices in range, every scan
// integrated once, ...) and against the map it must describe.
std::optional<slam::KeyframeGraphState> decode_graph(ByteReader &in, const std::string &name,
                                                     int map_integrations, bool with_covariances) {
  const std::uint64_t has_graph = in.u64();
  if (has_graph > 1) throw SnapshotError(name + ": has_graph is " + std::to_string(has_graph));
  if (has_graph == 0) return std::nullopt;
  if (in.remaining() < kGraphHeaderBytes) throw SnapshotError(name + ": truncated keyframe graph");
  slam::KeyframeGraphState graph;
  graph.path_m = in.f64("keyframe graph path_m");
  graph.last_frame = decode_pose(in, "keyframe graph last frame");
  const std::size_t keyframes =
      decode_count(in, name, "keyframes", kKeyframeBytes + (with_covariances ? kKeyframeCovarianceBytes : 0));
  for (std::size_t k = 0; k < keyframes; ++k)
    graph.keyframes.push_back(decode_keyframe(in, name, k, with_covariances));
  const std::size_t integrations = decode_count(in, name, "integrations", kIntegrationBytes);
  graph.integration_order.reserve(integrations);
  for (std::size_t i = 0; i < integrations; ++i) {
    const int keyframe = decode_index(in, name, "integration keyframe");
    graph.integration_order.emplace_back(keyframe, decode_index(in, name, "integration scan"));
  }
  const std::size_t edges = decode_count(in, name, "edges", kEdgeBytes);
  graph.edges.reserve(edges);
  for (std::size_t e = 0; e < edges; ++e) graph.edges.push_back(decode_edge(in, name, e));
  if (const std::string error = slam::keyframe_graph_state_error(graph); !error.empty())
    throw SnapshotError(name + ": keyframe graph: " + error);
  if (graph.integrations() != static_cast<std::size_t>(map_integrations)) {
    throw SnapshotError(name + ": the keyframe graph holds " + std::to_string(graph.integrations()) +
                        " integrated scans, the map " + std::to_string(map_integrations));
  }
  return graph;
}

}  // namespace

std::vector<std::uint8_t> encode_snapshot(const Snapshot &snapshot) {
  ByteWriter payload;
  payload.u64(snapshot.config_hash);
  payload.f64(snapshot.t_s);
  const Eigen::Vector2d t = snapshot.T_map_base.translation();
  payload.f64(t.x());
  payload.f64(t.y());
  payload.f64(slam::yaw_rad_of(snapshot.T_map_base));
  encode_matrix(payload, snapshot.covariance);
  const SnapshotCounters &n = snapshot.counters;
  for (std::uint64_t count : {n.frames, n.integrated, n.not_integrated, n.skipped, n.dropped})
    payload.u64(count);
  payload.i64(snapshot.map_integrations);
  const Eigen::Isometry2d odom = snapshot.T_odom_base.value_or(Eigen::Isometry2d::Identity());
  payload.u64(snapshot.T_odom_base ? 1 : 0);
  payload.f64(odom.translation().x());
  payload.f64(odom.translation().y());
  payload.f64(slam::yaw_rad_of(odom));
  payload.u64(snapshot.points.size());
  for (const slam::MapPoint &p : snapshot.points) {
    payload.f64(p.position_m.x());
    payload.f64(p.position_m.y());
    payload.i32(p.hits);
    payload.i32(p.first_seen);
  }
  payload.u64(snapshot.grid ? 1 : 0);
  if (snapshot.grid) {
    const grid::GridImage &g = *snapshot.grid;
    payload.i32(g.width);
    payload.i32(g.height);
    payload.f64(g.resolution_m);
    payload.f64(g.origin_m.x());
    payload.f64(g.origin_m.y());
    for (const std::int8_t cell : g.cells) payload.i8(cell);
    const bool flagged = g.above_floor.size() == g.cells.size();
    for (std::size_t i = 0; i < g.cells.size(); ++i) payload.i8(flagged && g.above_floor[i] != 0 ? 1 : 0);
  }
  encode_graph(payload, snapshot.graph);
  payload.u64(snapshot.odometry_scale ? 1 : 0);
  payload.f64(snapshot.odometry_scale ? snapshot.odometry_scale->factor : 1.0);
  payload.f64(snapshot.odometry_scale ? snapshot.odometry_scale->sigma : 0.0);

  ByteWriter header;
  header.bytes.assign(kMagic.begin(), kMagic.end());
  header.u32(kSnapshotVersion);
  header.u64(payload.bytes.size());
  const std::span<const std::uint8_t> checked(header.bytes.data() + kMagic.size(), 12);
  header.u32(checksum(checked, payload.bytes));
  header.bytes.insert(header.bytes.end(), payload.bytes.begin(), payload.bytes.end());
  return std::move(header.bytes);
}

Snapshot decode_snapshot(std::span<const std::uint8_t> bytes, const std::string &name) {
  if (bytes.size() < kHeaderBytes) {
    throw SnapshotError(name + ": truncated: " + std::to_string(bytes.size()) + " bytes, shorter than the " +
                        std::to_string(kHeaderBytes) + "-byte header");
  }
  if (!std::equal(kMagic.begin(), kMagic.end(), bytes.begin())) {
    throw SnapshotError(name + ": not an omnislam snapshot (bad magic)");
  }
  ByteReader header(bytes.subspan(kMagic.size(), kHeaderBytes - kMagic.size()), name);
  const std::uint32_t version = header.u32();
  const std::uint64_t payload_size = header.u64();
  const std::uint32_t stored_crc = header.u32();
  const std::span<const std::uint8_t> payload = bytes.subspan(kHeaderBytes);
  if (payload.size() != payload_size) {
    throw SnapshotError(name + ": " + (payload.size() < payload_size ? "truncated" : "trailing bytes") +
                        ": the header announces " + std::to_string(payload_size) +
                        " payload bytes, the file has " + std::to_string(payload.size()));
  }
  if (checksum(bytes.subspan(kMagic.size(), 12), payload) != stored_crc) {
    throw SnapshotError(name + ": checksum mismatch (the file is corrupt)");
  }
  if (version < 1 || version > kSnapshotVersion) {
    throw SnapshotError(name + ": unsupported snapshot version " + std::to_string(version) +
                        " (this build reads versions 1 to " + std::to_string(kSnapshotVersion) + ")");
  }
  const std::size_t fixed_bytes = kFixedPayloadBytesV1 + (version >= 2 ? kOdometryBytes : 0);
  if (payload.size() < fixed_bytes) throw SnapshotError(name + ": truncated payload");

  ByteReader in(payload, name);
  Snapshot s;
  s.version = version;
  s.config_hash = in.u64();
  s.t_s = in.f64("t_s");
  const double x = in.f64("x_m"), y = in.f64("y_m"), yaw = in.f64("yaw_rad");
  s.T_map_base = slam::planar_pose(x, y, yaw);
  s.covariance = decode_matrix(in, "covariance");
  SnapshotCounters &n = s.counters;
  for (std::uint64_t *count : {&n.frames, &n.integrated, &n.not_integrated, &n.skipped, &n.dropped})
    *count = in.u64();
  const std::int64_t integrations = in.i64();
  if (integrations < 0 || integrations > std::numeric_limits<int>::max()) {
    throw SnapshotError(name + ": map_integrations " + std::to_string(integrations) + " out of range");
  }
  s.map_integrations = static_cast<int>(integrations);
  if (version >= 2) {
    const std::uint64_t has_odometry = in.u64();
    if (has_odometry > 1) throw SnapshotError(name + ": has_odometry is " + std::to_string(has_odometry));
    const double ox = in.f64("odom x_m"), oy = in.f64("odom y_m"), oyaw = in.f64("odom yaw_rad");
    if (has_odometry == 1) s.T_odom_base = slam::planar_pose(ox, oy, oyaw);
  }
  const std::uint64_t count = in.u64();
  // Version 3 ends with the grid section (at least its u64 has_grid), version 4 with the
  // grid and graph sections (at least their two u64 flags); earlier ones with the points.
  const std::uint64_t sections_bytes =
      (version >= 4 ? 16 : (version == 3 ? 8 : 0)) + (version >= 7 ? kOdometryScaleBytes : 0);
  const std::uint64_t point_bytes = payload.size() - fixed_bytes;
  const std::uint64_t announced = count <= point_bytes / kPointBytes ? count * kPointBytes : point_bytes + 1;
  const bool points_fit = version >= 3 ? announced + sections_bytes <= point_bytes
                                       : point_bytes % kPointBytes == 0 && announced == point_bytes;
  if (!points_fit) {
    throw SnapshotError(name + ": announces " + std::to_string(count) + " map points but holds " +
                        std::to_string(point_bytes) + " bytes of points" +
                        (version >= 4 ? ", grid and graph" : (version == 3 ? " and grid" : "")));
  }
  s.points.reserve(count);
  for (std::uint64_t i = 0; i < count; ++i) {
    slam::MapPoint p;
    p.position_m.x() = in.f64("point x_m");
    p.position_m.y() = in.f64("point y_m");
    p.hits = in.i32();
    p.first_seen = in.i32();
    if (p.hits < 1 || p.first_seen < 0 || p.first_seen > s.map_integrations) {
      throw SnapshotError(name + ": map point " + std::to_string(i) + " has hits " + std::to_string(p.hits) +
                          " and first_seen " + std::to_string(p.first_seen) + " (map_integrations " +
                          std::to_string(s.map_integrations) + ")");
    }
    s.points.push_back(p);
  }
  if (version >= 3)
    s.grid = decode_grid(in, name, (version >= 4 ? 8 : 0) + (version >= 7 ? kOdometryScaleBytes : 0),
                         version >= 5);
  if (version >= 4) s.graph = decode_graph(in, name, s.map_integrations, version >= 6);
  if (version >= 7) {
    if (in.remaining() < kOdometryScaleBytes)
      throw SnapshotError(name + ": truncated odometry distance factor");
    const std::uint64_t has_scale = in.u64();
    if (has_scale > 1) throw SnapshotError(name + ": has_odometry_scale is " + std::to_string(has_scale));
    const double factor = in.f64("odometry scale factor"), sigma = in.f64("odometry scale sigma");
    if (has_scale == 1) {
      if (!(factor > 0.0) || !(sigma >= 0.0)) {
        throw SnapshotError(name + ": odometry distance factor " + std::to_string(factor) + " +- " +
                            std::to_string(sigma));
      }
      s.odometry_scale = SnapshotOdometryScale{factor, sigma};
    }
  }
  if (in.remaining() != 0) {
    throw SnapshotError(name + ": trailing bytes after the " +
                        (version >= 7   ? "odometry distance factor"
                         : version >= 4 ? "keyframe graph"
                                        : "occupancy grid"));
  }
  return s;
}

void write_snapshot(const std::filesystem::path &file, const Snapshot &snapshot) {
  const std::vector<std::uint8_t> bytes = encode_snapshot(snapshot);
  const std::filesystem::path dir = file.has_parent_path() ? file.parent_path() : ".";
  std::filesystem::path temporary = file;
  temporary += ".tmp";
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error(system_error("cannot create", temporary));
  try {
    write_all(fd, bytes, temporary);
    if (::fsync(fd) != 0) throw std::runtime_error(system_error("fsync", temporary));
  } catch (...) {
    ::close(fd);
    ::unlink(temporary.c_str());
    throw;
  }
  if (::close(fd) != 0) {
    ::unlink(temporary.c_str());
    throw std::runtime_error(system_error("close", temporary));
  }
  // rename() replaces atomically; the directory fsync makes the new name itself durable.
  if (::rename(temporary.c_str(), file.c_str()) != 0) {
    const std::string message = system_error("rename to", file);
    ::unlink(temporary.c_str());
    throw std::runtime_error(message);
  }
  fsync_directory(dir);
}

Snapshot read_snapshot(const std::filesystem::path &file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw SnapshotError(file.string() + ": cannot open the snapshot");
  const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) throw SnapshotError(file.string() + ": read error");
  return decode_snapshot(bytes, file.string());
}

std::filesystem::path move_aside(const std::filesystem::path &file) {
  for (int n = 1;; ++n) {
    std::filesystem::path target = file;
    target += ".corrupt-" + std::to_string(n);
    std::error_code exists_error;
    if (std::filesystem::exists(target, exists_error) || exists_error) continue;
    std::error_code error;
    std::filesystem::rename(file, target, error);
    if (error) throw std::runtime_error("cannot move " + file.string() + " aside: " + error.message());
    return target;
  }
}

ResumeResult resume_from_snapshot(const std::filesystem::path &file, CorruptSnapshotPolicy policy) {
  ResumeResult result;
  std::error_code error;
  if (!std::filesystem::exists(file, error)) {
    result.message = "no snapshot at " + file.string() + ": starting a new map";
    return result;
  }
  try {
    result.snapshot = read_snapshot(file);
    result.message =
        "resumed from " + file.string() + ": " + std::to_string(result.snapshot->points.size()) +
        " map points, " + std::to_string(result.snapshot->counters.frames) + " frames, " +
        (result.snapshot->graph ? std::to_string(result.snapshot->graph->keyframes.size()) + " keyframes"
                                : std::string("no keyframe graph"));
  } catch (const SnapshotError &corrupt) {
    if (policy == CorruptSnapshotPolicy::kRefuse) {
      throw SnapshotError(std::string(corrupt.what()) +
                          "; refusing to start (persistence.on_corrupt_snapshot: refuse)");
    }
    result.moved_aside_to = move_aside(file);
    result.message =
        std::string(corrupt.what()) + "; kept as " + result.moved_aside_to.string() + ", starting a new map";
  }
  return result;
}

std::uint64_t config_file_hash(const std::filesystem::path &file) {
  if (file.empty()) return 0;
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot open the file");
  std::uint64_t hash = 0xcbf29ce484222325ull;  // FNV-1a offset basis and prime
  for (std::istreambuf_iterator<char> it(in), end; it != end; ++it) {
    hash ^= static_cast<std::uint8_t>(*it);
    hash *= 0x100000001b3ull;
  }
  return hash;
}

}  // namespace omnislam::io
