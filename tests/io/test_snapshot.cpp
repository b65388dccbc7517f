#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "omnislam/io/snapshot.hpp"
#include "omnislam/slam/planar_pose.hpp"
#include "snapshot_bytes.hpp"

namespace fs = std::filesystem;
using omnislam::io::Snapshot;
using omnislam::io::SnapshotError;

namespace {

fs::path scratch(const std::string &name) {
  const fs::path dir = fs::temp_directory_path() / "omnislam-test-snapshot" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

Snapshot example() {
  Snapshot s;
  s.config_hash = 0x0123456789abcdefull;
  s.t_s = 12.5;
  s.T_map_base = Eigen::Translation2d(1.25, -0.5) * Eigen::Rotation2Dd(0.75);
  s.covariance << 1e-4, 2e-5, 0, 2e-5, 3e-4, 1e-6, 0, 1e-6, 5e-5;
  s.T_odom_base = Eigen::Translation2d(3.5, 0.25) * Eigen::Rotation2Dd(-1.5);
  s.counters = {125, 120, 5, 2, 7};
  s.map_integrations = 120;
  for (int i = 0; i < 50; ++i) s.points.push_back({{0.1 * i, -0.05 * i}, 1 + i % 7, i});
  return s;
}

std::vector<std::uint8_t> file_bytes(const fs::path &file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The version-6 file of the same state: version 7's bytes without the odometry's distance
// factor, the last 24 bytes (has_odometry_scale, factor, sigma).
std::vector<std::uint8_t> as_version_6(std::vector<std::uint8_t> bytes) {
  bytes.resize(bytes.size() - 24);
  bytes[8] = 6;
  omnislam::test::reseal_snapshot(bytes);
  return bytes;
}

void write_bytes(const fs::path &file, const std::vector<std::uint8_t> &bytes) {
  std::ofstream(file, std::ios::binary)
      .write(reinterpret_cast<const char *>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace

TEST_CASE("snapshot: the odometry pose round-trips; version-1 files (without it) are still read",
          "[io][snapshot]") {
  const Snapshot written = example();
  Snapshot read = omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(written), "odom.snap");
  REQUIRE(read.T_odom_base);
  CHECK(read.T_odom_base->translation().isApprox(Eigen::Vector2d(3.5, 0.25), 1e-12));
  CHECK(Eigen::Rotation2Dd(read.T_odom_base->linear()).angle() == Approx(-1.5).margin(1e-12));

  Snapshot without = example();
  without.T_odom_base.reset();
  CHECK_FALSE(omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(without), "none.snap").T_odom_base);

  // Version 1: the same bytes without the 32-byte odometry block after map_integrations
  // (and without version 3's grid and version 4's graph sections, 8 bytes each when empty).
  std::vector<std::uint8_t> v1 = as_version_6(omnislam::io::encode_snapshot(written));
  v1.resize(v1.size() - 16);
  const std::size_t odometry_at = 24 + 8 + 4 * 8 + 9 * 8 + 5 * 8 + 8;
  v1.erase(v1.begin() + static_cast<std::ptrdiff_t>(odometry_at),
           v1.begin() + static_cast<std::ptrdiff_t>(odometry_at + 32));
  v1[8] = 1;
  omnislam::test::reseal_snapshot(v1);
  read = omnislam::io::decode_snapshot(v1, "v1.snap");
  CHECK_FALSE(read.T_odom_base);
  CHECK(read.points.size() == 50);
  CHECK(read.version == 1);
  CHECK(read.points[49].first_seen == 49);
  CHECK(read.counters.dropped == 7);
}

TEST_CASE("snapshot: written atomically and read back exactly", "[io][snapshot]") {
  const fs::path dir = scratch("roundtrip");
  const Snapshot written = example();
  omnislam::io::write_snapshot(dir / "state.snap", written);
  // 24-byte header + 200-byte fixed payload + 24 bytes per point + has_grid 0 + has_graph 0
  // + has_odometry_scale 0 with its two doubles; no temporary left over.
  CHECK(fs::file_size(dir / "state.snap") == 24 + 200 + 24 * 50 + 8 + 8 + 24);
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);

  const Snapshot read = omnislam::io::read_snapshot(dir / "state.snap");
  CHECK(read.config_hash == 0x0123456789abcdefull);
  CHECK(read.t_s == 12.5);
  CHECK(read.T_map_base.translation().x() == 1.25);
  CHECK(read.T_map_base.translation().y() == -0.5);
  CHECK(omnislam::slam::yaw_rad_of(read.T_map_base) == Approx(0.75).epsilon(1e-15));
  CHECK(read.covariance == written.covariance);
  CHECK(read.counters.frames == 125);
  CHECK(read.counters.integrated == 120);
  CHECK(read.counters.not_integrated == 5);
  CHECK(read.counters.skipped == 2);
  CHECK(read.counters.dropped == 7);
  CHECK(read.map_integrations == 120);
  REQUIRE(read.points.size() == 50);
  CHECK(read.points[49].position_m.x() == written.points[49].position_m.x());
  CHECK(read.points[49].position_m.y() == written.points[49].position_m.y());
  CHECK(read.points[49].hits == 1 + 49 % 7);
  CHECK(read.points[49].first_seen == 49);

  // Replacing an existing snapshot keeps one file holding the new state.
  Snapshot next = written;
  next.counters.frames = 126;
  next.points.resize(3);
  omnislam::io::write_snapshot(dir / "state.snap", next);
  CHECK(omnislam::io::read_snapshot(dir / "state.snap").counters.frames == 126);
  CHECK(omnislam::io::read_snapshot(dir / "state.snap").points.size() == 3);
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);
}

TEST_CASE("snapshot: an empty map and the default pose round-trip", "[io][snapshot]") {
  const fs::path dir = scratch("empty");
  omnislam::io::write_snapshot(dir / "empty.snap", Snapshot{});
  const Snapshot read = omnislam::io::read_snapshot(dir / "empty.snap");
  CHECK(read.points.empty());
  CHECK(read.T_map_base.isApprox(Eigen::Isometry2d::Identity()));
  CHECK(read.counters.frames == 0);
}

TEST_CASE("snapshot: truncation, bit flips, other versions and bad values are rejected by name",
          "[io][snapshot]") {
  const std::vector<std::uint8_t> good = omnislam::io::encode_snapshot(example());
  // Every truncation is caught, whatever the length.
  for (std::size_t length = 0; length < good.size(); ++length) {
    const std::vector<std::uint8_t> cut(good.begin(), good.begin() + static_cast<long>(length));
    CHECK_THROWS_AS(omnislam::io::decode_snapshot(cut, "cut.snap"), SnapshotError);
  }
  const std::vector<std::uint8_t> header_only(good.begin(), good.begin() + 30);
  CHECK_THROWS_WITH(omnislam::io::decode_snapshot(header_only, "cut.snap"),
                    Catch::Contains("cut.snap: truncated") && Catch::Contains("1440 payload bytes") &&
                        Catch::Contains("has 6"));
  // A flipped bit anywhere after the magic fails the checksum (or, in the size field, the length).
  for (std::size_t i = 8; i < good.size(); i += 37) {
    std::vector<std::uint8_t> flipped = good;
    flipped[i] ^= 0x10;
    CHECK_THROWS_AS(omnislam::io::decode_snapshot(flipped, "flip.snap"), SnapshotError);
  }
  std::vector<std::uint8_t> flipped = good;
  flipped[100] ^= 0x01;
  CHECK_THROWS_WITH(omnislam::io::decode_snapshot(flipped, "flip.snap"),
                    Catch::Equals("flip.snap: checksum mismatch (the file is corrupt)"));
  std::vector<std::uint8_t> magic = good;
  magic[0] = 'X';
  CHECK_THROWS_WITH(omnislam::io::decode_snapshot(magic, "other.bin"), Catch::Contains("bad magic"));
  std::vector<std::uint8_t> longer = good;
  longer.push_back(0);
  CHECK_THROWS_WITH(omnislam::io::decode_snapshot(longer, "long.snap"), Catch::Contains("trailing bytes"));
}

TEST_CASE("snapshot: a future version or impossible values are named even with a valid checksum",
          "[io][snapshot]") {
  // A version-8 file (as a newer build would write it) has a valid CRC of its own.
  std::vector<std::uint8_t> v8 = omnislam::io::encode_snapshot(example());
  v8[8] = 8;
  omnislam::test::reseal_snapshot(v8);
  CHECK_THROWS_WITH(
      omnislam::io::decode_snapshot(v8, "v8.snap"),
      Catch::Equals("v8.snap: unsupported snapshot version 8 (this build reads versions 1 to 7)"));

  Snapshot bad = example();
  bad.points[3].hits = 0;
  CHECK_THROWS_WITH(omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(bad), "hits.snap"),
                    Catch::Contains("map point 3 has hits 0"));
  bad = example();
  bad.points[4].first_seen = 121;
  CHECK_THROWS_WITH(omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(bad), "age.snap"),
                    Catch::Contains("first_seen 121 (map_integrations 120)"));
  bad = example();
  bad.t_s = std::nan("");
  CHECK_THROWS_WITH(omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(bad), "nan.snap"),
                    Catch::Contains("t_s is not a finite number"));
}

