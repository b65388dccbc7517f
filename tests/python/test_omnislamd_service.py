"""omnislamd as a systemd service: sd_notify under a fake NOTIFY_SOCKET (READY, periodic
WATCHDOG, STATUS, STOPPING; a hung stage stops the WATCHDOG), snapshots that survive
`kill -9` and are resumed, corrupt snapshots, localization without a map.

Run by ctest ("service: omnislamd under systemd's protocols"), which sets OMNISLAM_BIN and
OMNISLAMD_BIN. DDS is off: these tests are about the process, not the topics."""
from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import threading
import time
from pathlib import Path

import pytest
from helpers import shifted
from omnislam_render.pngio import read_png, to_gray, write_png_gray

REPO = Path(__file__).resolve().parents[2]
DATASET = REPO / "datasets" / "sim-room-37"
pytestmark = pytest.mark.skipif(not os.environ.get("OMNISLAMD_BIN"), reason="needs OMNISLAMD_BIN (ctest sets it)")


class FakeNotifySocket:
    """What systemd listens on: a datagram socket; every message is kept with its arrival time."""

    def __init__(self, path: Path):
        self.path = path
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self.sock.bind(str(path))
        self.sock.settimeout(0.1)
        self.messages: list[tuple[float, str]] = []
        self.lock = threading.Lock()
        self.running = True
        self.thread = threading.Thread(target=self._receive, daemon=True)
        self.thread.start()

    def _receive(self):
        while self.running:
            try:
                data = self.sock.recv(4096)
            except socket.timeout:
                continue
            with self.lock:
                for line in data.decode().splitlines():
                    self.messages.append((time.monotonic(), line))

    def lines(self, prefix: str) -> list[tuple[float, str]]:
        with self.lock:
            return [(t, m) for t, m in self.messages if m.startswith(prefix)]

    def close(self):
        self.running = False
        self.thread.join()
        self.sock.close()


def write_config(path: Path, extra: str = "", rate_hz: float = 10, loops: int = 1, state: Path | None = None,
                 out: Path | None = None, snapshot_period_s: float = 0.5, on_corrupt: str = "start_fresh") -> Path:
    text = f"""
input: {{source: dataset, path: {DATASET}, rate_hz: {rate_hz}, loops: {loops}}}
pipeline: {{mode: replay}}
dds: {{enabled: false}}
"""
    if state is not None:
        text += (f"persistence: {{state_dir: {state}, snapshot_period_s: {snapshot_period_s}, "
                 f"on_corrupt_snapshot: {on_corrupt}}}\n")
    if out is not None:
        text += f"service: {{output_dir: {out}}}\n"
    path.write_text(text + extra)
    return path


def start(config: Path, env_extra: dict[str, str] | None = None) -> subprocess.Popen:
    env = dict(os.environ)
    env.pop("NOTIFY_SOCKET", None)
    env.update(env_extra or {})
    return subprocess.Popen([os.environ["OMNISLAMD_BIN"], "--config", str(config)], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, env=env)


def saved_state(tmp_path: Path, dataset: Path) -> tuple[Path, Path]:
    """A state directory holding the snapshot of a replay of `dataset` (`map save`), and the
    replay's output directory."""
    state = tmp_path / "state"
    state.mkdir()
    mapping = tmp_path / "mapping"
    subprocess.run([os.environ["OMNISLAM_BIN"], "replay", str(dataset), "--out", str(mapping)], check=True,
                   capture_output=True)
    subprocess.run([os.environ["OMNISLAM_BIN"], "map", "save", str(mapping), str(state / "state.omnisnap")],
                   check=True, capture_output=True)
    return state, mapping


def map_info(snapshot: Path) -> str:
    return subprocess.run([os.environ["OMNISLAM_BIN"], "map", "info", str(snapshot)], check=True,
                          capture_output=True, text=True).stdout


def info_value(info: str, key: str) -> str:
    return next(line for line in info.splitlines() if line.startswith(key + ":")).split(":", 1)[1].strip()


def evaluate(run: Path) -> dict:
    subprocess.run([os.environ["OMNISLAM_BIN"], "evaluate", str(run), str(DATASET)], check=True,
                   capture_output=True)
    return json.loads((run / "evaluation.json").read_text())


