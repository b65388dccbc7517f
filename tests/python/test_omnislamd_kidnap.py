"""omnislamd with a kidnapped robot (slam.lost_after_frames): l-room-2laps copied by
scripts/kidnap-dataset so that after frame 20 the robot is carried to where frame 40 was
taken, a part of the room the first 20 frames never saw. The service must say so (journal
and rt/omnislam/status: state localizing, "tracking lost at frame 23" in last_error), publish
no pose while in doubt or lost, and when the second lap brings the robot back into the mapped wing say it
was found again (state running) and publish from then on.
Loopback-only Cyclone config, a domain id of its own. Run by ctest ("dds: omnislamd kidnapped")."""

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.skipif(not os.environ.get("OMNISLAMD_BIN"), reason="needs OMNISLAMD_BIN (ctest sets it)")

os.environ.setdefault("CYCLONEDDS_URI", (REPO / "deploy" / "cyclonedds.xml").as_uri())
from cyclonedds.core import Policy, Qos  # noqa: E402  (after CYCLONEDDS_URI)
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402
from cyclonedds.util import duration  # noqa: E402

sys.path.insert(0, str(REPO / "scripts"))
from omnislam_msgs import PoseWithCovarianceStamped_, Status_  # noqa: E402
from helpers import dds_domain, omnislamd  # noqa: E402

RELIABLE = Policy.Reliability.Reliable(duration(seconds=1))


def test_kidnapped_robot_is_reported_lost_publishes_nothing_and_is_found_again(tmp_path):
    dataset = tmp_path / "kidnapped"
    made = subprocess.run([sys.executable, str(REPO / "scripts" / "kidnap-dataset"),
                           str(REPO / "datasets" / "l-room-2laps"), str(dataset), "--at", "20", "--to", "40"],
                          capture_output=True, text=True)
    assert made.returncode == 0, made.stderr
    frames = 20 + (119 - 40 + 1)

    domain = dds_domain(19)
    participant = DomainParticipant(domain)
    status_reader = DataReader(participant, Topic(participant, "rt/omnislam/status", Status_),
                               qos=Qos(RELIABLE, Policy.Durability.TransientLocal, Policy.History.KeepLast(100)))
    pose_reader = DataReader(participant, Topic(participant, "rt/omnislam/pose", PoseWithCovarianceStamped_),
                             qos=Qos(RELIABLE, Policy.History.KeepLast(200)))
    poses, statuses = [], []

    def take():
        poses.extend(s for s in pose_reader.take(N=200) if isinstance(s, PoseWithCovarianceStamped_))
        statuses.extend(s for s in status_reader.take(N=100) if isinstance(s, Status_))

    with omnislamd(tmp_path, f"""
input: {{source: dataset, path: {dataset}, rate_hz: 0}}
pipeline: {{mode: replay}}
dds: {{domain_id: {domain}, wait_for_subscribers: 1, wait_timeout_s: 30}}
""") as service:
        deadline = time.monotonic() + 120
        while service.poll() is None and time.monotonic() < deadline:
            take()
            time.sleep(0.02)
        assert service.wait(timeout=60) == 0
    time.sleep(0.5)
    take()
    log = (tmp_path / "omnislamd.log").read_text()

    assert "tracking lost at frame 23" in log, log
    assert "found again at frame 42 (lost since frame 23)" in log, log
    lost = [s for s in statuses if s.state == 5]
    assert lost and "tracking lost at frame 23" in lost[0].last_error
    assert any(s.state == 1 and s.frames_in == 42 for s in statuses)  # running again when found
    # Frames 21-22 (in doubt: their poses are the odometry's guess, which the scans speak
    # against) and 23-41 (lost) have no pose on the topic; every other frame has one.
    assert "frame 21 does not fit the map where odometry puts it: pose withheld" in log, log
    assert "2 frames in doubt before a fit or a loss" in log, log
    assert len(poses) == frames - 21, log
