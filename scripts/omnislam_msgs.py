"""omnislam's DDS message types for Python clients (pip install cyclonedds): the ROS 2
layouts of interfaces/ros2.idl and omnislam's own of interfaces/omnislam.idl. Names are
<pkg>::msg::dds_::<Type>_, final extensibility, no keys, int32 declared as int32.

Used by scripts/omnislam-subscribe and the tests; keep it beside a script that imports it.
(No `from __future__ import annotations`: cyclonedds resolves the field types at import.)"""
from dataclasses import dataclass

from cyclonedds.idl import IdlStruct
from cyclonedds.idl import annotations as annotate
from cyclonedds.idl import types


@dataclass
@annotate.final
class Time_(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: types.int32
    nanosec: types.uint32


@dataclass
@annotate.final
class Header_(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time_
    frame_id: str


@dataclass
@annotate.final
class Point_(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    x: types.float64
    y: types.float64
    z: types.float64


@dataclass
@annotate.final
class Quaternion_(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: types.float64
    y: types.float64
    z: types.float64
    w: types.float64


@dataclass
@annotate.final
class Pose_(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    position: Point_
    orientation: Quaternion_


@dataclass
@annotate.final
class PoseWithCovariance_(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovariance_"):
    pose: Pose_
    covariance: types.array[types.float64, 36]


@dataclass
@annotate.final
class PoseWithCovarianceStamped_(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovarianceStamped_"):
    header: Header_
    pose: PoseWithCovariance_


@dataclass
@annotate.final
class Vector3_(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: types.float64
    y: types.float64
    z: types.float64


@dataclass
@annotate.final
class Twist_(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    linear: Vector3_
    angular: Vector3_


@dataclass
@annotate.final
class TwistWithCovariance_(IdlStruct, typename="geometry_msgs::msg::dds_::TwistWithCovariance_"):
    twist: Twist_
    covariance: types.array[types.float64, 36]


@dataclass
@annotate.final
class Odometry_(IdlStruct, typename="nav_msgs::msg::dds_::Odometry_"):
    header: Header_
    child_frame_id: str
    pose: PoseWithCovariance_
    twist: TwistWithCovariance_


@dataclass
@annotate.final
class Transform_(IdlStruct, typename="geometry_msgs::msg::dds_::Transform_"):
    translation: Vector3_
    rotation: Quaternion_


@dataclass
@annotate.final
class TransformStamped_(IdlStruct, typename="geometry_msgs::msg::dds_::TransformStamped_"):
    header: Header_
    child_frame_id: str
    transform: Transform_


@dataclass
@annotate.final
class TFMessage_(IdlStruct, typename="tf2_msgs::msg::dds_::TFMessage_"):
    transforms: types.sequence[TransformStamped_]


@dataclass
@annotate.final
class MapMetaData_(IdlStruct, typename="nav_msgs::msg::dds_::MapMetaData_"):
    map_load_time: Time_
    resolution: types.float32
    width: types.uint32
    height: types.uint32
    origin: Pose_


@dataclass
@annotate.final
class OccupancyGrid_(IdlStruct, typename="nav_msgs::msg::dds_::OccupancyGrid_"):
    header: Header_
    info: MapMetaData_
    data: types.sequence[types.int8]


@dataclass
@annotate.final
class PointField_(IdlStruct, typename="sensor_msgs::msg::dds_::PointField_"):
    name: str
    offset: types.uint32
    datatype: types.uint8
    count: types.uint32


@dataclass
@annotate.final
class PointCloud2_(IdlStruct, typename="sensor_msgs::msg::dds_::PointCloud2_"):
    header: Header_
    height: types.uint32
    width: types.uint32
    fields: types.sequence[PointField_]
    is_bigendian: bool
    point_step: types.uint32
    row_step: types.uint32
    data: types.sequence[types.uint8]
    is_dense: bool


@dataclass
@annotate.final
class LaserScan_(IdlStruct, typename="sensor_msgs::msg::dds_::LaserScan_"):
    header: Header_
    angle_min: types.float32
    angle_max: types.float32
    angle_increment: types.float32
    time_increment: types.float32
    scan_time: types.float32
    range_min: types.float32
    range_max: types.float32
    ranges: types.sequence[types.float32]
    intensities: types.sequence[types.float32]


@dataclass
@annotate.final
class StageStats_(IdlStruct, typename="omnislam::msg::dds_::StageStats_"):
    name: str
    count: types.uint64
    mean_ms: types.float64
    p50_ms: types.float64
    p99_ms: types.float64
    max_ms: types.float64
    share: types.float64


@dataclass
@annotate.final
class QueueStats_(IdlStruct, typename="omnislam::msg::dds_::QueueStats_"):
    name: str
    capacity: types.int32
    depth_max: types.int32
    wait: StageStats_


@dataclass
@annotate.final
class StageProfile_(IdlStruct, typename="omnislam::msg::dds_::StageProfile_"):
    header: Header_
    frames_captured: types.uint64
    frames_dropped: types.uint64
    frames_out: types.uint64
    stages: types.sequence[StageStats_]
    queues: types.sequence[QueueStats_]
    latency: StageStats_


@dataclass
@annotate.final
class Status_(IdlStruct, typename="omnislam::msg::dds_::Status_"):
    header: Header_
    state: types.uint8
    state_name: str
    frames_in: types.uint64
    frames_out: types.uint64
    frames_dropped: types.uint64
    last_error: str