TEST_CASE("snapshot: a corrupt file is moved aside as .corrupt-N; resume starts fresh or refuses",
          "[io][snapshot]") {
  const fs::path dir = scratch("resume");
  const fs::path file = dir / "state.snap";
  using omnislam::io::CorruptSnapshotPolicy;

  auto fresh = omnislam::io::resume_from_snapshot(file, CorruptSnapshotPolicy::kStartFresh);
  CHECK_FALSE(fresh.snapshot);
  CHECK_THAT(fresh.message, Catch::Contains("no snapshot") && Catch::Contains("starting a new map"));

  omnislam::io::write_snapshot(file, example());
  auto resumed = omnislam::io::resume_from_snapshot(file, CorruptSnapshotPolicy::kRefuse);
  REQUIRE(resumed.snapshot);
  CHECK(resumed.snapshot->points.size() == 50);
  CHECK_THAT(resumed.message, Catch::Contains("50 map points, 125 frames"));

  std::vector<std::uint8_t> bytes = file_bytes(file);
  bytes.resize(bytes.size() - 10);
  write_bytes(file, bytes);
  CHECK_THROWS_WITH(omnislam::io::resume_from_snapshot(file, CorruptSnapshotPolicy::kRefuse),
                    Catch::Contains("truncated") && Catch::Contains("refusing to start"));
  CHECK(fs::exists(file));  // an operator decides what happens to it

  auto moved = omnislam::io::resume_from_snapshot(file, CorruptSnapshotPolicy::kStartFresh);
  CHECK_FALSE(moved.snapshot);
  CHECK(moved.moved_aside_to == dir / "state.snap.corrupt-1");
  CHECK(fs::file_size(dir / "state.snap.corrupt-1") == bytes.size());
  CHECK_FALSE(fs::exists(file));
  CHECK_THAT(moved.message, Catch::Contains("state.snap.corrupt-1") && Catch::Contains("starting a new map"));

  write_bytes(file, {1, 2, 3});
  CHECK(omnislam::io::move_aside(file) == dir / "state.snap.corrupt-2");
}

