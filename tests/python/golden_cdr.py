#!/usr/bin/env python3
"""Golden CDR bytes, serialised by rosbags (ROS 2 Humble's message layouts), of the two
messages omnislamd reads, with the field values that tests/dds/test_cdr_golden.cpp writes
through Cyclone DDS from interfaces/ros2.idl. Writes tests/dds/golden/*.hex (run it again
after changing the values; tests/python/test_ros2_interop.py checks the files are current).

    python3 tests/python/golden_cdr.py"""
import sys
from pathlib import Path

import numpy
from rosbags.typesys import Stores, get_typestore

GOLDEN = Path(__file__).resolve().parents[1] / "dds" / "golden"


def messages():
    """{file stem: (ROS 2 type, message)}: the values of test_cdr_golden.cpp."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    T = store.types
    stamp = T["builtin_interfaces/msg/Time"](sec=1700000000, nanosec=250000000)
    covariance = numpy.array([0.01 * i for i in range(36)], dtype=numpy.float64)
    pose = T["geometry_msgs/msg/PoseWithCovariance"](
        pose=T["geometry_msgs/msg/Pose"](position=T["geometry_msgs/msg/Point"](x=1.5, y=-2.25, z=0.0),
                                         orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.6, w=0.8)),
        covariance=covariance)
    odometry = T["nav_msgs/msg/Odometry"](
        header=T["std_msgs/msg/Header"](stamp=stamp, frame_id="odom"), child_frame_id="base_link", pose=pose,
        twist=T["geometry_msgs/msg/TwistWithCovariance"](
            twist=T["geometry_msgs/msg/Twist"](linear=T["geometry_msgs/msg/Vector3"](x=0.3, y=0.0, z=0.0),
                                               angular=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.1)),
            covariance=covariance))
    initial = T["geometry_msgs/msg/PoseWithCovarianceStamped"](
        header=T["std_msgs/msg/Header"](stamp=stamp, frame_id="map"), pose=pose)
    return store, {"odometry": ("nav_msgs/msg/Odometry", odometry),
                   "initialpose": ("geometry_msgs/msg/PoseWithCovarianceStamped", initial)}


def golden_hex() -> dict[str, str]:
    store, table = messages()
    return {name: bytes(store.serialize_cdr(msg, rostype)).hex() for name, (rostype, msg) in table.items()}


if __name__ == "__main__":
    GOLDEN.mkdir(parents=True, exist_ok=True)
    for name, text in golden_hex().items():
        (GOLDEN / f"{name}.hex").write_text(text + "\n")
        print(f"{GOLDEN / name}.hex: {len(text) // 2} bytes", file=sys.stderr)
