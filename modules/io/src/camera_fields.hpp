#pragma once

#include "omnislam/mirror/mirror_config.hpp"
#include "yaml_fields.hpp"

namespace omnislam::io::detail {

/// The camera keys shared by the config file and dataset.yaml: width, height,
/// center_px [u, v], focal_mm, pixel_pitch_mm, azimuth_offset_deg, and the rig's
/// misalignments focal_scale, mirror_dz_mm, mirror_tilt_deg [x, y], mirror_offset_mm [x, y].
void read_camera_fields(YamlSection &section, mirror::MirrorConfig &camera);

}  // namespace omnislam::io::detail
