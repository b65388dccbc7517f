"""omnislamd with odometry from DDS (rt/odom, nav_msgs/Odometry): frames are matched to the
samples by time stamp; a gap in the stream is noticed, logged, counted, and the run goes on.

The robot stands still (every image is frame 1 of sim-room-37, the odometry a constant
pose); the publisher here stops for 1.5 s in the middle. Loopback-only Cyclone config, a
domain id of its own. Run by ctest ("dds: omnislamd with rt/odom gaps")."""

import os
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.skipif(not os.environ.get("OMNISLAMD_BIN"), reason="needs OMNISLAMD_BIN (ctest sets it)")

os.environ.setdefault("CYCLONEDDS_URI", (REPO / "deploy" / "cyclonedds.xml").as_uri())
from cyclonedds.core import Policy, Qos  # noqa: E402  (after CYCLONEDDS_URI)
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.pub import DataWriter  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402
from cyclonedds.util import duration  # noqa: E402

sys.path.insert(0, str(REPO / "scripts"))
from omnislam_msgs import (Header_, Odometry_, Point_, Pose_, PoseWithCovariance_, Quaternion_, Time_,  # noqa: E402
                           Twist_, TwistWithCovariance_, Vector3_)


def odometry(stamp: float, x: float) -> Odometry_:
    sec = int(stamp)
    return Odometry_(
        header=Header_(stamp=Time_(sec=sec, nanosec=int((stamp - sec) * 1e9)), frame_id="odom"),
        child_frame_id="base_link",
        pose=PoseWithCovariance_(pose=Pose_(position=Point_(x=x, y=0.0, z=0.0),
                                            orientation=Quaternion_(x=0.0, y=0.0, z=0.0, w=1.0)),
                                 covariance=[0.0] * 36),
        twist=TwistWithCovariance_(twist=Twist_(linear=Vector3_(x=0.0, y=0.0, z=0.0),
                                                angular=Vector3_(x=0.0, y=0.0, z=0.0)),
                                   covariance=[0.0] * 36))


class OdometryPublisher:
    """50 Hz, stamped with the system clock (as frames are); silent during [gap_from, gap_to)
    seconds after start()."""

    def __init__(self, domain: int, gap_from: float, gap_to: float, reliable: bool = True):
        self.participant = DomainParticipant(domain)
        topic = Topic(self.participant, "rt/odom", Odometry_)
        # A base driver's sensor-data QoS is best effort; nav2 examples and ours are reliable.
        reliability = (Policy.Reliability.Reliable(duration(seconds=1)) if reliable
                       else Policy.Reliability.BestEffort)
        self.writer = DataWriter(self.participant, topic, qos=Qos(reliability, Policy.History.KeepLast(50)))
        self.gap = (gap_from, gap_to)
        self.running = True
        self.published = 0
        self.thread = threading.Thread(target=self._run, daemon=True)

    def start(self):
        self.thread.start()

    def _run(self):
        start = time.monotonic()
        while self.running:
            since = time.monotonic() - start
            if not self.gap[0] <= since < self.gap[1]:
                self.writer.write(odometry(time.time(), 0.0))
                self.published += 1
            time.sleep(0.02)

    def stop(self):
        self.running = False
        self.thread.join()


def run_standing_still(tmp_path, frames: int, publisher: OdometryPublisher, domain: int) -> str:
    """omnislamd over `frames` copies of sim-room-37's frame 1 at 10 Hz with odometry from
    DDS, `publisher` running; returns its log (the run must succeed)."""
    images = tmp_path / "images"
    images.mkdir()
    first = REPO / "datasets" / "sim-room-37" / "images" / "000001.png"
    for i in range(frames):
        shutil.copy(first, images / f"{i:06d}.png")
    config = tmp_path / "omnislamd.yaml"
    config.write_text(f"""
input: {{source: directory, path: {images}, rate_hz: 10, odometry: dds}}
pipeline: {{mode: replay}}
dds: {{domain_id: {domain}}}
service: {{output_dir: {tmp_path / 'out'}}}
""")
    publisher.start()
    time.sleep(1.0)  # discovery: the first frames find odometry already flowing
    try:
        service = subprocess.run([os.environ["OMNISLAMD_BIN"], "--config", str(config)], capture_output=True,
                                 text=True, timeout=120)
    finally:
        publisher.stop()
    log = service.stdout + service.stderr
    assert service.returncode == 0, log
    return log


def test_odometry_gap_is_noticed_counted_and_the_run_goes_on(tmp_path):
    domain = 100 + (os.getpid() * 2 + 7) % 100
    log = run_standing_still(tmp_path, 40, OdometryPublisher(domain, gap_from=2.0, gap_to=3.5), domain)
    stopped = next(line for line in log.splitlines() if "stopped:" in line)
    without = int(stopped.split(" skipped, ")[1].split()[0])
    # The 1.5 s gap falls in the 4 s run: ~15 frames at 10 Hz, minus the 0.2 s within which
    # the last sample before it still counts.
    assert 8 <= without <= 20, log
    assert "40 frames in, 40 out, 0 dropped, 0 skipped" in stopped
    warned = log.index("has no odometry (rt/odom has no sample close enough)")
    assert log.index("odometry is back at frame") > warned
    # The robot stood still and the trajectory says so, gap or not.
    poses = [line.split() for line in (tmp_path / "out" / "trajectory.tum").read_text().splitlines()
             if not line.startswith("#")]
    assert len(poses) == 40
    assert max(abs(float(p[1])) + abs(float(p[2])) for p in poses) < 0.02


def test_a_best_effort_odometry_writer_is_matched(tmp_path):
    """The sensor-data QoS of ROS 2 base drivers (best effort) feeds omnislamd as well."""
    domain = 100 + (os.getpid() * 2 + 9) % 100
    publisher = OdometryPublisher(domain, gap_from=1e9, gap_to=1e9, reliable=False)
    log = run_standing_still(tmp_path, 20, publisher, domain)
    stopped = next(line for line in log.splitlines() if "stopped:" in line)
    assert "20 frames in, 20 out, 0 dropped, 0 skipped" in stopped, log
    # Matched, so odometry flows (an unmatched reader would leave all 20 frames without);
    # the first frame or two may come before the service's reader has discovered the writer.
    without = int(stopped.split(" skipped, ")[1].split()[0])
    assert without <= 2, log
