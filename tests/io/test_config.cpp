#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "omnislam/io/config.hpp"

namespace fs = std::filesystem;

namespace {

fs::path write_file(const std::string &name, const std::string &text) {
  const fs::path dir = fs::temp_directory_path() / "omnislam-test-config";
  fs::create_directories(dir);
  const fs::path file = dir / name;
  std::ofstream(file) << text;
  return file;
}

}  // namespace

TEST_CASE("config: every section read on top of the defaults", "[io][config]") {
  const fs::path file = write_file("full.yaml",
                                   "# a comment\n"
                                   "camera:\n"
                                   "  width: 800\n"
                                   "  height: 600\n"
                                   "  center_px: [399.5, 299.5]\n"
                                   "  azimuth_offset_deg: 12.5\n"
                                   "  camera_height_m: 0.8\n"
                                   "vision:\n"
                                   "  sigma_px: 1.5\n"
                                   "  auto_thresholds: false\n"
                                   "  max_edges_per_column: 6\n"
                                   "  blackman_smoothing: true\n"
                                   "stereo:\n"
                                   "  occlusion_cost: 3.0\n"
                                   "  subpixel: cost_curve\n"
                                   "  triangulation: table\n"
                                   "  far_cutoff_m: 2.0\n"
                                   "  boundary: nearest_edge\n"
                                   "  floor:\n"
                                   "    max_edges_per_column: 20\n"
                                   "    contact_margin_px: 2.0\n"
                                   "    error_rate: 0.05\n"
                                   "    floor_plane_range: false\n"
                                   "    contact_ray_sigma_px: 1.0\n");
  const omnislam::io::Config config = omnislam::io::load_config(file);
  const auto &scan = config.scan;
  CHECK(scan.camera.image_width_px == 800);
  CHECK(scan.camera.image_height_px == 600);
  CHECK(scan.camera.center_u_px == 399.5);
  CHECK(scan.camera.center_v_px == 299.5);
  CHECK(scan.camera.azimuth_offset_deg == 12.5);
  CHECK(scan.camera.focal_mm == 25.0);  // default kept
  CHECK(scan.camera_height_m == 0.8);
  CHECK(scan.vision.canny.sigma_px == 1.5);
  CHECK_FALSE(scan.vision.canny.auto_thresholds);
  CHECK(scan.vision.selection.max_edges_per_column == 6);
  CHECK(scan.vision.selection.blackman_smoothing);
  CHECK(scan.vision.selection.min_relative_contrast == 0.15);
  CHECK(scan.stereo.occlusion_cost == 3.0);
  CHECK(scan.stereo.subpixel == omnislam::stereo::SubpixelMethod::kCostCurve);
  CHECK(scan.stereo.triangulation == omnislam::stereo::TriangulationMethod::kTable);
  CHECK(scan.stereo.far_cutoff_m == 2.0);
  CHECK(scan.stereo.boundary == omnislam::stereo::BoundaryMethod::kNearestEdge);
  CHECK(scan.stereo.floor.max_edges_per_column == 20);
  CHECK(scan.stereo.floor.contact_margin_px == 2.0);
  CHECK(scan.stereo.floor.error_rate == 0.05);
  CHECK_FALSE(scan.stereo.floor.floor_plane_range);
  CHECK(scan.stereo.floor.contact_ray_sigma_px == 1.0);
  CHECK(scan.stereo.near_cutoff_m == 0.3);
}

TEST_CASE("config: an empty file keeps the defaults", "[io][config]") {
  const omnislam::io::Config config = omnislam::io::load_config(write_file("empty.yaml", ""));
  CHECK(config.scan.camera_height_m == 1.0);
  CHECK(config.scan.stereo.subpixel == omnislam::stereo::SubpixelMethod::kEdgePeak);
}