def test_notify_ready_watchdog_status_stopping(tmp_path):
    notify = FakeNotifySocket(tmp_path / "notify")
    try:
        service = start(write_config(tmp_path / "c.yaml", loops=100),
                        {"NOTIFY_SOCKET": str(notify.path), "WATCHDOG_USEC": "1000000"})
        time.sleep(3.0)
        service.send_signal(signal.SIGTERM)
        log, _ = service.communicate(timeout=30)
        assert service.returncode == 0, log
    finally:
        notify.close()
    ready = notify.lines("READY=1")
    pets = notify.lines("WATCHDOG=1")
    stopping = notify.lines("STOPPING=1")
    assert len(ready) == 1 and len(stopping) == 1, notify.messages
    # Every 0.5 s (half of WatchdogSec), never a whole WatchdogSec apart, from READY to STOPPING.
    between = [t for t, _ in pets if ready[0][0] <= t <= stopping[0][0]]
    assert len(between) >= 5, notify.messages
    assert between[0] - ready[0][0] < 0.5
    assert max(b - a for a, b in zip(between, between[1:])) < 0.9
    statuses = [m for _, m in notify.lines("STATUS=running: frames in")]
    assert statuses and "dropped 0, skipped 0, without odometry 0" in statuses[-1]


def test_a_hung_stage_stops_the_watchdog(tmp_path):
    notify = FakeNotifySocket(tmp_path / "notify")
    try:
        config = write_config(tmp_path / "c.yaml", extra="service: {stage_timeout_s: 0.5}\n", loops=100)
        service = start(config, {"NOTIFY_SOCKET": str(notify.path), "WATCHDOG_USEC": "1000000",
                                 "OMNISLAM_TEST_STALL": "slam:12"})
        # Frame 12 reaches SLAM ~1.1 s after READY and is declared hung 0.5 s later.
        deadline = time.monotonic() + 30
        while not notify.lines("STATUS=hung") and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(2.5)  # five watchdog periods without a ping
        service.send_signal(signal.SIGTERM)  # the stalled stage lets go on stop
        log, _ = service.communicate(timeout=30)
        assert service.returncode == 0, log
    finally:
        notify.close()
    assert "the slam stage has been busy with one frame for more than 0.5 s" in log
    ready = notify.lines("READY=1")[0][0]
    hung = notify.lines("STATUS=hung in the slam stage")
    assert len(hung) == 1, notify.messages
    pets = [t for t, _ in notify.lines("WATCHDOG=1")]
    assert len([t for t in pets if ready <= t < hung[0][0]]) >= 2  # petted while it ran
    stopping = notify.lines("STOPPING=1")[0][0]
    assert stopping - hung[0][0] > 2.0
    assert not [t for t in pets if hung[0][0] <= t < stopping], "WATCHDOG=1 sent while a stage hung"


def test_kill_9_then_restart_continues_map_and_pose(tmp_path):
    state = tmp_path / "state"
    snapshot = state / "state.omnisnap"
    # The uninterrupted run: its error is the bound.
    whole = start(write_config(tmp_path / "whole.yaml", rate_hz=0, out=tmp_path / "whole"))
    log, _ = whole.communicate(timeout=120)
    assert whole.returncode == 0, log
    bound = evaluate(tmp_path / "whole")["ate"]

    # READY marks the start of capture; at 10 Hz frame k is captured 0.1 (k - 1) s later.
    notify = FakeNotifySocket(tmp_path / "notify")
    try:
        first = start(write_config(tmp_path / "first.yaml", state=state), {"NOTIFY_SOCKET": str(notify.path)})
        deadline = time.monotonic() + 30
        while not notify.lines("READY=1") and time.monotonic() < deadline:
            time.sleep(0.01)
        time.sleep(2.0)
        first.kill()  # SIGKILL: no shutdown, no final snapshot
        killed = time.monotonic()
        first.communicate(timeout=10)
    finally:
        notify.close()
    captured = int((killed - notify.lines("READY=1")[0][0]) * 10) + 1
    info = map_info(snapshot)
    frames_saved = int(info_value(info, "frames").split(",")[0])
    points_saved = int(info_value(info, "map points").split()[0])
    t_saved = float(info_value(info, "pose").split(" t ")[1].split()[0])
    # Lost: at most the snapshot interval (5 frames) plus the frames still in the pipeline.
    assert captured - 5 - 3 <= frames_saved <= captured, info
    assert points_saved > 200
    assert info_value(info, "odometry") != "none"
    # The snapshot carries the keyframe graph the map was built from (version 4).
    keyframes_saved = int(info_value(info, "keyframe graph").split()[0])
    assert keyframes_saved > 0, info

    second = start(write_config(tmp_path / "second.yaml", state=state, out=tmp_path / "second", rate_hz=0))
    log, _ = second.communicate(timeout=120)
    assert second.returncode == 0, log
    assert f"resumed from {snapshot}: {points_saved} map points, {frames_saved} frames, {keyframes_saved} keyframes" in log
    trajectory = [line.split() for line in (tmp_path / "second" / "trajectory.tum").read_text().splitlines()
                  if not line.startswith("#")]
    assert abs(float(trajectory[0][0]) - (t_saved + 0.1)) < 1e-6  # continues with the next frame
    assert len(trajectory) == 37 - frames_saved
    resumed = evaluate(tmp_path / "second")["ate"]
    assert resumed["max_m"] <= max(bound["max_m"], 0.083)
    assert resumed["final_m"] <= max(bound["final_m"], 0.083)
    final = map_info(snapshot)
    assert int(info_value(final, "frames").split(",")[0]) == 37
    # The resumed run continued the saved graph: its keyframes are still the first ones.
    assert int(info_value(final, "keyframe graph").split()[0]) > keyframes_saved, final