TEST_CASE("snapshot: writing into a missing directory fails with the path", "[io][snapshot]") {
  CHECK_THROWS_WITH(omnislam::io::write_snapshot("/nonexistent-omnislam/state.snap", example()),
                    Catch::Contains("/nonexistent-omnislam/state.snap.tmp"));
}

TEST_CASE("config file hash: FNV-1a of the bytes", "[io][snapshot]") {
  const fs::path dir = scratch("hash");
  std::ofstream(dir / "empty.yaml").flush();
  { std::ofstream(dir / "a.yaml") << "a"; }
  CHECK(omnislam::io::config_file_hash("") == 0);
  CHECK(omnislam::io::config_file_hash(dir / "empty.yaml") == 0xcbf29ce484222325ull);
  CHECK(omnislam::io::config_file_hash(dir / "a.yaml") == 0xaf63dc4c8601ec8cull);
}

namespace {

omnislam::grid::GridImage example_grid() {
  omnislam::grid::GridImage g;
  g.width = 7;
  g.height = 3;
  g.resolution_m = 0.05;
  g.origin_m = {-1.25, 0.4};
  for (int i = 0; i < g.width * g.height; ++i) g.cells.push_back(i % 3 == 0 ? -1 : (i % 3 == 1 ? 0 : 100));
  for (int i = 0; i < g.width * g.height; ++i)
    g.above_floor.push_back(i % 6 == 2 ? 1 : 0);  // some occupied cells
  return g;
}

}  // namespace