TEST_CASE("config: unknown keys and wrong types name the key and file:line", "[io][config]") {
  const fs::path unknown = write_file("unknown.yaml", "vision:\n  sigma_px: 1.0\n  sigmaa: 2\n");
  CHECK_THROWS_WITH(omnislam::io::load_config(unknown),
                    Catch::Contains("unknown.yaml:3:") && Catch::Contains("unknown key 'vision.sigmaa'"));
  const fs::path section = write_file("section.yaml", "camera: {}\nslam_typo: {}\n");
  CHECK_THROWS_WITH(omnislam::io::load_config(section),
                    Catch::Contains("section.yaml:2:") && Catch::Contains("'slam_typo'"));
  const fs::path type = write_file("type.yaml", "stereo:\n  occlusion_cost: high\n");
  CHECK_THROWS_WITH(
      omnislam::io::load_config(type),
      Catch::Contains("type.yaml:2:") && Catch::Contains("'stereo.occlusion_cost' must be a number"));
  const fs::path integer = write_file("integer.yaml", "vision:\n  max_edges_per_column: 2.5\n");
  CHECK_THROWS_WITH(omnislam::io::load_config(integer),
                    Catch::Contains("integer.yaml:2:") && Catch::Contains("must be an integer"));
  const fs::path floor = write_file("floor.yaml", "stereo:\n  floor:\n    error_rate: 0.7\n");
  CHECK_THROWS_WITH(omnislam::io::load_config(floor), Catch::Contains("'stereo.floor.error_rate'"));
  const fs::path floor_key = write_file("floor_key.yaml", "stereo:\n  floor:\n    margin: 1\n");
  CHECK_THROWS_WITH(omnislam::io::load_config(floor_key),
                    Catch::Contains("floor_key.yaml:3:") && Catch::Contains("'stereo.floor.margin'"));
  const fs::path boundary = write_file("boundary.yaml", "stereo:\n  boundary: widest\n");
  CHECK_THROWS_WITH(omnislam::io::load_config(boundary),
                    Catch::Contains("boundary.yaml:2:") && Catch::Contains("floor_boundary or nearest_edge"));
  const fs::path choice = write_file("choice.yaml", "stereo:\n  subpixel: magic\n");
  CHECK_THROWS_WITH(omnislam::io::load_config(choice),
                    Catch::Contains("choice.yaml:2:") && Catch::Contains("none, edge_peak or cost_curve"));
  const fs::path center = write_file("center.yaml", "camera:\n  center_px: 511.5\n");
  CHECK_THROWS_WITH(omnislam::io::load_config(center),
                    Catch::Contains("center.yaml:2:") && Catch::Contains("camera.center_px"));
  const fs::path syntax = write_file("syntax.yaml", "camera:\n  width: [1, 2\n");
  CHECK_THROWS_WITH(omnislam::io::load_config(syntax), Catch::Contains("syntax.yaml:"));
  CHECK_THROWS_WITH(omnislam::io::load_config("/nonexistent/omnislam.yaml"),
                    Catch::Contains("/nonexistent/omnislam.yaml"));
}