def test_corrupt_snapshot_is_kept_aside_or_refused(tmp_path):
    state = tmp_path / "state"
    state.mkdir()
    (state / "state.omnisnap").write_bytes(b"OMNISNAP" + bytes(40))
    refused = start(write_config(tmp_path / "refuse.yaml", state=state, rate_hz=0, on_corrupt="refuse"))
    log, _ = refused.communicate(timeout=60)
    assert refused.returncode == 3, log
    assert f"{state}/state.omnisnap: trailing bytes" in log and "refusing to start" in log
    assert (state / "state.omnisnap").exists()

    fresh = start(write_config(tmp_path / "fresh.yaml", state=state, rate_hz=0))
    log, _ = fresh.communicate(timeout=60)
    assert fresh.returncode == 0, log
    assert f"kept as {state}/state.omnisnap.corrupt-1, starting a new map" in log
    assert (state / "state.omnisnap.corrupt-1").read_bytes() == b"OMNISNAP" + bytes(40)
    assert int(info_value(map_info(state / "state.omnisnap"), "frames").split(",")[0]) == 37


def test_localization_only_needs_a_map(tmp_path):
    config = write_config(tmp_path / "c.yaml", state=tmp_path / "state", rate_hz=0,
                          extra="slam: {localization_only: true}\n")
    service = start(config)
    log, _ = service.communicate(timeout=60)
    assert service.returncode == 3, log
    assert "slam.localization_only needs a saved map, and there is none at" in log


def test_video_input_through_videocapture(tmp_path):
    """source: video reads through cv::VideoCapture (here an image-sequence pattern, which
    OpenCV opens like a video file: colour frames, converted to grey); without odometry the
    service runs the thesis's SLAM without odometry and still follows the true path."""
    config = tmp_path / "c.yaml"
    config.write_text(f"""
input: {{source: video, path: {DATASET}/images/%06d.png, odometry: none, rate_hz: 0}}
pipeline: {{mode: replay}}
dds: {{enabled: false}}
service: {{output_dir: {tmp_path / 'out'}}}
""")
    service = start(config)
    log, _ = service.communicate(timeout=120)
    assert service.returncode == 0, log
    assert "SLAM without odometry" in log and "37 frames in, 37 out, 0 dropped, 0 skipped" in log
    truth = [line.split() for line in (DATASET / "groundtruth.tum").read_text().splitlines()
             if not line.startswith("#")]
    estimate = [line.split() for line in (tmp_path / "out" / "trajectory.tum").read_text().splitlines()
                if not line.startswith("#")]
    assert len(estimate) == 37
    # Frame 1 is the map frame and the ground truth's first pose is the identity.
    assert [float(v) for v in truth[0][1:3]] == [0.0, 0.0]
    errors = [((float(e[1]) - float(t[1])) ** 2 + (float(e[2]) - float(t[2])) ** 2) ** 0.5
              for e, t in zip(estimate, truth)]
    assert max(errors) < 0.25, errors


