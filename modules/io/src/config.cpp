#include "omnislam/io/config.hpp"

#include <cmath>
#include <initializer_list>
#include <numbers>
#include <string>
#include <utility>

#include "camera_fields.hpp"
#include "yaml_fields.hpp"

namespace omnislam::io {
namespace detail {

// omnislamd's sections (service_config.cpp).
void read_service_sections(YamlSection &top, ServiceConfig &service);
// The image degradation (degradation_section.cpp).
void read_degradation(YamlSection &section, degrade::DegradationConfig &config);

namespace {

// A pair `key: [x, y]` of finite numbers, scaled (e.g. degrees to radians).
void read_pair(YamlSection &section, const char *key, const char *expected, double scale, double &x,
               double &y) {
  if (!section.has(key)) return;
  const YAML::Node pair = section.node(key);
  if (!pair.IsSequence() || pair.size() != 2) section.fail(key, expected);
  try {
    x = pair[0].as<double>() * scale;
    y = pair[1].as<double>() * scale;
  } catch (const YAML::Exception &) {
    section.fail(key, expected);
  }
  if (!std::isfinite(x) || !std::isfinite(y)) section.fail(key, expected);
}

// The rig's misalignments (issue 12); the bounds keep the general model's iterations,
// which start from the designed rig, in their basin and reject unit mistakes (mm for m).
void read_rig_fields(YamlSection &section, mirror::RigConfig &rig) {
  constexpr double kMaxShiftMm = 10.0;
  constexpr double kMaxTiltDeg = 5.0;
  constexpr double kRad = std::numbers::pi / 180.0;
  section.read("focal_scale", rig.focal_scale);
  section.read("mirror_dz_mm", rig.mirror_dz_mm);
  read_pair(section, "mirror_tilt_deg", "must be [x, y] in degrees", kRad, rig.mirror_tilt_x_rad,
            rig.mirror_tilt_y_rad);
  read_pair(section, "mirror_offset_mm", "must be [x, y] in millimetres", 1.0, rig.mirror_offset_x_mm,
            rig.mirror_offset_y_mm);
  read_pair(section, "level_tilt_deg", "must be [x, y] in degrees", kRad, rig.level_tilt_x_rad,
            rig.level_tilt_y_rad);
  if (!(rig.focal_scale >= 0.9 && rig.focal_scale <= 1.1))
    section.fail("focal_scale", "must be in [0.9, 1.1]");
  if (!(std::abs(rig.mirror_dz_mm) <= kMaxShiftMm)) section.fail("mirror_dz_mm", "must be within +-10 mm");
  if (!(std::abs(rig.mirror_tilt_x_rad) <= kMaxTiltDeg * kRad &&
        std::abs(rig.mirror_tilt_y_rad) <= kMaxTiltDeg * kRad))
    section.fail("mirror_tilt_deg", "each angle must be within +-5 degrees");
  if (!(std::abs(rig.mirror_offset_x_mm) <= kMaxShiftMm && std::abs(rig.mirror_offset_y_mm) <= kMaxShiftMm))
    section.fail("mirror_offset_mm", "each offset must be within +-10 mm");
  if (!(std::abs(rig.level_tilt_x_rad) <= kMaxTiltDeg * kRad &&
        std::abs(rig.level_tilt_y_rad) <= kMaxTiltDeg * kRad))
    section.fail("level_tilt_deg", "each angle must be within +-5 degrees");
}

}  // namespace

void read_camera_fields(YamlSection &section, mirror::MirrorConfig &camera) {
  section.read("width", camera.image_width_px);
  section.read("height", camera.image_height_px);
  read_pixel_pair(section, "center_px", camera.center_u_px, camera.center_v_px);
  section.read("focal_mm", camera.focal_mm);
  section.read("pixel_pitch_mm", camera.pixel_pitch_mm);
  section.read("azimuth_offset_deg", camera.azimuth_offset_deg);
  if (camera.image_width_px <= 0) section.fail("width", "must be positive");
  if (camera.image_height_px <= 0) section.fail("height", "must be positive");
  if (!(camera.focal_mm > 0.0)) section.fail("focal_mm", "must be positive");
  if (!(camera.pixel_pitch_mm > 0.0)) section.fail("pixel_pitch_mm", "must be positive");
  read_rig_fields(section, camera.rig);
}

}  // namespace detail
namespace {

using detail::YamlSection;

template <typename Enum>
void read_choice(YamlSection &section, const char *key, Enum &value,
                 std::initializer_list<std::pair<const char *, Enum>> choices, const char *message) {
  std::string text;
  section.read(key, text);
  if (text.empty()) return;
  for (const auto &[name, choice] : choices) {
    if (text == name) {
      value = choice;
      return;
    }
  }
  section.fail(key, message);
}

// An angle given in degrees in the file and kept in radians in the config.
void read_degrees(YamlSection &section, const char *key, double &value_rad) {
  double degrees = value_rad * 180.0 / std::numbers::pi;
  section.read(key, degrees);
  value_rad = degrees * std::numbers::pi / 180.0;
}

void read_vision(YamlSection &section, vision::VisionConfig &vision) {
  vision::CannyConfig &canny = vision.canny;
  section.read("sigma_px", canny.sigma_px);
  section.read("half_window_px", canny.half_window_px);
  section.read("auto_thresholds", canny.auto_thresholds);
  section.read("high_threshold", canny.high_threshold);
  section.read("low_threshold", canny.low_threshold);
  section.read("auto_not_edge_fraction", canny.auto_not_edge_fraction);
  section.read("auto_low_ratio", canny.auto_low_ratio);
  section.read("auto_min_high_threshold", canny.auto_min_high_threshold);
  section.read("noise_edges_per_panorama", canny.noise_edges_per_panorama);
  section.read("min_fragment_px", canny.min_fragment_px);
  vision::EdgeSelectionConfig &selection = vision.selection;
  section.read("horizontal_ratio", selection.horizontal_ratio);
  section.read("max_edges_per_column", selection.max_edges_per_column);
  section.read("blackman_smoothing", selection.blackman_smoothing);
  section.read("min_relative_contrast", selection.min_relative_contrast);
  section.read("half_window_rows", selection.half_window_rows);
  section.read("half_window_columns", selection.half_window_columns);
  if (canny.sigma_px < 0.0) section.fail("sigma_px", "must be >= 0");
  if (selection.max_edges_per_column < 1 || selection.max_edges_per_column > 16) {
    section.fail("max_edges_per_column", "must be in 1..16");
  }
  if (selection.half_window_rows < 0 || selection.half_window_rows > 20) {
    section.fail("half_window_rows", "must be in 0..20");
  }
  if (selection.half_window_columns < 0 || selection.half_window_columns > 20) {
    section.fail("half_window_columns", "must be in 0..20");
  }
}

void read_stereo(YamlSection &section, stereo::StereoConfig &stereo) {
  section.read("min_range_m", stereo.min_range_m);
  section.read("max_range_m", stereo.max_range_m);
  section.read("disparity_margin_px", stereo.disparity_margin_px);
  section.read("occlusion_cost", stereo.occlusion_cost);
  section.read("near_cutoff_m", stereo.near_cutoff_m);
  section.read("far_cutoff_m", stereo.far_cutoff_m);
  section.read("one_point_per_degree", stereo.one_point_per_degree);
  read_choice(section, "subpixel", stereo.subpixel,
              {{"none", stereo::SubpixelMethod::kNone},
               {"edge_peak", stereo::SubpixelMethod::kEdgePeak},
               {"cost_curve", stereo::SubpixelMethod::kCostCurve}},
              "must be none, edge_peak or cost_curve");
  read_choice(
      section, "triangulation", stereo.triangulation,
      {{"exact", stereo::TriangulationMethod::kExact}, {"table", stereo::TriangulationMethod::kTable}},
      "must be exact or table");
  read_choice(section, "boundary", stereo.boundary,
              {{"floor_boundary", stereo::BoundaryMethod::kFloorBoundary},
               {"nearest_edge", stereo::BoundaryMethod::kNearestEdge}},
              "must be floor_boundary or nearest_edge");
  read_section(section, "floor", [&stereo](YamlSection &floor) {
    stereo::FloorBoundaryConfig &config = stereo.floor;
    floor.read("max_edges_per_column", config.max_edges_per_column);
    floor.read("contact_margin_px", config.contact_margin_px);
    floor.read("error_rate", config.error_rate);
    floor.read("floor_plane_range", config.floor_plane_range);
    floor.read("contact_ray_sigma_px", config.contact_ray_sigma_px);
    if (config.max_edges_per_column < 1 || config.max_edges_per_column > 64)
      floor.fail("max_edges_per_column", "must be 1..64");
    if (!(config.contact_margin_px > 0.0 && config.contact_margin_px <= 10.0))
      floor.fail("contact_margin_px", "must be in (0, 10]");
    if (!(config.error_rate > 0.0 && config.error_rate < 0.5))
      floor.fail("error_rate", "must be in (0, 0.5)");
    if (!(config.contact_ray_sigma_px >= 0.0 && config.contact_ray_sigma_px <= 5.0))
      floor.fail("contact_ray_sigma_px", "must be in [0, 5]");
  });

  if (!(stereo.max_range_m > stereo.min_range_m)) section.fail("max_range_m", "must exceed min_range_m");
  if (!(stereo.far_cutoff_m > stereo.near_cutoff_m))
    section.fail("far_cutoff_m", "must exceed near_cutoff_m");
}

// slam.loop_closure: keyframes, the pose graph and loop acceptance (docs/slam.md "Loop closure").
void read_loop_closure(YamlSection &section, slam::LoopClosureConfig &loops) {
  section.read("enabled", loops.enabled);
  slam::KeyframeConfig &keyframes = loops.keyframes;
  section.read("keyframe_distance_m", keyframes.keyframe_distance_m);
  read_degrees(section, "keyframe_angle_deg", keyframes.keyframe_angle_rad);
  section.read("edge_floor_xy_m", keyframes.edge_floor_xy_m);
  read_degrees(section, "edge_floor_yaw_deg", keyframes.edge_floor_yaw_rad);
  section.read("drift_per_m", keyframes.drift_per_m);
  read_degrees(section, "drift_yaw_deg_per_m", keyframes.drift_yaw_per_m);
  section.read("keyframe_max_scans", keyframes.max_scans);
  section.read("min_path_gap_m", loops.min_path_gap_m);
  section.read("submap_path_m", loops.submap_path_m);
  section.read("max_candidate_distance_m", loops.max_candidate_distance_m);
  section.read("max_candidates", loops.max_candidates);
  section.read("max_window_m", loops.max_window_m);
  read_degrees(section, "max_window_deg", loops.max_window_rad);
  section.read("grid_resolution_m", loops.grid_resolution_m);
  section.read("max_sample_points", loops.max_sample_points);
  section.read("min_score", loops.min_score);
  section.read("ambiguity_ratio", loops.ambiguity_ratio);
  section.read("distinct_m", loops.distinct_m);
  read_degrees(section, "distinct_deg", loops.distinct_rad);
  section.read("max_rms_m", loops.max_rms_m);
  section.read("min_overlap", loops.min_overlap);
  section.read("min_weak_direction_share", loops.min_weak_direction_share);
  section.read("agreement_m", loops.agreement_m);
  read_degrees(section, "agreement_deg", loops.agreement_rad);
  section.read("loop_floor_xy_m", loops.loop_floor_xy_m);
  read_degrees(section, "loop_floor_yaw_deg", loops.loop_floor_yaw_rad);
  section.read("loop_chi2_limit", loops.graph.loop_chi2_limit);
  section.read("loop_loss_scale", loops.graph.loop_loss_scale);
  section.read("rebuild_min_shift_m", loops.rebuild_min_shift_m);
  section.read("reuse_keyframes", loops.reuse_keyframes);
  for (const auto &[key, value] : {std::pair{"keyframe_distance_m", keyframes.keyframe_distance_m},
                                   {"keyframe_angle_deg", keyframes.keyframe_angle_rad},
                                   {"edge_floor_xy_m", keyframes.edge_floor_xy_m},
                                   {"edge_floor_yaw_deg", keyframes.edge_floor_yaw_rad},
                                   {"submap_path_m", loops.submap_path_m},
                                   {"max_window_m", loops.max_window_m},
                                   {"grid_resolution_m", loops.grid_resolution_m},
                                   {"distinct_m", loops.distinct_m},
                                   {"max_rms_m", loops.max_rms_m},
                                   {"agreement_m", loops.agreement_m},
                                   {"loop_floor_xy_m", loops.loop_floor_xy_m},
                                   {"loop_floor_yaw_deg", loops.loop_floor_yaw_rad},
                                   {"loop_chi2_limit", loops.graph.loop_chi2_limit},
                                   {"loop_loss_scale", loops.graph.loop_loss_scale}}) {
    if (!(value > 0.0)) section.fail(key, "must be positive");
  }
  for (const auto &[key, value] : {std::pair{"drift_per_m", keyframes.drift_per_m},
                                   {"drift_yaw_deg_per_m", keyframes.drift_yaw_per_m},
                                   {"min_path_gap_m", loops.min_path_gap_m},
                                   {"max_candidate_distance_m", loops.max_candidate_distance_m},
                                   {"max_window_deg", loops.max_window_rad},
                                   {"distinct_deg", loops.distinct_rad},
                                   {"agreement_deg", loops.agreement_rad},
                                   {"rebuild_min_shift_m", loops.rebuild_min_shift_m}}) {
    if (value < 0.0) section.fail(key, "must be >= 0");
  }
  for (const auto &[key, value] : {std::pair{"min_score", loops.min_score},
                                   {"ambiguity_ratio", loops.ambiguity_ratio},
                                   {"min_overlap", loops.min_overlap},
                                   {"min_weak_direction_share", loops.min_weak_direction_share}}) {
    if (!(value >= 0.0 && value <= 1.0)) section.fail(key, "must be in [0, 1]");
  }
  if (keyframes.max_scans < 1) section.fail("keyframe_max_scans", "must be at least 1");
  if (loops.max_candidates < 1 || loops.max_candidates > 50)
    section.fail("max_candidates", "must be in 1..50");
  if (loops.max_sample_points < 10 || loops.max_sample_points > 10000)
    section.fail("max_sample_points", "must be in 10..10000");
}

void read_slam(YamlSection &section, slam::SlamConfig &slam) {
  read_choice(
      section, "target", slam.target,
      {{"map", slam::RegistrationTarget::kMap}, {"previous_scan", slam::RegistrationTarget::kPreviousScan}},
      "must be map or previous_scan");
  read_choice(
      section, "metric", slam.icp.metric,
      {{"point_to_line", slam::IcpMetric::kPointToLine}, {"point_to_point", slam::IcpMetric::kPointToPoint}},
      "must be point_to_line or point_to_point");
  section.read("overlap", slam.icp.overlap);
  section.read("initial_search_radius_m", slam.icp.initial_search_radius_m);
  section.read("max_iterations", slam.icp.max_iterations);
  section.read("estimate_scale", slam.icp.estimate_scale);
  section.read("keep_global_minimum", slam.icp.keep_global_minimum);
  section.read("covariance_sectors", slam.icp.covariance_sectors);
  section.read("range_weighting_passes", slam.icp.range_weighting_passes);
  section.read("residual_tail_dof", slam.icp.residual_tail_dof);
  section.read("min_constraining_pairs", slam.icp.min_constraining_pairs);
  section.read("use_srel_test", slam.use_srel_test);
  section.read("srel_limit_percent", slam.srel_limit_percent);
  section.read("srel_relax_percent", slam.srel_relax_percent);
  section.read("optional_map_correction", slam.optional_map_correction);
  section.read("max_rms_m", slam.max_rms_m);
  section.read("min_inlier_share", slam.min_inlier_share);
  section.read("max_correction_m", slam.max_correction_m);
  read_degrees(section, "max_correction_deg", slam.max_correction_rad);
  section.read("odometry_gate", slam.odometry_gate);
  section.read("odometry_prior", slam.odometry_prior);
  section.read("min_scan_points", slam.min_scan_points);
  section.read("use_odometry", slam.use_odometry);
  section.read("no_odometry_min_srel_percent", slam.no_odometry_min_srel_percent);
  read_degrees(section, "no_odometry_max_rotation_deg", slam.no_odometry_max_rotation_rad);
  section.read("fusion_radius_m", slam.map.fusion_radius_m);
  section.read("noise_radius_m", slam.map.noise_radius_m);
  section.read("noise_min_neighbors", slam.map.noise_min_neighbors);
  section.read("prune_every", slam.map.prune_every);
  section.read("prune_min_hits", slam.map.prune_min_hits);
  section.read("prune_min_age", slam.map.prune_min_age);
  section.read("localization_only", slam.localization_only);
  section.read("map_min_step_m", slam.map_min_step_m);
  section.read("lost_after_frames", slam.lost_after_frames);
  detail::read_section(section, "loop_closure",
                       [&slam](YamlSection &loops) { read_loop_closure(loops, slam.loop_closure); });
  detail::read_section(section, "odometry_scale", [&slam](YamlSection &scale) {
    slam::OdometryScaleConfig &config = slam.odometry_scale;
    scale.read("enabled", config.enabled);
    scale.read("prior_sigma", config.prior_sigma);
    scale.read("significance_sigmas", config.significance_sigmas);
    scale.read("outlier_sigmas", config.outlier_sigmas);
    if (!(config.prior_sigma > 0.0 && config.prior_sigma <= 1.0))
      scale.fail("prior_sigma", "must be in (0, 1]");
    if (!(config.significance_sigmas >= 0.0 && std::isfinite(config.significance_sigmas)))
      scale.fail("significance_sigmas", "must be >= 0 (0: the factor applied as soon as it differs from 1)");
    if (!(config.outlier_sigmas > 0.0 && std::isfinite(config.outlier_sigmas)))
      scale.fail("outlier_sigmas", "must be positive");
  });
  if (!(slam.icp.overlap > 0.0 && slam.icp.overlap <= 1.0)) section.fail("overlap", "must be in (0, 1]");
  if (!(slam.icp.initial_search_radius_m > 0.0)) section.fail("initial_search_radius_m", "must be positive");
  if (slam.icp.covariance_sectors < 1 || slam.icp.covariance_sectors > 360)
    section.fail("covariance_sectors", "must be in 1..360");
  if (slam.icp.range_weighting_passes < 0 || slam.icp.range_weighting_passes > 10)
    section.fail("range_weighting_passes", "must be in 0..10");
  if (!(slam.icp.residual_tail_dof >= 0.0 && std::isfinite(slam.icp.residual_tail_dof)))
    section.fail("residual_tail_dof", "must be >= 0 (0: Gaussian residuals)");
  if (!(slam.icp.min_constraining_pairs >= 0.0 && std::isfinite(slam.icp.min_constraining_pairs)))
    section.fail("min_constraining_pairs", "must be >= 0 (0: every direction the pairs' own)");
  if (slam.icp.max_iterations < 1 || slam.icp.max_iterations > 1000) {
    section.fail("max_iterations", "must be in 1..1000");
  }
  for (const auto &[key, value] : {std::pair{"max_rms_m", slam.max_rms_m},
                                   {"fusion_radius_m", slam.map.fusion_radius_m},
                                   {"noise_radius_m", slam.map.noise_radius_m}}) {
    if (!(value > 0.0)) section.fail(key, "must be positive");
  }
  for (const auto &[key, value] : {std::pair{"srel_limit_percent", slam.srel_limit_percent},
                                   {"srel_relax_percent", slam.srel_relax_percent},
                                   {"max_correction_m", slam.max_correction_m}}) {
    if (value < 0.0) section.fail(key, "must be >= 0");
  }
  for (const auto &[key, value] : {std::pair{"min_scan_points", slam.min_scan_points},
                                   {"noise_min_neighbors", slam.map.noise_min_neighbors},
                                   {"prune_every", slam.map.prune_every},
                                   {"prune_min_hits", slam.map.prune_min_hits},
                                   {"prune_min_age", slam.map.prune_min_age},
                                   {"lost_after_frames", slam.lost_after_frames}}) {
    if (value < 0) section.fail(key, "must be >= 0");
  }
  if (!(slam.map_min_step_m >= 0.0 && std::isfinite(slam.map_min_step_m)))
    section.fail("map_min_step_m", "must be a distance >= 0 (0: every accepted frame is integrated)");
  if (!(slam.min_inlier_share >= 0.0 && slam.min_inlier_share <= 1.0)) {
    section.fail("min_inlier_share", "must be in [0, 1]");
  }
}

}  // namespace

Config load_config(const std::filesystem::path &file) {
  const std::string name = file.string();
  const YAML::Node root = detail::load_yaml(name);
  Config config;
  if (!root || root.IsNull()) return config;  // an empty file keeps every default
  YamlSection top(root, "", name);
  using detail::read_section;
  read_section(top, "camera", [&](YamlSection &camera) {
    detail::read_camera_fields(camera, config.scan.camera);
    camera.read("camera_height_m", config.scan.camera_height_m);
    if (!(config.scan.camera_height_m > 0.0)) camera.fail("camera_height_m", "must be positive");
  });
  read_section(top, "vision", [&](YamlSection &vision) { read_vision(vision, config.scan.vision); });
  read_section(top, "stereo", [&](YamlSection &stereo) { read_stereo(stereo, config.scan.stereo); });
  read_section(top, "slam", [&](YamlSection &slam) { read_slam(slam, config.slam); });
  read_section(top, "persistence", [&](YamlSection &persistence) {
    persistence.read("state_dir", config.persistence.state_dir);
    persistence.read("resume", config.persistence.resume);
    persistence.read("snapshot_period_s", config.persistence.snapshot_period_s);
    if (config.persistence.snapshot_period_s < 0.0) persistence.fail("snapshot_period_s", "must be >= 0");
    read_choice(persistence, "on_corrupt_snapshot", config.persistence.refuse_corrupt_snapshot,
                {{"start_fresh", false}, {"refuse", true}}, "must be start_fresh or refuse");
    read_choice(persistence, "start_pose", config.persistence.start_pose,
                {{"auto", PersistenceConfig::StartPose::kAuto},
                 {"saved", PersistenceConfig::StartPose::kSaved},
                 {"search", PersistenceConfig::StartPose::kSearch}},
                "must be auto, saved or search");
  });
  read_section(top, "degradation",
               [&](YamlSection &degradation) { detail::read_degradation(degradation, config.degradation); });
  detail::read_service_sections(top, config.service);
  top.finish();
  return config;
}

}  // namespace omnislam::io
