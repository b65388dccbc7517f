"""omnislamd end to end over DDS: an independent subscriber process (scripts/omnislam-subscribe,
pip cyclonedds) receives one pose per frame, equal to `omnislam replay`'s trajectory.tum, plus
map, profile and status messages. Loopback-only Cyclone config, a domain id of its own.

Run by ctest ("dds: omnislamd end to end"), which sets OMNISLAM_BIN and OMNISLAMD_BIN."""
from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DATASET = REPO / "datasets" / "sim-room-37"
SUBSCRIBER = REPO / "scripts" / "omnislam-subscribe"
pytestmark = pytest.mark.skipif(not os.environ.get("OMNISLAMD_BIN"), reason="needs OMNISLAMD_BIN (ctest sets it)")


def dds_env():
    env = dict(os.environ)
    env["CYCLONEDDS_URI"] = (REPO / "deploy" / "cyclonedds.xml").as_uri()
    return env


def domain_id(offset: int) -> int:
    return 100 + (os.getpid() * 2 + offset) % 100  # distinct from other tests and runs


def start_subscriber(domain: int) -> subprocess.Popen:
    sub = subprocess.Popen([sys.executable, str(SUBSCRIBER), "--domain", str(domain), "--until-status", "stopped",
                            "--timeout", "60"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           env=dds_env())
    assert sub.stdout.readline().strip() == "ready"
    return sub


def write_config(path: Path, domain: int, out: Path, rate_hz: float, loops: int = 1, mode: str = "replay") -> Path:
    path.write_text(f"""
input: {{source: dataset, path: {DATASET}, rate_hz: {rate_hz}, loops: {loops}}}
pipeline: {{mode: {mode}, profile_period_s: 0.2}}
dds: {{domain_id: {domain}, wait_for_subscribers: 1, wait_timeout_s: 20}}
service: {{output_dir: {out}}}
""")
    return path


def read_tum(path: Path) -> dict[float, tuple[float, float, float]]:
    poses = {}
    for line in path.read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        t, x, y, _z, _qx, _qy, qz, qw = map(float, line.split())
        poses[round(t, 6)] = (x, y, 2.0 * math.atan2(qz, qw))
    return poses


def test_subscriber_gets_every_pose_equal_to_replay(tmp_path):
    replay = tmp_path / "replay"
    subprocess.run([os.environ["OMNISLAM_BIN"], "replay", str(DATASET), "--out", str(replay)], check=True,
                   capture_output=True, timeout=120)
    expected = read_tum(replay / "trajectory.tum")

    domain = domain_id(0)
    sub = start_subscriber(domain)
    config = write_config(tmp_path / "omnislamd.yaml", domain, tmp_path / "service", rate_hz=0)
    service = subprocess.run([os.environ["OMNISLAMD_BIN"], "--config", str(config)], capture_output=True, text=True,
                             env=dds_env(), timeout=120)
    assert service.returncode == 0, service.stderr + service.stdout
    out, err = sub.communicate(timeout=60)
    assert sub.returncode == 0, err

    lines = out.splitlines()
    poses = [line.split() for line in lines if line.startswith("pose ")]
    assert len(poses) == len(expected) == 37
    for fields in poses:
        t, x, y, yaw = float(fields[1]), float(fields[2][2:]), float(fields[3][2:]), float(fields[4][4:])
        ex, ey, eyaw = expected[round(t, 6)]
        assert abs(x - ex) < 1e-6 and abs(y - ey) < 1e-6 and abs(math.remainder(yaw - eyaw, 2 * math.pi)) < 1e-6
    assert len({float(f[1]) for f in poses}) == 37  # one per frame
    maps = [line for line in lines if line.startswith("map ")]
    assert maps and int(maps[-1].split("points=")[1]) == len((replay / "map.csv").read_text().splitlines()) - 1
    profiles = [line for line in lines if line.startswith("profile ")]
    assert profiles and "frames_out=37 dropped=0" in profiles[-1]
    assert (tmp_path / "service" / "trajectory.tum").read_bytes() == (replay / "trajectory.tum").read_bytes()
    # The occupancy grid in nav2_map_server's files, written at shutdown: the replay's.
    for name in ("map.yaml", "map.pgm"):
        assert (tmp_path / "service" / name).read_bytes() == (replay / name).read_bytes()
    # ... and on rt/map (nav_msgs/OccupancyGrid): the last grid is the one in map.pgm.
    grids = [line for line in lines if line.startswith("grid ")]
    assert grids, out
    fields = dict(field.split("=") for field in grids[-1].split()[2:])
    pgm = (replay / "map.pgm").read_bytes().split(b"\n", 3)
    width, height = map(int, pgm[1].split())
    shades = pgm[3]
    assert (int(fields["width"]), int(fields["height"])) == (width, height)
    assert int(fields["occupied"]) == shades.count(0) and int(fields["free"]) == shades.count(254)
    assert int(fields["unknown"]) == shades.count(205)


def test_sigterm_drains_publishes_final_state_and_exits_0(tmp_path):
    domain = domain_id(1)
    sub = start_subscriber(domain)
    config = write_config(tmp_path / "omnislamd.yaml", domain, tmp_path / "service", rate_hz=20, loops=100,
                          mode="live")
    service = subprocess.Popen([os.environ["OMNISLAMD_BIN"], "--config", str(config)], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, env=dds_env())
    time.sleep(2.5)
    service.send_signal(signal.SIGTERM)
    log, _ = service.communicate(timeout=30)
    assert service.returncode == 0, log
    out, err = sub.communicate(timeout=30)
    assert sub.returncode == 0, err
    status = [line for line in out.splitlines() if line.startswith("status ")]
    assert status[-1].startswith("status stopped")
    frames_out = int(status[-1].split("out=")[1].split()[0])
    assert 10 <= frames_out < 37 * 100
    trajectory = (tmp_path / "service" / "trajectory.tum").read_text().splitlines()
    assert len(trajectory) - 1 == frames_out  # every captured frame drained to the files


def test_omnislam_echo_prints_pose_and_status(tmp_path):
    domain = domain_id(2)
    echo = [os.environ["OMNISLAM_BIN"], "echo", "--domain", str(domain)]
    poses = subprocess.Popen(echo + ["omnislam/pose", "--count", "3", "--timeout", "60"], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=dds_env())
    status = subprocess.Popen(echo + ["rt/omnislam/status", "--timeout", "60"], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, env=dds_env())
    config = write_config(tmp_path / "omnislamd.yaml", domain, tmp_path / "service", rate_hz=20)
    service = subprocess.run([os.environ["OMNISLAMD_BIN"], "--config", str(config)], capture_output=True, text=True,
                             env=dds_env(), timeout=120)
    assert service.returncode == 0, service.stderr + service.stdout
    out, err = poses.communicate(timeout=60)
    assert poses.returncode == 0, err
    expected = read_tum(tmp_path / "service" / "trajectory.tum")
    lines = out.splitlines()
    assert [line.split()[1] for line in lines] == ["stamp=0.000000000", "stamp=0.100000000", "stamp=0.200000000"]
    for line in lines:
        fields = dict(f.split("=", 1) for f in line.split()[1:])
        ex, ey, _ = expected[round(float(fields["stamp"]), 6)]
        assert fields["frame"] == "map"
        assert abs(float(fields["x"]) - ex) < 1e-6 and abs(float(fields["y"]) - ey) < 1e-6
    time.sleep(1.0)
    status.send_signal(signal.SIGINT)
    out, _ = status.communicate(timeout=30)
    assert 'state=stopped in=37 out=37 dropped=0 error=""' in out.splitlines()[-1]


def test_tf_map_to_odom_at_20_hz_stamped_ahead(tmp_path):
    """rt/tf (tf2_msgs/TFMessage): map -> odom after every frame and at >= 20 Hz between
    frames, stamped future_dating_s ahead; composed with the frame's odometry it is the
    frame's map pose."""
    domain = domain_id(1)
    sub = start_subscriber(domain)
    config = tmp_path / "omnislamd.yaml"
    config.write_text(f"""
input: {{source: dataset, path: {DATASET}, rate_hz: 10}}
pipeline: {{mode: replay}}
dds: {{domain_id: {domain}, wait_for_subscribers: 1, wait_timeout_s: 20, tf: {{rate_hz: 20, future_dating_s: 0.1}}}}
""")
    service = subprocess.run([os.environ["OMNISLAMD_BIN"], "--config", str(config)], capture_output=True, text=True,
                             env=dds_env(), timeout=120)
    assert service.returncode == 0, service.stderr + service.stdout
    out, err = sub.communicate(timeout=60)
    assert sub.returncode == 0, err
    lines = out.splitlines()
    poses = {round(float(f[1]), 6): (float(f[2][2:]), float(f[3][2:]), float(f[4][4:]))
             for f in (line.split() for line in lines if line.startswith("pose "))}
    tfs = [line.split() for line in lines if line.startswith("tf ")]
    assert len(poses) == 37
    stamps = [float(f[1]) for f in tfs]
    assert all(f[2] == "map->odom" for f in tfs)
    # Between the first and the last frame (3.6 s, played at the recorded 10 Hz): at least
    # 20 a second, and the stamps never run backwards.
    span = max(poses) - min(poses)
    inside = [s for s in stamps if min(poses) + 0.1 <= s <= max(poses) + 0.1]
    print(f"rt/tf: {len(inside)} messages over {span:.1f} s of data: {len(inside) / span:.1f} Hz")
    assert len(inside) >= 20 * span, (len(inside), span)
    assert all(b >= a - 1e-9 for a, b in zip(stamps, stamps[1:])), stamps
    # Every frame's own message is stamped 0.1 s ahead of it, and with the frame's odometry
    # (the dataset's odometry.tum) gives back the frame's pose.
    odometry = read_tum(DATASET / "odometry.tum")
    by_stamp = {round(float(f[1]), 6): f for f in tfs}
    for t, (x, y, yaw) in poses.items():
        f = by_stamp[round(t + 0.1, 6)]
        mx, my, myaw = float(f[3][2:]), float(f[4][2:]), float(f[5][4:])
        ox, oy, oyaw = odometry[round(t, 6)]
        cx = mx + math.cos(myaw) * ox - math.sin(myaw) * oy
        cy = my + math.sin(myaw) * ox + math.cos(myaw) * oy
        assert abs(cx - x) < 1e-6 and abs(cy - y) < 1e-6
        assert abs(math.remainder(myaw + oyaw - yaw, 2 * math.pi)) < 1e-6
    assert min(stamps) >= min(poses) + 0.1 - 1e-6