TEST_CASE(
    "snapshot: the occupancy grid (since version 3) round-trips with what stood above the floor "
    "(since version 5); version-4, -3 and -2 files still read",
    "[io][snapshot]") {
  Snapshot written = example();
  written.grid = example_grid();
  const std::vector<std::uint8_t> v5 = as_version_6(omnislam::io::encode_snapshot(written));
  CHECK(v5.size() == 24 + 200 + 24 * 50 + 8 + 32 + 21 + 21 + 8);
  const Snapshot read = omnislam::io::decode_snapshot(v5, "grid.snap");
  CHECK(read.version == 6);  // without a graph version 6's bytes are version 5's
  REQUIRE(read.grid);
  CHECK(read.grid->width == 7);
  CHECK(read.grid->height == 3);
  CHECK(read.grid->resolution_m == 0.05);
  CHECK(read.grid->origin_m == Eigen::Vector2d(-1.25, 0.4));
  CHECK(read.grid->cells == written.grid->cells);
  CHECK(read.grid->above_floor == written.grid->above_floor);
  CHECK(read.points.size() == 50);
  // A grid without flags (read from a map file) is written as none above the floor.
  Snapshot unflagged = written;
  unflagged.grid->above_floor.clear();
  const Snapshot zeros =
      omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(unflagged), "zeros.snap");
  CHECK(zeros.grid->above_floor == std::vector<std::uint8_t>(21, 0));

  // Version 4: version 5 without the flags (the 21 bytes before has_graph), still read.
  std::vector<std::uint8_t> v4 = v5;
  v4.erase(v4.end() - 8 - 21, v4.end() - 8);
  v4[8] = 4;
  omnislam::test::reseal_snapshot(v4);
  const Snapshot four = omnislam::io::decode_snapshot(v4, "v4.snap");
  CHECK(four.version == 4);
  REQUIRE(four.grid);
  CHECK(four.grid->cells == written.grid->cells);
  CHECK(four.grid->above_floor.empty());

  // Version 3: version 4 without the graph section (has_graph 0: 8 bytes), still read.
  std::vector<std::uint8_t> v3 = v4;
  v3.resize(v3.size() - 8);
  v3[8] = 3;
  omnislam::test::reseal_snapshot(v3);
  const Snapshot three = omnislam::io::decode_snapshot(v3, "v3.snap");
  CHECK(three.version == 3);
  REQUIRE(three.grid);
  CHECK(three.grid->cells == written.grid->cells);
  CHECK(three.points.size() == 50);
  CHECK_FALSE(three.graph);

  // Version 2: version 3 without the grid section.
  std::vector<std::uint8_t> v2 = as_version_6(omnislam::io::encode_snapshot(example()));
  v2.resize(v2.size() - 16);
  v2[8] = 2;
  omnislam::test::reseal_snapshot(v2);
  const Snapshot old = omnislam::io::decode_snapshot(v2, "v2.snap");
  CHECK(old.version == 2);
  CHECK_FALSE(old.grid);
  CHECK(old.points.size() == 50);

  // A cell that is not -1, 0 or 100, and a grid shorter than announced, are named.
  omnislam::grid::GridImage odd_cell = example_grid(), short_grid = example_grid();
  odd_cell.cells[5] = 42;
  short_grid.cells.pop_back();
  Snapshot bad = example();
  bad.grid = std::move(odd_cell);
  CHECK_THROWS_WITH(omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(bad), "cell.snap"),
                    Catch::Equals("cell.snap: occupancy grid cell 5 is 42 (not -1, 0 or 100)"));
  bad.grid = std::move(short_grid);
  CHECK_THROWS_WITH(
      omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(bad), "short.snap"),
      Catch::Contains(
          "short.snap: the occupancy grid announces 21 cells (42 bytes), the file holds 40 bytes"));
  // A flag that is not 0 or 1 is named.
  std::vector<std::uint8_t> odd_flag = v5;
  const std::size_t flag_at = v5.size() - 8 - 21 + 4;  // cell 4's flag, before has_graph
  odd_flag.at(flag_at) = 7;
  omnislam::test::reseal_snapshot(odd_flag);
  CHECK_THROWS_WITH(omnislam::io::decode_snapshot(odd_flag, "flag.snap"),
                    Catch::Equals("flag.snap: occupancy grid cell 4 has above-floor flag 7 (not 0 or 1)"));
  // Every truncation of a file with a grid is caught too.
  for (std::size_t length = v5.size() - 80; length < v5.size(); ++length) {
    std::vector<std::uint8_t> cut(v5.begin(), v5.begin() + static_cast<long>(length));
    omnislam::test::reseal_snapshot(cut);
    CHECK_THROWS_AS(omnislam::io::decode_snapshot(cut, "cut.snap"), SnapshotError);
  }
}