TEST_CASE("config: the rig's misalignments in the camera section, bad values named", "[io][config][rig]") {
  const fs::path file = write_file("rig.yaml",
                                   "camera:\n"
                                   "  focal_scale: 1.008\n"
                                   "  mirror_dz_mm: 2.5\n"
                                   "  mirror_tilt_deg: [0.8, -0.5]\n"
                                   "  mirror_offset_mm: [0.7, -0.4]\n"
                                   "  level_tilt_deg: [0.8, -0.6]\n");
  const omnislam::mirror::RigConfig rig = omnislam::io::load_config(file).scan.camera.rig;
  CHECK(rig.focal_scale == 1.008);
  CHECK(rig.mirror_dz_mm == 2.5);
  CHECK(rig.mirror_tilt_x_rad == Approx(0.8 * 3.14159265358979323846 / 180.0).epsilon(1e-15));
  CHECK(rig.mirror_tilt_y_rad == Approx(-0.5 * 3.14159265358979323846 / 180.0).epsilon(1e-15));
  CHECK(rig.mirror_offset_x_mm == 0.7);
  CHECK(rig.mirror_offset_y_mm == -0.4);
  CHECK(rig.level_tilt_x_rad == Approx(0.8 * 3.14159265358979323846 / 180.0).epsilon(1e-15));
  CHECK(rig.level_tilt_y_rad == Approx(-0.6 * 3.14159265358979323846 / 180.0).epsilon(1e-15));
  CHECK_FALSE(rig.nominal());
  CHECK_FALSE(omnislam::io::load_config(write_file("tilt.yaml", "camera:\n  level_tilt_deg: [0, 0.1]\n"))
                  .scan.camera.rig.nominal());
  CHECK(omnislam::io::load_config(write_file("norig.yaml", "camera:\n  width: 1024\n"))
            .scan.camera.rig.nominal());
  const std::pair<const char *, const char *> bad[] = {
      {"camera:\n  focal_scale: 0\n", "camera.focal_scale"},
      {"camera:\n  mirror_dz_mm: 270\n", "camera.mirror_dz_mm"},
      {"camera:\n  mirror_tilt_deg: 1.0\n", "camera.mirror_tilt_deg"},
      {"camera:\n  mirror_tilt_deg: [0, 90]\n", "camera.mirror_tilt_deg"},
      {"camera:\n  mirror_offset_mm: [0.5, .nan]\n", "camera.mirror_offset_mm"},
      {"camera:\n  mirror_offset: [0.5, 0]\n", "camera.mirror_offset"},
      {"camera:\n  level_tilt_deg: [6, 0]\n", "camera.level_tilt_deg"},
  };
  for (const auto &[text, key] : bad) {
    CAPTURE(text);
    CHECK_THROWS_WITH(omnislam::io::load_config(write_file("badrig.yaml", text)),
                      Catch::Contains("badrig.yaml:2:") && Catch::Contains(key));
  }
}

TEST_CASE("config: the degradation section, per factor, with errors naming key and line", "[io][config]") {
  const fs::path file =
      write_file("degradation.yaml",
                 "degradation:\n"
                 "  seed: 42\n"
                 "  center_px: [500.0, 510.5]\n"
                 "  exposure: {max_change: 0.05}\n"
                 "  vignetting: {enabled: false, rim_falloff: 0.2, rim_radius_px: 480}\n"
                 "  dust: {count: 3, min_radius_px: 1, max_radius_px: 2, max_opacity: 0.5}\n"
                 "  blur: {radius_px: 1.5}\n"
                 "  noise: {full_well_e: 9000, read_noise_dn: 1.0}\n"
                 "  jpeg: {quality: 70}\n");
  const omnislam::degrade::DegradationConfig d = omnislam::io::load_config(file).degradation;
  CHECK(d.seed == 42);
  CHECK(d.center_u_px == 500.0);
  CHECK(d.center_v_px == 510.5);
  CHECK(d.exposure.enabled);
  CHECK(d.exposure.max_change == 0.05);
  CHECK_FALSE(d.vignetting.enabled);
  CHECK(d.vignetting.rim_falloff == 0.2);
  CHECK(d.vignetting.rim_radius_px == 480.0);
  CHECK(d.dust.count == 3);
  CHECK(d.dust.max_radius_px == 2.0);
  CHECK(d.dust.min_opacity == 0.3);  // default kept
  CHECK(d.dust.max_opacity == 0.5);
  CHECK(d.blur.radius_px == 1.5);
  CHECK(d.noise.full_well_e == 9000.0);
  CHECK(d.noise.read_noise_dn == 1.0);
  CHECK(d.jpeg.quality == 70);
  CHECK(omnislam::io::load_config(write_file("no-degradation.yaml", "")).degradation.noise.full_well_e ==
        6000.0);

  const auto fails = [](const char *name, const char *text, const char *location, const char *message) {
    CAPTURE(name);
    CHECK_THROWS_WITH(omnislam::io::load_config(write_file(name, text)),
                      Catch::Contains(location) && Catch::Contains(message));
  };
  fails("degradation-unknown.yaml", "degradation:\n  noise:\n    full_well: 5000\n",
        "degradation-unknown.yaml:3:", "unknown key 'degradation.noise.full_well'");
  fails("degradation-factor.yaml", "degradation:\n  smudge: {}\n",
        "degradation-factor.yaml:2:", "unknown key 'degradation.smudge'");
  fails("degradation-type.yaml", "degradation:\n  blur: {radius_px: wide}\n",
        "degradation-type.yaml:2:", "'degradation.blur.radius_px' must be a number");
  fails("degradation-range.yaml", "degradation:\n  jpeg:\n    quality: 101\n",
        "degradation-range.yaml:3:", "'degradation.jpeg.quality' must be in 1..100");
  fails("degradation-seed.yaml", "degradation:\n  seed: -1\n",
        "degradation-seed.yaml:2:", "'degradation.seed' must be a non-negative integer");
  fails("degradation-opacity.yaml", "degradation:\n  dust: {min_opacity: 0.8, max_opacity: 0.6}\n",
        "degradation-opacity.yaml:2:", "'degradation.dust.max_opacity' must be in [0.8, 1]");
  fails("degradation-exposure.yaml", "degradation:\n  exposure: {max_change: 1.0}\n",
        "degradation-exposure.yaml:2:", "'degradation.exposure.max_change' must be in [0, 1)");
  fails("degradation-enabled.yaml", "degradation:\n  noise: {enabled: maybe}\n",
        "degradation-enabled.yaml:2:", "'degradation.noise.enabled' must be true or false");
}

