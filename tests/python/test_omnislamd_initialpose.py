"""omnislamd with rt/initialpose (geometry_msgs/PoseWithCovarianceStamped, as RViz's "2D Pose
Estimate" publishes it: reliable, volatile): the pose sets SLAM's pose for the next frame; a
pose in another frame than `map` is ignored, logged and reported in the status' last_error.

This process publishes the initial poses before omnislamd starts its frames (it waits for a
pose reader: dds.wait_for_subscribers), so the first frame is the one that gets them: the
map starts at the given pose and the whole trajectory is `omnislam replay`'s, moved by it.
Loopback-only Cyclone config, a domain id of its own. Run by ctest ("dds: omnislamd
rt/initialpose")."""

import math
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DATASET = REPO / "datasets" / "sim-room-37"
pytestmark = pytest.mark.skipif(not os.environ.get("OMNISLAMD_BIN"), reason="needs OMNISLAMD_BIN (ctest sets it)")

os.environ.setdefault("CYCLONEDDS_URI", (REPO / "deploy" / "cyclonedds.xml").as_uri())
from cyclonedds.core import Policy, Qos  # noqa: E402  (after CYCLONEDDS_URI)
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.pub import DataWriter  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402
from cyclonedds.util import duration  # noqa: E402

sys.path.insert(0, str(REPO / "scripts"))
from omnislam_msgs import (Header_, Point_, Pose_, PoseWithCovariance_, PoseWithCovarianceStamped_,  # noqa: E402
                           Quaternion_, Status_, Time_)

RELIABLE = Policy.Reliability.Reliable(duration(seconds=1))


def initial_pose(frame_id: str, x: float, y: float, yaw: float) -> PoseWithCovarianceStamped_:
    covariance = [0.0] * 36
    covariance[0] = covariance[7] = 0.25 ** 2
    covariance[35] = math.radians(10) ** 2
    now = time.time()
    return PoseWithCovarianceStamped_(
        header=Header_(stamp=Time_(sec=int(now), nanosec=int((now % 1) * 1e9)), frame_id=frame_id),
        pose=PoseWithCovariance_(pose=Pose_(position=Point_(x=x, y=y, z=0.0),
                                            orientation=Quaternion_(x=0.0, y=0.0, z=math.sin(yaw / 2),
                                                                    w=math.cos(yaw / 2))),
                                 covariance=covariance))


def read_tum(path: Path) -> list[tuple[float, float, float, float]]:
    poses = []
    for line in path.read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            t, x, y, _z, _qx, _qy, qz, qw = map(float, line.split())
            poses.append((t, x, y, 2.0 * math.atan2(qz, qw)))
    return poses


def compose(a, b):
    """(x, y, yaw) a * b."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2]


def wait_until(condition, timeout_s: float, what: str):
    deadline = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.05)


def test_initial_pose_moves_the_map_frame_and_a_foreign_frame_is_rejected(tmp_path):
    replay = tmp_path / "replay"
    subprocess.run([os.environ["OMNISLAM_BIN"], "replay", str(DATASET), "--out", str(replay)], check=True,
                   capture_output=True, timeout=120)
    expected = read_tum(replay / "trajectory.tum")

    domain = 100 + (os.getpid() * 2 + 11) % 100  # the scheme of the other DDS tests, an offset of its own
    config = tmp_path / "omnislamd.yaml"
    config.write_text(f"""
input: {{source: dataset, path: {DATASET}, rate_hz: 0}}
pipeline: {{mode: replay}}
dds: {{domain_id: {domain}, wait_for_subscribers: 1, wait_timeout_s: 30}}
""")
    log_file = (tmp_path / "omnislamd.log").open("w")
    service = subprocess.Popen([os.environ["OMNISLAMD_BIN"], "--config", str(config)], stdout=log_file,
                               stderr=subprocess.STDOUT, env=dict(os.environ))
    try:
        participant = DomainParticipant(domain)
        writer = DataWriter(participant, Topic(participant, "rt/initialpose", PoseWithCovarianceStamped_),
                            qos=Qos(RELIABLE, Policy.Durability.Volatile, Policy.History.KeepLast(10)))
        wait_until(lambda: len(writer.get_matched_subscriptions()) > 0, 30, "omnislamd's rt/initialpose reader")
        start = (1.5, -0.75, math.radians(30))
        writer.write(initial_pose("odom", 9.0, 9.0, 0.0))  # not the map frame: ignored
        writer.write(initial_pose("map", *start))
        writer.wait_for_acks(duration(seconds=10))  # both are in omnislamd's reader before frame 1

        status_reader = DataReader(participant, Topic(participant, "rt/omnislam/status", Status_),
                                   qos=Qos(RELIABLE, Policy.Durability.TransientLocal, Policy.History.KeepLast(1)))
        poses, stopped = [], None
        pose_reader = DataReader(participant, Topic(participant, "rt/omnislam/pose", PoseWithCovarianceStamped_),
                                 qos=Qos(RELIABLE, Policy.History.KeepLast(100)))
        deadline = time.monotonic() + 120
        while stopped is None and time.monotonic() < deadline:
            for sample in pose_reader.take(N=100):
                if isinstance(sample, PoseWithCovarianceStamped_):
                    p = sample.pose.pose
                    poses.append((p.position.x, p.position.y,
                                  2.0 * math.atan2(p.orientation.z, p.orientation.w)))
            for sample in status_reader.take(N=10):
                if isinstance(sample, Status_) and sample.state in (3, 4):  # stopped, failed
                    stopped = sample
            time.sleep(0.02)
        assert service.wait(timeout=60) == 0
    finally:
        if service.poll() is None:
            service.kill()
        log_file.close()
    log = (tmp_path / "omnislamd.log").read_text()
    for sample in pose_reader.take(N=100):  # what arrived with the final status
        if isinstance(sample, PoseWithCovarianceStamped_):
            p = sample.pose.pose
            poses.append((p.position.x, p.position.y, 2.0 * math.atan2(p.orientation.z, p.orientation.w)))

    assert stopped is not None, log
    assert len(poses) == len(expected) == 37, log
    # The first frame seeds the map at the initial pose exactly ...
    assert abs(poses[0][0] - start[0]) < 1e-9 and abs(poses[0][1] - start[1]) < 1e-9
    assert abs(math.remainder(poses[0][2] - start[2], 2 * math.pi)) < 1e-9
    # ... and every later pose is the replay's (map = first pose) moved by it.
    worst_m = 0.0
    for (x, y, yaw), (_t, ex, ey, eyaw) in zip(poses, expected):
        mx, my, myaw = compose(start, (ex, ey, eyaw))
        worst_m = max(worst_m, math.hypot(x - mx, y - my))
        assert abs(math.remainder(yaw - myaw, 2 * math.pi)) < math.radians(1.0)
    print(f"largest distance from the moved replay trajectory: {worst_m:.4f} m")
    assert worst_m < 0.01  # measured 0.3 mm: the same registrations in a rotated frame
    assert "initial pose ignored: frame_id 'odom', expected 'map' (dds.tf.map_frame)" in log
    assert "1 initial poses on rt/initialpose applied, 1 in another frame ignored" in log
    assert stopped.last_error == "initial pose ignored: frame_id 'odom', expected 'map' (dds.tf.map_frame)"