namespace {

using omnislam::slam::KeyframeGraphState;

// Three keyframes of 40 scans each (120 integrations, as example()'s map), integrated
// keyframe after keyframe; sequential edges 0-1 and 1-2 and a loop edge 0-2.
KeyframeGraphState example_graph() {
  KeyframeGraphState g;
  for (int k = 0; k < 3; ++k) {
    KeyframeGraphState::SavedKeyframe keyframe{{0.5 * k, 0.1 * k, 0.3 * k - 0.1}, 0.6 * k, {}};
    keyframe.covariance << 4e-6 * (k + 1), 1e-7, 2e-8 * k, 1e-7, 9e-6 * (k + 1), 0.0, 2e-8 * k, 0.0,
        3e-5 * (k + 1);
    for (int scan = 0; scan < 40; ++scan) {
      keyframe.scans_keyframe.push_back(std::make_shared<const omnislam::slam::Points2>(
          omnislam::slam::Points2{{1.0 + k, 0.01 * scan}, {-0.5, 2.0 - k}, {0.125 * scan, -1.0 / 3.0}}));
      g.integration_order.emplace_back(k, scan);
    }
    g.keyframes.push_back(std::move(keyframe));
  }
  Eigen::Matrix3d information;
  information << 1e4, 10, 0, 10, 2e4, 5, 0, 5, 3e5;
  g.edges.push_back({0, 1, {0.5, 0.1, 0.3}, information, false});
  g.edges.push_back({1, 2, {0.49, 0.11, 0.31}, information, false});
  g.edges.push_back({0, 2, {1.0, 0.2, 0.6}, 0.5 * information, true});
  g.path_m = 1.4;
  g.last_frame = {1.1, 0.25, 0.55};
  return g;
}

Snapshot example_with_graph() {
  Snapshot s = example();
  s.graph = example_graph();
  return s;
}

bool same_pose(const omnislam::slam::PlanarPose &a, const omnislam::slam::PlanarPose &b) {
  return a.x_m == b.x_m && a.y_m == b.y_m && a.yaw_rad == b.yaw_rad;
}

// Re-encodes `s` with its graph edited by `edit`: the writer does not check, the reader must.
std::vector<std::uint8_t> with_graph(const std::function<void(KeyframeGraphState &)> &edit) {
  Snapshot s = example_with_graph();
  edit(*s.graph);
  return omnislam::io::encode_snapshot(s);
}

void put_u64(std::vector<std::uint8_t> &bytes, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i)
    bytes[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
}

}  // namespace