TEST_CASE("config: the slam section, and the bundled thesis preset", "[io][config]") {
  const fs::path file =
      write_file("slam.yaml",
                 "slam:\n  target: previous_scan\n  metric: point_to_point\n  overlap: 0.8\n"
                 "  max_correction_deg: 5\n  prune_min_age: 0\n");
  const omnislam::io::Config config = omnislam::io::load_config(file);
  CHECK(config.slam.target == omnislam::slam::RegistrationTarget::kPreviousScan);
  CHECK(config.slam.icp.metric == omnislam::slam::IcpMetric::kPointToPoint);
  CHECK(config.slam.icp.overlap == 0.8);
  CHECK(config.slam.max_correction_rad == Approx(5.0 * 3.14159265358979 / 180.0));
  CHECK(config.slam.map.prune_min_age == 0);
  CHECK_THROWS_WITH(omnislam::io::load_config(write_file("slam-bad.yaml", "slam:\n  overlap: 1.5\n")),
                    Catch::Contains("slam-bad.yaml:2") && Catch::Contains("overlap"));
  CHECK_THROWS_WITH(omnislam::io::load_config(write_file("slam-choice.yaml", "slam:\n  target: moon\n")),
                    Catch::Contains("target"));
  CHECK(omnislam::io::Config{}.slam.icp.residual_tail_dof == 4.0);
  CHECK(omnislam::io::load_config(write_file("slam-tail.yaml", "slam:\n  residual_tail_dof: 0\n"))
            .slam.icp.residual_tail_dof == 0.0);
  CHECK_THROWS_WITH(
      omnislam::io::load_config(write_file("slam-tail-bad.yaml", "slam:\n  residual_tail_dof: -1\n")),
      Catch::Contains("slam-tail-bad.yaml:2") && Catch::Contains("residual_tail_dof"));
  const omnislam::io::Config thesis =
      omnislam::io::load_config(OMNISLAM_SOURCE_DIR "/deploy/thesis-2008.yaml");
  CHECK(thesis.slam.use_srel_test);
  CHECK(thesis.slam.target == omnislam::slam::RegistrationTarget::kPreviousScan);
  CHECK_FALSE(thesis.slam.loop_closure.enabled);  // the thesis has no pose graph
  CHECK_FALSE(thesis.slam.odometry_gate);         // nor a plausibility gate on corrections
  CHECK(omnislam::io::Config{}.slam.odometry_gate);
  CHECK_FALSE(thesis.slam.odometry_prior);  // nor a prior in the registration
  CHECK(omnislam::io::Config{}.slam.odometry_prior);
  CHECK_FALSE(omnislam::io::load_config(write_file("slam-gate.yaml", "slam:\n  odometry_gate: false\n"))
                  .slam.odometry_gate);
}