@pytest.mark.parametrize("shift", [(0.0, 0.0), (1.2, -0.8)])
def test_rig_check_at_start_warns_when_the_rim_is_off_centre(tmp_path, shift):
    """The first live image's mirror rim against camera.center_px: within 0.5 px an info line,
    beyond it a warning in the journal (and the status); the service runs on either way."""
    images = tmp_path / "images"
    images.mkdir()
    for frame in range(1, 4):
        image = to_gray(read_png(DATASET / "images" / f"{frame:06d}.png"))
        write_png_gray(images / f"{frame:06d}.png", shifted(image, *shift))
    config = tmp_path / "c.yaml"
    config.write_text(f"""
input: {{source: video, path: {images}/%06d.png, odometry: none, rate_hz: 0}}
pipeline: {{mode: replay}}
dds: {{enabled: false}}
""")
    service = start(config)
    log, _ = service.communicate(timeout=120)
    assert service.returncode == 0, log
    assert "3 frames in, 3 out, 0 dropped, 0 skipped" in log
    check = [line for line in log.splitlines() if "rig check:" in line]
    assert len(check) == 1, log
    off = (shift[0] ** 2 + shift[1] ** 2) ** 0.5
    assert f"{off:.2f} px from the configured (511.50, 511.50)" in check[0]
    assert ("[warning]" in check[0]) == (off > 0.5), check[0]
    assert ("omnislam calibrate rim" in check[0]) == (off > 0.5)


def test_localization_only_finds_its_pose_on_the_saved_map(tmp_path):
    """With slam.localization_only the saved pose is not trusted (persistence.start_pose auto):
    the service searches the saved map, publishes nothing until one pose is confirmed, then
    tracks in the saved map's frame without changing the map."""
    state, mapping = saved_state(tmp_path, DATASET)
    out = tmp_path / "out"
    service = start(write_config(tmp_path / "c.yaml", state=state, out=out, rate_hz=0,
                                 extra="slam: {localization_only: true}\n"))
    log, _ = service.communicate(timeout=120)
    assert service.returncode == 0, log
    assert "searching for the pose on the saved map" in log
    assert "localized on the saved map at frame 3 after 2 frames" in log
    poses = [line for line in (out / "trajectory.tum").read_text().splitlines() if not line.startswith("#")]
    assert len(poses) == 35
    evaluated = evaluate(out)
    assert evaluated["ate"]["max_m"] <= 0.02
    # The published covariance adds how far the saved map may be off where the robot is (the
    # snapshot's keyframe covariances): measured mean NEES 2.5, 97% inside the 95% ellipse
    # (245.9 and 20% from a snapshot without them, the registration's covariance alone).
    assert 1.0 <= evaluated["covariance"]["mean_nees"] <= 10.0
    assert evaluated["covariance"]["inside_95_share"] >= 0.8
    assert (out / "map.csv").read_text() == (mapping / "map.csv").read_text()


def test_start_pose_search_maps_on_from_the_found_pose_with_the_maps_uncertainty(tmp_path):
    """persistence.start_pose search without localization_only: the pose is searched for on the
    saved map, then SLAM goes on from it; the walk of the published covariance starts from the
    search's plus how far the saved map may be off there (its keyframes' covariances).
    Measured mean NEES 3.1, 100% inside the 95% ellipse (7.2 and 94.3% when the walk started
    from the search's covariance alone)."""
    state, _ = saved_state(tmp_path, DATASET)
    out = tmp_path / "out"
    config = write_config(tmp_path / "c.yaml", out=out, rate_hz=0)
    config.write_text(config.read_text() +
                      f"persistence: {{state_dir: {state}, snapshot_period_s: 100, start_pose: search}}\n")
    service = start(config)
    log, _ = service.communicate(timeout=120)
    assert service.returncode == 0, log
    assert "localized on the saved map at frame 3 after 2 frames" in log
    evaluated = evaluate(out)
    assert evaluated["online_ate"]["max_m"] <= 0.02
    assert 1.0 <= evaluated["covariance"]["mean_nees"] <= 10.0
    assert evaluated["covariance"]["inside_95_share"] >= 0.95


def test_start_pose_search_on_another_rooms_map_publishes_nothing(tmp_path):
    state, _ = saved_state(tmp_path, REPO / "datasets" / "office-real")
    before = (state / "state.omnisnap").read_bytes()
    out = tmp_path / "out"
    config = tmp_path / "search.yaml"
    config.write_text(f"""
input: {{source: dataset, path: {DATASET}, rate_hz: 0}}
pipeline: {{mode: replay}}
dds: {{enabled: false}}
persistence: {{state_dir: {state}, snapshot_period_s: 0.5, start_pose: search}}
service: {{output_dir: {out}}}
""")
    service = start(config)
    log, _ = service.communicate(timeout=120)
    assert service.returncode == 0, log
    assert "37 frames and no pose found on the saved map (it is kept unchanged)" in log
    assert (state / "state.omnisnap").read_bytes() == before
