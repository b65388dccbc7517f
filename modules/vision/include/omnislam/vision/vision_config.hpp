#pragma once

/// @file
/// Settings of the vision front-end (thesis sec. 3 steps 1-4, annex A defaults where they
/// apply). Plain structs with defaults; only io/ parses them from YAML.

namespace omnislam::vision {

/// Canny on one panorama (thesis: Sigma 1.0, TamanhoFiltro auto, LimiteSuperior/Inferior auto).
struct CannyConfig {
  double sigma_px = 1.0;         ///< Gaussian smoothing before the gradient
  int half_window_px = 0;        ///< Gaussian window 2w+1; 0 = auto, w = ceil(3 sigma)
  bool auto_thresholds = true;   ///< choose the hysteresis thresholds from the image
  double high_threshold = 40.0;  ///< gradient magnitude (Sobel units on 8-bit), when not auto
  double low_threshold = 16.0;
  /// Auto: the high threshold is this quantile of the gradient magnitude (the share of
  /// pixels taken as "not edge", as in MATLAB's edge(...,'canny')), never below
  /// auto_min_high_threshold (a rendered floor has almost no gradient, so the bare quantile
  /// would turn shading into edges); low = auto_low_ratio * high.
  double auto_not_edge_fraction = 0.7;
  double auto_low_ratio = 0.4;
  double auto_min_high_threshold = 24.0;
  /// Auto: no row's high threshold lies below the gradient magnitude that the frame's
  /// sensor noise alone exceeds at this many pixels of a panorama (the noise measured on each
  /// frame, vision/image_noise.hpp; its gradient follows a Rayleigh law of scale s, exceeding
  /// s sqrt(2 ln(N / n)) at n of N pixels). So a dim, noisy frame keeps the edges that stand
  /// out of its noise and no others. 0 turns the noise floor off.
  double noise_edges_per_panorama = 1.0;
  int min_fragment_px = 6;  ///< 8-connected edge fragments smaller than this are noise
};

/// Nearest horizontal edges and the candidates' similarity window (thesis sec. 3 steps 3-4).
struct EdgeSelectionConfig {
  /// An edge pixel counts as horizontal when |gradient along the column| >= ratio *
  /// |across|; the others (near-vertical edges, whose pixels all lie at one distance) are
  /// dropped. 0.3 drops edges within ~17 deg of vertical: a wall seen obliquely near the
  /// robot makes a steep but not vertical floor contact in the panorama, and 1.0 (45 deg)
  /// loses it (coverage on sim-room-37: 65% with 1.0, 93% with 0.3).
  double horizontal_ratio = 0.3;
  /// Per column keep this many edge runs, counted from the bottom row up (nearest the robot).
  int max_edges_per_column = 4;
  bool blackman_smoothing = false;      ///< thesis UsaBlackman: normalised 7x7 Blackman FIR first
  double min_relative_contrast = 0.15;  ///< (max - min) / mean in the window (IntensidadeRelativa)
  int half_window_rows = 3;             ///< similarity window half-sizes (PD_MeiaJanela*)
  int half_window_columns = 1;
};

struct VisionConfig {
  CannyConfig canny;
  EdgeSelectionConfig selection;
};

}  // namespace omnislam::vision