TEST_CASE("snapshot: version 4 and later carry the keyframe graph exactly; re-encoding gives the same bytes",
          "[io][snapshot]") {
  Snapshot written = example_with_graph();
  written.grid = example_grid();
  const std::vector<std::uint8_t> bytes = omnislam::io::encode_snapshot(written);
  // The graph section: 8 (has_graph) + 32 + 3 keyframes x (40 + 72 + 40 scans x (8 + 3 x 16))
  // + 8 + 120 x 8 + 8 + 3 x 112.
  const std::size_t graph_at = 24 + 200 + 24 * 50 + 8 + 32 + 21 + 21;
  CHECK(bytes.size() == graph_at + 8 + 32 + 8 + 3 * (40 + 72 + 40 * 56) + 8 + 960 + 8 + 336 + 24);
  const Snapshot read = omnislam::io::decode_snapshot(bytes, "graph.snap");
  CHECK(read.version == 7);
  REQUIRE(read.grid);
  REQUIRE(read.graph);
  const KeyframeGraphState &want = *written.graph, &got = *read.graph;
  REQUIRE(got.keyframes.size() == 3);
  for (std::size_t k = 0; k < 3; ++k) {
    CHECK(same_pose(got.keyframes[k].T_map_keyframe, want.keyframes[k].T_map_keyframe));
    CHECK(got.keyframes[k].path_m == want.keyframes[k].path_m);
    CHECK(got.keyframes[k].covariance == want.keyframes[k].covariance);
    REQUIRE(got.keyframes[k].scans_keyframe.size() == 40);
    for (std::size_t scan = 0; scan < 40; ++scan)
      CHECK(*got.keyframes[k].scans_keyframe[scan] == *want.keyframes[k].scans_keyframe[scan]);
  }
  CHECK(got.integration_order == want.integration_order);
  REQUIRE(got.edges.size() == 3);
  for (std::size_t e = 0; e < 3; ++e) {
    CHECK(got.edges[e].from == want.edges[e].from);
    CHECK(got.edges[e].to == want.edges[e].to);
    CHECK(same_pose(got.edges[e].T_from_to, want.edges[e].T_from_to));
    CHECK(got.edges[e].information == want.edges[e].information);
    CHECK(got.edges[e].loop == want.edges[e].loop);
  }
  CHECK(got.path_m == 1.4);
  CHECK(same_pose(got.last_frame, want.last_frame));
  CHECK(omnislam::io::encode_snapshot(read) == bytes);

  // Version 5: version 6 without the keyframes' covariances (72 bytes after each keyframe's
  // pose and path), still read, with zero covariances.
  std::vector<std::uint8_t> v5 = as_version_6(bytes);
  for (int k = 2; k >= 0; --k) {
    const std::size_t at = graph_at + 8 + 32 + 8 + static_cast<std::size_t>(k) * (40 + 72 + 40 * 56) + 32;
    v5.erase(v5.begin() + static_cast<std::ptrdiff_t>(at), v5.begin() + static_cast<std::ptrdiff_t>(at + 72));
  }
  v5[8] = 5;
  omnislam::test::reseal_snapshot(v5);
  const Snapshot five = omnislam::io::decode_snapshot(v5, "v5.snap");
  CHECK(five.version == 5);
  REQUIRE(five.graph);
  REQUIRE(five.graph->keyframes.size() == 3);
  for (std::size_t k = 0; k < 3; ++k) {
    CHECK(same_pose(five.graph->keyframes[k].T_map_keyframe, want.keyframes[k].T_map_keyframe));
    CHECK(five.graph->keyframes[k].covariance.isZero());
    CHECK(*five.graph->keyframes[k].scans_keyframe[39] == *want.keyframes[k].scans_keyframe[39]);
  }
  CHECK(five.graph->edges.size() == 3);

  // Without a graph: one u64 0 where the graph would be.
  const std::vector<std::uint8_t> none = omnislam::io::encode_snapshot(example());
  CHECK_FALSE(omnislam::io::decode_snapshot(none, "none.snap").graph);
  CHECK(omnislam::io::encode_snapshot(omnislam::io::decode_snapshot(none, "none.snap")) == none);
}

