"""ROS 2 interop without ROS 2, on one live run of omnislamd over sim-room-37 (20 Hz):

- scripts/omnislam-record writes a rosbag2 bag with MCAP storage; rosbags reads it back with
  every topic under its ROS 2 name and type, and every message deserialises;
- golden bytes: each recorded sample is the CDR omnislamd put on the wire, and rosbags (an
  independent implementation of the ROS 2 message layouts) serialises the values it decodes
  from it into the same bytes (up to the end padding Cyclone declares in the encapsulation
  header, see same_cdr), while those values are the ones omnislamd meant (the
  pose of trajectory.tum, the grid of map.pgm, REP-105 frame ids); the inputs omnislamd reads
  (nav_msgs/Odometry, rt/initialpose) are checked the other way round, from known values;
- `omnislam map export` of the run's snapshot, loaded by nav2_map_server's trinary rules,
  reproduces the last /map grid cell for cell.

Loopback-only Cyclone config, a domain id of its own. Run by ctest ("dds: ROS 2 interop")."""
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy
import pytest

REPO = Path(__file__).resolve().parents[2]
DATASET = REPO / "datasets" / "sim-room-37"
pytestmark = pytest.mark.skipif(not os.environ.get("OMNISLAMD_BIN"), reason="needs OMNISLAMD_BIN (ctest sets it)")

os.environ.setdefault("CYCLONEDDS_URI", (REPO / "deploy" / "cyclonedds.xml").as_uri())
sys.path.insert(0, str(REPO / "scripts"))
import omnislam_msgs as m  # noqa: E402
from omnislam_ros2 import PUBLISHED, TOPICS, typestore  # noqa: E402
from helpers import dds_domain  # noqa: E402
from rosbags.rosbag2 import Reader  # noqa: E402


