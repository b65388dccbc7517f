"""omnislam's topics as ROS 2 sees them over rmw_cyclonedds: the ROS name (DDS topic "rt" +
name), the ROS 2 type name, the DDS type of omnislam_msgs.py, and the QoS omnislamd offers
(architecture.md "DDS"). Plus a rosbags type store that knows omnislam's own messages
(interfaces/omnislam.idl written as ROS 2 .msg files).

Used by scripts/omnislam-record and the tests; keep it beside a script that imports it."""
from dataclasses import dataclass

from rosbags.typesys import Stores, get_types_from_msg, get_typestore

import omnislam_msgs as m


@dataclass(frozen=True)
class TopicSpec:
    ros_name: str    # "/tf"; the DDS topic is "rt/tf"
    ros_type: str    # "tf2_msgs/msg/TFMessage"
    dds_type: type   # omnislam_msgs class (its DDS type name must match the writer's)
    reliable: bool
    transient_local: bool
    depth: int

    @property
    def dds_name(self) -> str:
        return "rt" + self.ros_name


TOPICS = {t.ros_name: t for t in (
    TopicSpec("/tf", "tf2_msgs/msg/TFMessage", m.TFMessage_, True, False, 100),
    TopicSpec("/map", "nav_msgs/msg/OccupancyGrid", m.OccupancyGrid_, True, True, 1),
    TopicSpec("/map_metadata", "nav_msgs/msg/MapMetaData", m.MapMetaData_, True, True, 1),
    TopicSpec("/omnislam/pose", "geometry_msgs/msg/PoseWithCovarianceStamped", m.PoseWithCovarianceStamped_,
              True, False, 10),
    TopicSpec("/omnislam/map", "sensor_msgs/msg/PointCloud2", m.PointCloud2_, True, True, 1),
    TopicSpec("/omnislam/scan", "sensor_msgs/msg/LaserScan", m.LaserScan_, False, False, 5),
    TopicSpec("/omnislam/profile", "omnislam/msg/StageProfile", m.StageProfile_, True, False, 10),
    TopicSpec("/omnislam/status", "omnislam/msg/Status", m.Status_, True, True, 1),
    # Inputs omnislamd reads (recorded only when asked for): QoS as their usual writers offer.
    TopicSpec("/odom", "nav_msgs/msg/Odometry", m.Odometry_, False, False, 50),
    TopicSpec("/initialpose", "geometry_msgs/msg/PoseWithCovarianceStamped", m.PoseWithCovarianceStamped_,
              True, False, 10),
)}

# What omnislamd publishes: recorded by default.
PUBLISHED = ["/tf", "/map", "/map_metadata", "/omnislam/pose", "/omnislam/map", "/omnislam/scan",
             "/omnislam/profile", "/omnislam/status"]

# interfaces/omnislam.idl as ROS 2 message definitions (a package "omnislam" with these
# msg files would have the same layout).
OMNISLAM_MSGS = {
    "omnislam/msg/StageStats": """string name
uint64 count
float64 mean_ms
float64 p50_ms
float64 p99_ms
float64 max_ms
float64 share
""",
    "omnislam/msg/QueueStats": """string name
int32 capacity
int32 depth_max
omnislam/StageStats wait
""",
    "omnislam/msg/StageProfile": """std_msgs/Header header
uint64 frames_captured
uint64 frames_dropped
uint64 frames_out
omnislam/StageStats[] stages
omnislam/QueueStats[] queues
omnislam/StageStats latency
""",
    "omnislam/msg/Status": """std_msgs/Header header
uint8 state
string state_name
uint64 frames_in
uint64 frames_out
uint64 frames_dropped
string last_error
""",
}


def typestore():
    """ROS 2 Humble's message types plus omnislam's own."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    types = {}
    for name, text in OMNISLAM_MSGS.items():
        types.update(get_types_from_msg(text, name))
    store.register(types)
    return store