TEST_CASE("snapshot: a version-4 keyframe graph that does not hold together is rejected by name",
          "[io][snapshot]") {
  using Graph = KeyframeGraphState;
  const auto rejects = [](const std::vector<std::uint8_t> &bytes, const std::string &message) {
    CHECK_THROWS_WITH(omnislam::io::decode_snapshot(bytes, "bad.snap"),
                      Catch::Equals("bad.snap: " + message));
  };
  rejects(with_graph([](Graph &g) { g.edges[2].to = 3; }),
          "keyframe graph: edge 2 joins keyframes 0 and 3 (3 keyframes)");
  rejects(with_graph([](Graph &g) { g.edges[0].from = 1; }),
          "keyframe graph: edge 0 joins keyframes 1 and 1 (3 keyframes)");
  rejects(with_graph([](Graph &g) { g.edges[1].information.setZero(); }),
          "keyframe graph: edge 1: information is not symmetric positive definite");
  rejects(with_graph([](Graph &g) { g.edges[1].information(0, 1) = -3.0; }),
          "keyframe graph: edge 1: information is not symmetric positive definite");
  rejects(with_graph([](Graph &g) {
            g.integration_order.back() = {2, 40};
          }),
          "keyframe graph: integration 119 names scan 40 of keyframe 2, which does not exist");
  rejects(with_graph([](Graph &g) {
            g.integration_order[5] = {0, 4};
          }),
          "keyframe graph: integration 5 names scan 4 of keyframe 0, named before");
  rejects(with_graph([](Graph &g) { g.integration_order.pop_back(); }),
          "keyframe graph: the integration order names 119 scans, the keyframes hold 120");
  rejects(with_graph([](Graph &g) {
            g.integration_order.pop_back();
            g.keyframes[2].scans_keyframe.pop_back();
          }),
          "the keyframe graph holds 119 integrated scans, the map 120");
  rejects(
      with_graph([](Graph &g) { g.keyframes[2].path_m = 0.5; }),
      "keyframe graph: keyframe 2: path_m 0.500000 is not finite or below the previous keyframe's 0.600000");
  rejects(with_graph([](Graph &g) { g.path_m = 1.0; }),
          "keyframe graph: path_m 1.000000 is not finite or below the last keyframe's");
  rejects(with_graph([](Graph &g) {
            g.keyframes[1].scans_keyframe[7] =
                std::make_shared<const omnislam::slam::Points2>(omnislam::slam::Points2{{std::nan(""), 0.0}});
          }),
          "keyframe 1 scan point x_m is not a finite number");
  rejects(with_graph([](Graph &g) { g.edges[2].T_from_to.yaw_rad = INFINITY; }),
          "edge 2 yaw_rad is not a finite number");
  rejects(with_graph([](Graph &g) { g.keyframes[1].covariance(2, 2) = -1e-3; }),
          "keyframe graph: keyframe 1: covariance is not symmetric positive semi-definite");
  rejects(with_graph([](Graph &g) { g.keyframes[2].covariance(0, 1) = 1e-3; }),
          "keyframe graph: keyframe 2: covariance is not symmetric positive semi-definite");

  // Flags and counts edited in the bytes (the writer cannot produce them).
  const std::vector<std::uint8_t> good = as_version_6(omnislam::io::encode_snapshot(example_with_graph()));
  const std::size_t edges_at = good.size() - 3 * 112 - 8;  // the edge count
  std::vector<std::uint8_t> bytes = good;
  put_u64(bytes, good.size() - 112 + 8, 2);  // the last edge's loop flag
  omnislam::test::reseal_snapshot(bytes);
  rejects(bytes, "keyframe graph edge 2 loop is 2");
  bytes = good;
  put_u64(bytes, edges_at, 1000000000000ull);
  omnislam::test::reseal_snapshot(bytes);
  rejects(bytes, "the keyframe graph announces 1000000000000 edges, the 336 bytes left cannot hold them");
  bytes = good;
  put_u64(bytes, edges_at, 2);
  omnislam::test::reseal_snapshot(bytes);
  rejects(bytes, "trailing bytes after the keyframe graph");
  bytes = as_version_6(omnislam::io::encode_snapshot(example()));
  put_u64(bytes, bytes.size() - 8, 2);  // has_graph
  omnislam::test::reseal_snapshot(bytes);
  rejects(bytes, "has_graph is 2");
  // Every truncation of the graph section, resealed, is caught.
  const std::size_t graph_at = as_version_6(omnislam::io::encode_snapshot(example())).size() - 8;
  for (std::size_t length = graph_at; length < good.size(); length += 7) {
    std::vector<std::uint8_t> cut(good.begin(), good.begin() + static_cast<long>(length));
    omnislam::test::reseal_snapshot(cut);
    CHECK_THROWS_AS(omnislam::io::decode_snapshot(cut, "cut.snap"), SnapshotError);
  }
}