def nav2_trinary(yaml_file: Path):
    """A map file as nav2_map_server loads it in trinary mode (its documented rules), as
    (width, height, resolution, origin, cells in OccupancyGrid order)."""
    fields = {}
    for line in yaml_file.read_text().splitlines():
        key, _, value = line.partition(":")
        fields[key.strip()] = value.strip()
    assert fields["mode"] == "trinary"
    negate = int(fields["negate"]) != 0
    occupied, free = float(fields["occupied_thresh"]), float(fields["free_thresh"])
    raw = (yaml_file.parent / fields["image"]).read_bytes()
    magic, size, maxval, pixels = raw.split(b"\n", 3)
    assert magic == b"P5" and maxval == b"255"
    width, height = map(int, size.split())
    cells = []
    for row in range(height - 1, -1, -1):  # the image's top row is the grid's highest y
        for v in pixels[row * width:(row + 1) * width]:
            p = v / 255.0 if negate else (255 - v) / 255.0
            cells.append(100 if p > occupied else (0 if p < free else -1))
    origin = [float(x) for x in fields["origin"].strip("[]").split(",")]
    return width, height, float(fields["resolution"]), origin, cells


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    work = tmp_path_factory.mktemp("interop")
    domain = dds_domain(13)
    config = work / "omnislamd.yaml"
    config.write_text(f"""
input: {{source: dataset, path: {DATASET}, rate_hz: 20}}
pipeline: {{mode: replay, profile_period_s: 0.5}}
dds: {{domain_id: {domain}, wait_for_subscribers: 1, wait_timeout_s: 30}}
persistence: {{state_dir: {work / 'state'}, resume: false}}
service: {{output_dir: {work / 'service'}}}
""")
    recorder = subprocess.Popen([sys.executable, str(REPO / "scripts" / "omnislam-record"), "--out",
                                 str(work / "bag"), "--domain", str(domain), "--until-status", "--duration", "120"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert recorder.stdout.readline().startswith("recording ")
    service = subprocess.run([os.environ["OMNISLAMD_BIN"], "--config", str(config)], capture_output=True, text=True,
                             timeout=120)
    out, err = recorder.communicate(timeout=60)
    assert service.returncode == 0, service.stderr + service.stdout
    assert recorder.returncode == 0, err
    print(out)
    return work


def read_bag(path: Path):
    store = typestore()
    messages = {}
    with Reader(path) as bag:
        types = {c.topic: c.msgtype for c in bag.connections}
        qos = {c.topic: c.ext.offered_qos_profiles for c in bag.connections}
        for connection, _timestamp, raw in bag.messages():
            messages.setdefault(connection.topic, []).append(bytes(raw))
    return store, types, qos, messages


def test_recording_lists_every_topic_with_its_ros2_type_and_messages_deserialise(run):
    bag = run / "bag"
    mcap_files = list(bag.glob("*.mcap"))
    assert len(mcap_files) == 1 and mcap_files[0].read_bytes()[:8] == b"\x89MCAP0\r\n"
    assert "storage_identifier: mcap" in (bag / "metadata.yaml").read_text()
    store, types, qos, messages = read_bag(bag)
    assert sorted(types) == sorted(PUBLISHED)
    for topic in PUBLISHED:
        assert types[topic] == TOPICS[topic].ros_type
        assert messages.get(topic), f"no message on {topic}"
        for raw in messages[topic]:
            store.deserialize_cdr(raw, types[topic])
    assert qos["/map"][0].durability.name == "TRANSIENT_LOCAL" and qos["/omnislam/scan"][0].reliability.name == "BEST_EFFORT"
    poses = messages["/omnislam/pose"]
    assert len(poses) == 37
    assert len(messages["/tf"]) > 37  # re-sent between frames


def same_cdr(raw: bytes, expected: bytes) -> bool:
    """The same CDR stream: equal encapsulation kind (bytes 0-1) and body. Cyclone pads the
    body to a multiple of 4 and declares the pad count in the encapsulation options (the low
    two bits of byte 3; XTypes 1.3 sec. 7.6.3.1.2), as ROS 2 over rmw_cyclonedds sends it;
    rosbags writes no end padding and options 0."""
    pad = raw[3] & 3
    body = raw[4:len(raw) - pad]
    return (raw[:3] == expected[:3] and expected[3] == 0 and body == expected[4:]
            and raw[len(raw) - pad:] == bytes(pad) and len(raw[4:]) % 4 == 0 if pad else raw == expected)


def test_golden_bytes_of_every_published_type(run):
    store, types, _qos, messages = read_bag(run / "bag")
    padded = set()
    for topic, samples in messages.items():
        for raw in samples:
            expected = bytes(store.serialize_cdr(store.deserialize_cdr(raw, types[topic]), types[topic]))
            assert same_cdr(raw, expected), f"{topic}: bytes differ from rosbags': {raw[:16].hex()} {expected[:16].hex()}"
            padded.update([topic] if len(raw) != len(expected) else [])
    print("topics whose samples carry Cyclone's declared end padding:", sorted(padded))

    # The values rosbags decodes are the ones omnislamd meant.
    trajectory = {}
    for line in (run / "service" / "trajectory.tum").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            t, x, y, *_ = map(float, line.split())
            trajectory[round(t, 6)] = (x, y)
    for raw in messages["/omnislam/pose"]:
        pose = store.deserialize_cdr(raw, "geometry_msgs/msg/PoseWithCovarianceStamped")
        assert pose.header.frame_id == "map"
        x, y = trajectory[round(pose.header.stamp.sec + pose.header.stamp.nanosec * 1e-9, 6)]
        assert abs(pose.pose.pose.position.x - x) < 1e-6 and abs(pose.pose.pose.position.y - y) < 1e-6
    tf = store.deserialize_cdr(messages["/tf"][-1], "tf2_msgs/msg/TFMessage")
    assert [(t.header.frame_id, t.child_frame_id) for t in tf.transforms] == [("map", "odom")]
    grid = store.deserialize_cdr(messages["/map"][-1], "nav_msgs/msg/OccupancyGrid")
    width, height, resolution, origin, cells = nav2_trinary(run / "service" / "map.yaml")
    assert (grid.info.width, grid.info.height) == (width, height)
    assert list(grid.data) == cells
    assert grid.header.frame_id == "map"
    metadata = store.deserialize_cdr(messages["/map_metadata"][-1], "nav_msgs/msg/MapMetaData")
    assert (metadata.width, metadata.height, metadata.resolution) == (width, height, grid.info.resolution)
    scan = store.deserialize_cdr(messages["/omnislam/scan"][-1], "sensor_msgs/msg/LaserScan")
    assert len(scan.ranges) == 360
    cloud = store.deserialize_cdr(messages["/omnislam/map"][-1], "sensor_msgs/msg/PointCloud2")
    assert [f.name for f in cloud.fields][:3] == ["x", "y", "z"]
    assert cloud.width * cloud.height == len((run / "service" / "map.csv").read_text().splitlines()) - 1
    status = store.deserialize_cdr(messages["/omnislam/status"][-1], "omnislam/msg/Status")
    assert status.state_name == "stopped" and status.frames_out == 37
    profile = store.deserialize_cdr(messages["/omnislam/profile"][-1], "omnislam/msg/StageProfile")
    assert [s.name for s in profile.stages][:2] == ["read", "unwarp"]


def test_golden_files_of_the_read_types_are_rosbags_output():
    """tests/dds/golden/*.hex, against which test_dds_golden checks Cyclone's bytes from our
    IDL, are what rosbags serialises now."""
    sys.path.insert(0, str(REPO / "tests" / "python"))
    from golden_cdr import GOLDEN, golden_hex
    for name, text in golden_hex().items():
        assert (GOLDEN / f"{name}.hex").read_text().strip() == text, f"{name}.hex: run tests/python/golden_cdr.py"


def test_golden_bytes_of_the_types_omnislamd_reads():
    store = typestore()
    header = m.Header_(stamp=m.Time_(sec=1700000000, nanosec=250000000), frame_id="odom")
    pose = m.Pose_(position=m.Point_(x=1.5, y=-2.25, z=0.0), orientation=m.Quaternion_(x=0.0, y=0.0, z=0.6, w=0.8))
    covariance = [0.01 * i for i in range(36)]
    odometry = m.Odometry_(header=header, child_frame_id="base_link",
                           pose=m.PoseWithCovariance_(pose=pose, covariance=covariance),
                           twist=m.TwistWithCovariance_(twist=m.Twist_(linear=m.Vector3_(x=0.3, y=0.0, z=0.0),
                                                                       angular=m.Vector3_(x=0.0, y=0.0, z=0.1)),
                                                        covariance=covariance))
    R = store.types
    expected = R["nav_msgs/msg/Odometry"](
        header=R["std_msgs/msg/Header"](stamp=R["builtin_interfaces/msg/Time"](sec=1700000000, nanosec=250000000),
                                        frame_id="odom"),
        child_frame_id="base_link",
        pose=R["geometry_msgs/msg/PoseWithCovariance"](
            pose=R["geometry_msgs/msg/Pose"](position=R["geometry_msgs/msg/Point"](x=1.5, y=-2.25, z=0.0),
                                             orientation=R["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.6, w=0.8)),
            covariance=numpy.array(covariance, dtype="float64")),
        twist=R["geometry_msgs/msg/TwistWithCovariance"](
            twist=R["geometry_msgs/msg/Twist"](linear=R["geometry_msgs/msg/Vector3"](x=0.3, y=0.0, z=0.0),
                                               angular=R["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.1)),
            covariance=numpy.array(covariance, dtype="float64")))
    assert odometry.serialize() == store.serialize_cdr(expected, "nav_msgs/msg/Odometry")

    initial = m.PoseWithCovarianceStamped_(header=m.Header_(stamp=header.stamp, frame_id="map"),
                                           pose=m.PoseWithCovariance_(pose=pose, covariance=covariance))
    expected_initial = R["geometry_msgs/msg/PoseWithCovarianceStamped"](
        header=R["std_msgs/msg/Header"](stamp=expected.header.stamp, frame_id="map"), pose=expected.pose)
    assert initial.serialize() == store.serialize_cdr(expected_initial, "geometry_msgs/msg/PoseWithCovarianceStamped")


def test_exported_map_files_reproduce_the_published_grid_cell_for_cell(run):
    store, _types, _qos, messages = read_bag(run / "bag")
    grid = store.deserialize_cdr(messages["/map"][-1], "nav_msgs/msg/OccupancyGrid")
    for source in (run / "state" / "state.omnisnap", run / "service"):
        out = run / f"export-{source.name}"
        subprocess.run([os.environ["OMNISLAM_BIN"], "map", "export", str(source), "--out", str(out)], check=True,
                       capture_output=True, timeout=60)
        width, height, resolution, origin, cells = nav2_trinary(out / "map.yaml")
        assert (width, height) == (grid.info.width, grid.info.height)
        assert abs(resolution - grid.info.resolution) < 1e-6
        assert abs(origin[0] - grid.info.origin.position.x) < 1e-6
        assert abs(origin[1] - grid.info.origin.position.y) < 1e-6
        assert cells == list(grid.data)
        assert cells.count(100) > 100 and cells.count(0) > 1000


def test_recorder_names_bad_arguments(tmp_path):
    record = [sys.executable, str(REPO / "scripts" / "omnislam-record")]
    unknown = subprocess.run([*record, "--out", str(tmp_path / "bag"), "/nope"], capture_output=True, text=True,
                             timeout=30)
    assert unknown.returncode == 2 and "unknown topic(s) /nope" in unknown.stderr
    (tmp_path / "taken").mkdir()
    taken = subprocess.run([*record, "--out", str(tmp_path / "taken")], capture_output=True, text=True, timeout=30)
    assert taken.returncode == 2 and f"{tmp_path / 'taken'} exists" in taken.stderr
