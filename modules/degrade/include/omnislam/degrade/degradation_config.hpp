#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

/// @file
/// Settings of the image degradation that makes a rendered, noise-free image look like
/// the output of a small CMOS board camera. One plain struct per factor, each with an
/// `enabled` switch; the factors are applied in their physical order (exposure,
/// vignetting, dust, blur, noise, jpeg). Only io/ parses them from YAML (section
/// `degradation:`). Image convention: pixel centres at integers, radii about `center_px`.

namespace omnislam::degrade {

/// Per-frame brightness change of auto-exposure hunting and mains-flicker lighting: the
/// whole frame is multiplied by a gain drawn uniformly in [1 - max_change, 1 + max_change].
/// 0.15: frame-to-frame steps of several percent, rarely more than 15%, are what a
/// webcam's auto-exposure does under 50 Hz lights.
struct ExposureConfig {
  bool enabled = true;
  double max_change = 0.15;  ///< relative, in [0, 1)
};

/// Radial fall-off of illumination (lens vignetting, cos^4 law and the mirror's
/// reflectance at grazing angles): gain = 1 - rim_falloff * (r / rim_radius_px)^2, the
/// first term of cos^4, clamped at 0. 0.30 at r = 512 px: a small board-camera lens has
/// a relative illumination of 60-80% at the edge of its image circle.
struct VignettingConfig {
  bool enabled = true;
  double rim_falloff = 0.30;     ///< darkening at rim_radius_px, in [0, 1]
  double rim_radius_px = 512.0;  ///< radius where the darkening is rim_falloff (> 0)
};

/// Dust specks on the mirror: dark soft disks that stay put from frame to frame (they sit
/// on the mirror, not in the scene), so their positions, sizes and opacities depend on the
/// seed only. Each speck multiplies the image by 1 - opacity inside its radius, with a
/// 2 px linear soft edge (out of focus). Placed uniformly by area so that the whole speck,
/// edge included, lies in the mirror annulus [inner_radius_px, outer_radius_px]
/// (62..512 px: the mirror's image between the camera's own reflection and the rim).
/// 12 specks of 2-6 px: a mirror cleaned now and then, a few visible motes.
struct DustConfig {
  bool enabled = true;
  int count = 12;                 ///< number of specks, 0..1000
  double min_radius_px = 2.0;     ///< radius of the opaque core, drawn uniformly
  double max_radius_px = 6.0;     ///< in [min_radius_px, max_radius_px]
  double min_opacity = 0.3;       ///< share of light a speck's core blocks, drawn
  double max_opacity = 0.7;       ///< uniformly in [min_opacity, max_opacity] (0..1)
  double inner_radius_px = 62.0;  ///< mirror annulus about center_px
  double outer_radius_px = 512.0;
};

/// Defocus: a pillbox (disk) point-spread function of radius radius_px, anti-aliased by
/// pixel-area coverage. The mirror's virtual images of near and far objects lie at
/// different depths, so no single focus setting makes them all sharp; 1 px is a small
/// blur circle. 0 disables the blur.
struct BlurConfig {
  bool enabled = true;
  double radius_px = 1.0;  ///< 0..20
};

/// Sensor noise, Poisson-Gaussian: the signal in electrons is value / 255 * full_well_e,
/// its shot noise has variance = signal (Gaussian approximation), plus Gaussian read noise
/// of read_noise_dn; then rounding and clamping to 8 bits. In grey levels (DN) the
/// variance is value * 255 / full_well_e + read_noise_dn^2. 6000 e-: full well of a ~3 um
/// pixel; 2 DN: the dark-frame noise (read, dark current, ADC) of cheap 8-bit cameras.
/// At grey level 128 that is a standard deviation of 3.1 DN.
struct NoiseConfig {
  bool enabled = true;
  double full_well_e = 6000.0;  ///< electrons at grey level 255 (> 0)
  double read_noise_dn = 2.0;   ///< standard deviation in grey levels (>= 0)
};

/// Lossy compression of an MJPEG / network camera stream: encode and decode with libjpeg
/// (OpenCV) at this quality; 85 is a common camera default.
struct JpegConfig {
  bool enabled = true;
  int quality = 85;  ///< 1..100
};

/// All factors. A default-constructed config applies every factor with its default.
struct DegradationConfig {
  std::uint64_t seed = 1;      ///< every random draw depends on (seed, frame number) only
  double center_u_px = 511.5;  ///< optical axis (architecture.md image convention)
  double center_v_px = 511.5;
  ExposureConfig exposure;
  VignettingConfig vignetting;
  DustConfig dust;
  BlurConfig blur;
  NoiseConfig noise;
  JpegConfig jpeg;
};

/// Factor names in the order they are applied.
inline constexpr std::array<std::string_view, 6> kFactorNames = {"exposure", "vignetting", "dust",
                                                                 "blur",     "noise",      "jpeg"};

/// Restricts `config` to the factors of `list`: "all", "none", or comma-separated factor
/// names (exposure, vignetting, dust, blur, noise, jpeg; spaces around names allowed).
/// A factor stays enabled when it is listed and was enabled in `config` (so a config file
/// can switch a factor off for good); an unlisted factor is disabled. Returns an empty
/// string on success; otherwise the error (naming the unknown or empty entry and the valid
/// names) and `config` is unchanged.
[[nodiscard]] std::string apply_factor_list(std::string_view list, DegradationConfig &config);

/// The enabled factors as a comma-separated list in application order, or "none".
[[nodiscard]] std::string enabled_factors(const DegradationConfig &config);

}  // namespace omnislam::degrade