TEST_CASE("config: slam.loop_closure, with unknown keys and bad values naming key and line", "[io][config]") {
  const omnislam::io::Config defaults;
  CHECK(defaults.slam.loop_closure.enabled);
  const omnislam::io::Config config = omnislam::io::load_config(
      write_file("loops.yaml",
                 "slam:\n  loop_closure:\n    enabled: false\n    keyframe_distance_m: 0.8\n"
                 "    keyframe_angle_deg: 30\n    min_path_gap_m: 8\n    max_candidates: 2\n"
                 "    drift_per_m: 0.05\n    max_window_deg: 6\n    min_overlap: 0.7\n"
                 "    loop_chi2_limit: 16.27\n    keyframe_max_scans: 8\n"));
  const omnislam::slam::LoopClosureConfig &loops = config.slam.loop_closure;
  CHECK_FALSE(loops.enabled);
  CHECK(loops.keyframes.keyframe_distance_m == 0.8);
  CHECK(loops.keyframes.keyframe_angle_rad == Approx(30.0 * 3.14159265358979 / 180.0));
  CHECK(loops.min_path_gap_m == 8.0);
  CHECK(loops.max_candidates == 2);
  CHECK(loops.keyframes.drift_per_m == 0.05);
  CHECK(loops.max_window_rad == Approx(6.0 * 3.14159265358979 / 180.0));
  CHECK(loops.min_overlap == 0.7);
  CHECK(loops.graph.loop_chi2_limit == 16.27);
  CHECK(loops.keyframes.max_scans == 8);
  CHECK(loops.ambiguity_ratio == defaults.slam.loop_closure.ambiguity_ratio);  // unset keys keep defaults
  CHECK_THROWS_WITH(
      omnislam::io::load_config(
          write_file("loops-unknown.yaml", "slam:\n  loop_closure:\n    enable: true\n")),
      Catch::Contains("loops-unknown.yaml:3:") && Catch::Contains("unknown key 'slam.loop_closure.enable'"));
  CHECK_THROWS_WITH(
      omnislam::io::load_config(
          write_file("loops-share.yaml", "slam:\n  loop_closure:\n    min_overlap: 1.5\n")),
      Catch::Contains("loops-share.yaml:3") && Catch::Contains("'slam.loop_closure.min_overlap'"));
  CHECK_THROWS_WITH(omnislam::io::load_config(
                        write_file("loops-count.yaml", "slam:\n  loop_closure:\n    max_candidates: 0\n")),
                    Catch::Contains("max_candidates"));
  CHECK_THROWS_WITH(omnislam::io::load_config(write_file(
                        "loops-scans.yaml", "slam:\n  loop_closure:\n    keyframe_max_scans: 0\n")),
                    Catch::Contains("loops-scans.yaml:3") && Catch::Contains("keyframe_max_scans"));
}

TEST_CASE("config: slam.map_min_step_m, 0 for the thesis", "[io][config]") {
  CHECK(omnislam::io::Config{}.slam.map_min_step_m == 0.05);
  CHECK(omnislam::io::load_config(OMNISLAM_SOURCE_DIR "/deploy/thesis-2008.yaml").slam.map_min_step_m == 0.0);
  CHECK(omnislam::io::load_config(write_file("step.yaml", "slam:\n  map_min_step_m: 0.1\n"))
            .slam.map_min_step_m == 0.1);
  CHECK_THROWS_WITH(omnislam::io::load_config(write_file("step-bad.yaml", "slam:\n  map_min_step_m: -0.1\n")),
                    Catch::Contains("step-bad.yaml:2") && Catch::Contains("map_min_step_m"));
}

