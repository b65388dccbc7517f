#pragma once

#include <filesystem>
#include <stdexcept>

#include "omnislam/degrade/degradation_config.hpp"
#include "omnislam/io/service_config.hpp"
#include "omnislam/slam/slam.hpp"
#include "omnislam/stereo/stereo_config.hpp"

/// @file
/// The YAML configuration of the omnislam commands. Every key is optional (the defaults
/// are the thesis camera and settings); an unknown key or a value of the wrong type is an
/// error naming the key and file:line. Sections and keys:
///
/// ```yaml
/// camera:   {width, height, center_px: [u, v], focal_mm, pixel_pitch_mm,
///            azimuth_offset_deg, camera_height_m, and the rig's misalignments
///            focal_scale, mirror_dz_mm, mirror_tilt_deg: [x, y], mirror_offset_mm: [x, y]}
/// vision:   {sigma_px, half_window_px, auto_thresholds, high_threshold, low_threshold,
///            auto_not_edge_fraction, auto_low_ratio, auto_min_high_threshold,
///            min_fragment_px, horizontal_ratio, max_edges_per_column, blackman_smoothing,
///            min_relative_contrast, half_window_rows, half_window_columns}
/// stereo:   {min_range_m, max_range_m, disparity_margin_px, occlusion_cost,
///            subpixel: none | edge_peak | cost_curve, triangulation: exact | table,
///            near_cutoff_m, far_cutoff_m, one_point_per_degree,
///            boundary: floor_boundary | nearest_edge,
///            floor: {max_edges_per_column, contact_margin_px, error_rate, floor_plane_range}}
/// slam:     {target: map | previous_scan, metric: point_to_line | point_to_point, overlap,
///            initial_search_radius_m, max_iterations, estimate_scale, keep_global_minimum,
///            use_srel_test, srel_limit_percent, srel_relax_percent, optional_map_correction,
///            max_rms_m, min_inlier_share, max_correction_m, max_correction_deg, odometry_gate,
///            odometry_prior,
///            min_scan_points, use_odometry, no_odometry_min_srel_percent, no_odometry_max_rotation_deg,
///            fusion_radius_m, noise_radius_m, noise_min_neighbors, prune_every, prune_min_hits,
///            prune_min_age, localization_only, map_min_step_m, lost_after_frames,
///            loop_closure: {...; keyframe_max_scans: docs/slam.md "Loop closure"},
///            odometry_scale: {enabled, prior_sigma, significance_sigmas, outlier_sigmas}}
/// degradation: {seed, center_px: [u, v],
///               exposure: {enabled, max_change}, vignetting: {enabled, rim_falloff, rim_radius_px},
///               dust: {enabled, count, min_radius_px, max_radius_px, min_opacity, max_opacity,
///                      inner_radius_px, outer_radius_px},
///               blur: {enabled, radius_px}, noise: {enabled, full_well_e, read_noise_dn},
///               jpeg: {enabled, quality}}
/// persistence: {state_dir, resume, snapshot_period_s, on_corrupt_snapshot: start_fresh | refuse,
///               start_pose: auto | saved | search}
/// input, pipeline, dds, service: omnislamd's sections (service_config.hpp)
/// ```
/// The field meanings are documented on the structs (vision_config.hpp, stereo_config.hpp, slam.hpp,
/// degrade/degradation_config.hpp).

namespace omnislam::io {

/// An invalid configuration (or dataset.yaml): unreadable file, YAML syntax, unknown key,
/// wrong type, value out of range. The message names the file:line:column and the key.
/// The commands exit with code 2 on it, which the service unit does not restart on.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// State persistence of the service (io/snapshot.hpp).
struct PersistenceConfig {
  /// Where the snapshot (state.omnisnap) lives; empty: $STATE_DIRECTORY (systemd's
  /// StateDirectory), and without it no persistence.
  std::string state_dir;
  bool resume = true;                    ///< continue from the snapshot at start (false: a new map)
  double snapshot_period_s = 30.0;       ///< how often the map and pose are saved; 0 = only at shutdown
  bool refuse_corrupt_snapshot = false;  ///< false: a corrupt snapshot is moved aside and a new map started
  /// Where the robot is when it resumes: the snapshot's pose (kSaved), or unknown and
  /// searched for on the saved map before anything is published (kSearch: a robot carried
  /// while off). kAuto: kSearch with slam.localization_only, else kSaved.
  enum class StartPose { kAuto, kSaved, kSearch };
  StartPose start_pose = StartPose::kAuto;
};

struct Config {
  stereo::ScanConfig scan;
  slam::SlamConfig slam;
  PersistenceConfig persistence;
  /// Image degradation: parameters of `omnislam degrade` and `replay --degrade`; which
  /// factors run is chosen by those commands' factor list (degradation_config.hpp).
  degrade::DegradationConfig degradation;
  ServiceConfig service;  ///< omnislamd: input, pipeline, dds, service (service_config.hpp)
};

/// Reads a configuration file on top of the defaults. Throws ConfigError naming the file
/// (and file:line:column of the offending key) on any problem.
[[nodiscard]] Config load_config(const std::filesystem::path &file);

}  // namespace omnislam::io
