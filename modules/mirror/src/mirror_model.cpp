#include "omnislam/mirror/mirror_model.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace omnislam::mirror {
namespace {

constexpr double kMmPerM = 1000.0;
constexpr double kHalfPi = std::numbers::pi / 2.0;

MirrorModel::LobeConstants derive(const LobeConfig &lobe, const char *name) {
  MirrorModel::LobeConstants k;
  k.focus_r_mm = lobe.focus_r_mm;
  k.focus_z_mm = lobe.focus_z_mm;
  k.a_mm = lobe.a_mm;
  // The hyperbola's foci are F0 and F, so c is half their distance (mirror.md sec. 1).
  k.c_mm = std::hypot(lobe.focus_r_mm, lobe.focus_z_mm) / 2.0;
  if (!(lobe.a_mm > 0.0) || !(k.c_mm > lobe.a_mm) || !(lobe.focus_z_mm > 0.0)) {
    throw std::invalid_argument(std::string("mirror: ") + name +
                                " lobe needs focus_z_mm > 0 and 0 < a_mm < |F0 F|/2");
  }
  k.b_mm = std::sqrt(k.c_mm * k.c_mm - k.a_mm * k.a_mm);
  k.k = (k.c_mm - k.a_mm) / (k.c_mm + k.a_mm);
  k.beta_rad = std::atan2(lobe.focus_r_mm, lobe.focus_z_mm);  // thesis eq. 2-12
  return k;
}

}  // namespace

MirrorModel::MirrorModel(const MirrorConfig &config)
    : config_(config), inner_(derive(config.inner, "inner")), outer_(derive(config.outer, "outer")) {
  if (!(config.focal_mm > 0.0) || !(config.pixel_pitch_mm > 0.0)) {
    throw std::invalid_argument("mirror: focal_mm and pixel_pitch_mm must be positive");
  }
  if (config.image_width_px <= 0 || config.image_height_px <= 0 || config.discard_px < 0 ||
      config.rows_per_lobe <= 0 || config.columns <= 0) {
    throw std::invalid_argument(
        "mirror: image size, rows_per_lobe and columns must be positive, discard_px >= 0");
  }
}

const MirrorModel::LobeConstants &MirrorModel::constants(Lobe lobe) const {
  return lobe == Lobe::kInner ? inner_ : outer_;
}

MirrorModel::RadiusRange MirrorModel::radius_range(Lobe lobe) const {
  const double first = config_.discard_px + (lobe == Lobe::kInner ? 0 : config_.rows_per_lobe);
  return {first, first + config_.rows_per_lobe};
}

MirrorModel::ThetaRange MirrorModel::theta_range(Lobe lobe) const {
  const RadiusRange radii = radius_range(lobe);
  return {theta_of_radius_px(lobe, radii.min_px), theta_of_radius_px(lobe, radii.max_px)};
}

double MirrorModel::radius_px_of_row(Lobe lobe, double row) const {
  // Row 0 is the bin farthest from the centre; each row samples its bin's centre.
  return radius_range(lobe).max_px - 0.5 - row;
}

double MirrorModel::row_of_radius_px(Lobe lobe, double radius_px) const {
  return radius_range(lobe).max_px - 0.5 - radius_px;
}

std::optional<double> MirrorModel::radius_px_of_theta(Lobe lobe, double theta_rad) const {
  const LobeConstants &c = constants(lobe);
  // Half-angle law in the lobe frame: tan(gamma'/2) = k tan(theta'/2), theta' = theta + beta,
  // gamma = gamma' + beta (mirror.md sec. 3-4).
  const double theta_lobe = theta_rad + c.beta_rad;
  if (!(theta_lobe > 0.0 && theta_lobe < std::numbers::pi)) return std::nullopt;
  const double gamma = c.beta_rad + 2.0 * std::atan(c.k * std::tan(theta_lobe / 2.0));
  if (!(gamma >= 0.0 && gamma < kHalfPi)) return std::nullopt;
  return config_.focal_mm * std::tan(gamma) / config_.pixel_pitch_mm;
}

double MirrorModel::theta_of_radius_px(Lobe lobe, double radius_px) const {
  const LobeConstants &c = constants(lobe);
  const double gamma = std::atan(radius_px * config_.pixel_pitch_mm / config_.focal_mm);
  return 2.0 * std::atan(std::tan((gamma - c.beta_rad) / 2.0) / c.k) - c.beta_rad;
}

MeridianRay MirrorModel::back_project(Lobe lobe, double radius_px) const {
  const LobeConstants &c = constants(lobe);
  return {{c.focus_r_mm / kMmPerM, c.focus_z_mm / kMmPerM}, theta_of_radius_px(lobe, radius_px)};
}

std::optional<double> MirrorModel::project_radius_px(Lobe lobe, const MeridianPoint &point) const {
  if (!std::isfinite(point.range_m) || !std::isfinite(point.height_m)) return std::nullopt;
  const LobeConstants &c = constants(lobe);
  const double theta =
      std::atan2(point.range_m * kMmPerM - c.focus_r_mm, c.focus_z_mm - point.height_m * kMmPerM);
  const std::optional<double> radius = radius_px_of_theta(lobe, theta);
  const RadiusRange annulus = radius_range(lobe);
  if (!radius || *radius < annulus.min_px || *radius >= annulus.max_px) return std::nullopt;
  return radius;
}

std::optional<double> MirrorModel::project_row(Lobe lobe, const MeridianPoint &point) const {
  const std::optional<double> radius = project_radius_px(lobe, point);
  if (!radius) return std::nullopt;
  return row_of_radius_px(lobe, *radius);
}

std::optional<MeridianPoint> MirrorModel::triangulate(double theta_inner_rad, double theta_outer_rad) const {
  // Thesis eq. 2-6 solved as the intersection of two rays from the foci, directions
  // (sin theta, -cos theta); valid only if both ray parameters are positive (mirror.md sec. 6).
  const double si = std::sin(theta_inner_rad), ci = std::cos(theta_inner_rad);
  const double se = std::sin(theta_outer_rad), ce = std::cos(theta_outer_rad);
  const double det = si * ce - se * ci;  // sin(theta_I - theta_E)
  if (!std::isfinite(det) || std::abs(det) < 1e-12) return std::nullopt;
  const double dr = outer_.focus_r_mm - inner_.focus_r_mm;
  const double dz = outer_.focus_z_mm - inner_.focus_z_mm;
  const double s = (dr * ce + se * dz) / det;  // distance along the inner ray
  const double t = (si * dz + ci * dr) / det;  // distance along the outer ray
  if (!(s > 0.0 && t > 0.0)) return std::nullopt;
  return MeridianPoint{(inner_.focus_r_mm + s * si) / kMmPerM, (inner_.focus_z_mm - s * ci) / kMmPerM};
}

std::optional<MeridianPoint> MirrorModel::triangulate_rows(double inner_row, double outer_row) const {
  return triangulate(theta_of_radius_px(Lobe::kInner, radius_px_of_row(Lobe::kInner, inner_row)),
                     theta_of_radius_px(Lobe::kOuter, radius_px_of_row(Lobe::kOuter, outer_row)));
}

double MirrorModel::disparity_at_infinity(double theta_rad) const {
  const std::optional<double> inner = radius_px_of_theta(Lobe::kInner, theta_rad);
  const std::optional<double> outer = radius_px_of_theta(Lobe::kOuter, theta_rad);
  if (!inner || !outer) return std::numeric_limits<double>::quiet_NaN();
  return row_of_radius_px(Lobe::kOuter, *outer) - row_of_radius_px(Lobe::kInner, *inner);
}

}  // namespace omnislam::mirror