TEST_CASE("config: slam.lost_after_frames, 0 (never lost) for the thesis", "[io][config]") {
  CHECK(omnislam::io::Config{}.slam.lost_after_frames == 3);
  CHECK(omnislam::io::load_config(OMNISLAM_SOURCE_DIR "/deploy/thesis-2008.yaml").slam.lost_after_frames ==
        0);
  CHECK(omnislam::io::load_config(OMNISLAM_SOURCE_DIR "/deploy/omnislamd.yaml").slam.lost_after_frames == 3);
  CHECK(omnislam::io::load_config(write_file("lost.yaml", "slam:\n  lost_after_frames: 5\n"))
            .slam.lost_after_frames == 5);
  CHECK_THROWS_WITH(
      omnislam::io::load_config(write_file("lost-bad.yaml", "slam:\n  lost_after_frames: -1\n")),
      Catch::Contains("lost-bad.yaml:2") && Catch::Contains("lost_after_frames"));
}

TEST_CASE("config: the installed defaults (deploy/*.yaml) load", "[io][config]") {
  const fs::path deploy = fs::path(OMNISLAM_SOURCE_DIR) / "deploy";
  const omnislam::io::Config service = omnislam::io::load_config(deploy / "omnislamd.yaml");
  CHECK(service.scan.camera.image_width_px == 1024);
  CHECK(service.scan.camera_height_m == 1.0);
  CHECK_FALSE(service.slam.localization_only);
  CHECK(service.persistence.snapshot_period_s == 30.0);
  CHECK_FALSE(service.persistence.refuse_corrupt_snapshot);
  const omnislam::io::Config thesis = omnislam::io::load_config(deploy / "thesis-2008.yaml");
  CHECK(thesis.slam.target == omnislam::slam::RegistrationTarget::kPreviousScan);
}

TEST_CASE("config: dds.tf frames, rate and future dating; bad values name the key", "[io][config]") {
  const omnislam::io::Config defaults =
      omnislam::io::load_config(write_file("tf_default.yaml", "dds:\n  domain_id: 3\n"));
  CHECK(defaults.service.dds.tf.enabled);
  CHECK(defaults.service.dds.tf.map_frame == "map");
  CHECK(defaults.service.dds.tf.odom_frame == "odom");
  CHECK(defaults.service.dds.tf.base_frame == "base_link");
  CHECK_FALSE(defaults.service.dds.tf.publish_odom_to_base);
  CHECK(defaults.service.dds.tf.rate_hz == 20.0);
  CHECK(defaults.service.dds.tf.future_dating_s == 0.1);
  const omnislam::io::Config set = omnislam::io::load_config(
      write_file("tf_set.yaml",
                 "dds:\n  tf: {map_frame: world, publish_odom_to_base: true, rate_hz: 50, "
                 "future_dating_s: 0.2}\n"));
  CHECK(set.service.dds.tf.map_frame == "world");
  CHECK(set.service.dds.tf.publish_odom_to_base);
  CHECK(set.service.dds.tf.rate_hz == 50.0);
  CHECK(set.service.dds.tf.future_dating_s == 0.2);
  CHECK_THROWS_WITH(omnislam::io::load_config(write_file("tf_rate.yaml", "dds:\n  tf:\n    rate_hz: 0\n")),
                    Catch::Contains("tf_rate.yaml:3:") && Catch::Contains("rate_hz"));
  CHECK_THROWS_WITH(omnislam::io::load_config(write_file("tf_key.yaml", "dds:\n  tf:\n    rate: 10\n")),
                    Catch::Contains("tf_key.yaml:3:") && Catch::Contains("rate"));
}