TEST_CASE("snapshot: version 7 carries the odometry's distance factor; version 6 files read without it",
          "[io][snapshot]") {
  Snapshot written = example_with_graph();
  written.odometry_scale = omnislam::io::SnapshotOdometryScale{0.9712, 0.0034};
  const std::vector<std::uint8_t> bytes = omnislam::io::encode_snapshot(written);
  const Snapshot read = omnislam::io::decode_snapshot(bytes, "scale.snap");
  CHECK(read.version == 7);
  REQUIRE(read.odometry_scale);
  CHECK(read.odometry_scale->factor == 0.9712);
  CHECK(read.odometry_scale->sigma == 0.0034);
  REQUIRE(read.graph);
  CHECK(omnislam::io::encode_snapshot(read) == bytes);
  CHECK_FALSE(
      omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(example()), "none.snap").odometry_scale);
  // Version 6: the same state without the section, still read.
  const Snapshot six = omnislam::io::decode_snapshot(as_version_6(bytes), "v6.snap");
  CHECK(six.version == 6);
  CHECK_FALSE(six.odometry_scale);
  CHECK(six.graph->keyframes.size() == 3);
  // A flag other than 0 or 1, a factor that is not positive, a negative sigma, and every
  // truncation of the section are named.
  std::vector<std::uint8_t> flag = bytes;
  put_u64(flag, bytes.size() - 24, 3);
  omnislam::test::reseal_snapshot(flag);
  CHECK_THROWS_WITH(omnislam::io::decode_snapshot(flag, "flag.snap"),
                    Catch::Equals("flag.snap: has_odometry_scale is 3"));
  Snapshot bad = written;
  bad.odometry_scale->factor = -1.0;
  CHECK_THROWS_WITH(omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(bad), "factor.snap"),
                    Catch::Contains("factor.snap: odometry distance factor -1.000000"));
  bad.odometry_scale = omnislam::io::SnapshotOdometryScale{1.01, -0.1};
  CHECK_THROWS_AS(omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(bad), "sigma.snap"),
                  SnapshotError);
  bad.odometry_scale->sigma = std::nan("");
  CHECK_THROWS_WITH(omnislam::io::decode_snapshot(omnislam::io::encode_snapshot(bad), "nan.snap"),
                    Catch::Contains("odometry scale sigma is not a finite number"));
  for (std::size_t length = bytes.size() - 24; length < bytes.size(); ++length) {
    std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<long>(length));
    omnislam::test::reseal_snapshot(cut);
    CHECK_THROWS_AS(omnislam::io::decode_snapshot(cut, "cut.snap"), SnapshotError);
  }
}
