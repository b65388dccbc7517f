#include "omnislam/calib/rim.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <utility>
#include <vector>

#include "omnislam/mirror/rig_model.hpp"

namespace omnislam::calib {
namespace {

constexpr double kSampleStepPx = 0.25;
// The slope's centroid is taken over the peak +- this (an edge's blur, not the next edge).
constexpr double kCentroidHalfPx = 2.0;
// The step's two sides are averaged over this far from it (beyond the edge's own blur).
constexpr double kSideFromPx = 2.0;
constexpr double kSideToPx = 5.0;
// A second pass casts the rays from the first pass's centre, so they cross the circle
// square on however far the configured centre was off.
constexpr int kPasses = 2;
// Points of a predicted circle (the image of a mirror edge: a circle, or nearly one).
constexpr int kPredictionPoints = 360;

enum class Polarity { kDarkOutside, kDarkInside };

// Bilinear sample; NaN outside the image.
double sample(const cv::Mat &image, double u, double v) {
  if (!(u >= 0.0 && v >= 0.0 && u <= image.cols - 1.0 && v <= image.rows - 1.0)) return std::nan("");
  const int u0 = std::min(static_cast<int>(u), image.cols - 2),
            v0 = std::min(static_cast<int>(v), image.rows - 2);
  const double fu = u - u0, fv = v - v0;
  const std::uint8_t *top = image.ptr<std::uint8_t>(v0);
  const std::uint8_t *bottom = image.ptr<std::uint8_t>(v0 + 1);
  return (1.0 - fv) * ((1.0 - fu) * top[u0] + fu * top[u0 + 1]) +
         fv * ((1.0 - fu) * bottom[u0] + fu * bottom[u0 + 1]);
}

// The radius where the ray from `centre` at angle `phi` crosses the step, or NaN.
double step_radius(const cv::Mat &image, const Eigen::Vector2d &centre, double phi, double expected_px,
                   Polarity polarity, const RimConfig &config) {
  const double first = std::max(1.0, expected_px - config.search_px);
  const int samples = static_cast<int>((2.0 * config.search_px) / kSampleStepPx) + 1;
  const double cos_phi = std::cos(phi), sin_phi = std::sin(phi);
  const auto at = [&](double radius) {
    return sample(image, centre.x() + radius * cos_phi, centre.y() + radius * sin_phi);
  };
  // The profile, sampled once from half a pixel before the first radius to half a pixel
  // after the last; its derivative over one pixel (central differences), signed so that the
  // step looked for is positive.
  constexpr int kPixel = static_cast<int>(1.0 / kSampleStepPx);
  std::vector<double> profile(static_cast<std::size_t>(samples + kPixel));
  for (int j = 0; j < samples + kPixel; ++j)
    profile[static_cast<std::size_t>(j)] = at(first - 0.5 + j * kSampleStepPx);
  const double sign = polarity == Polarity::kDarkOutside ? -1.0 : 1.0;
  int best = -1;
  double best_slope = 0.0;
  std::vector<double> slopes(static_cast<std::size_t>(samples));
  for (int i = 0; i < samples; ++i) {
    const double slope =
        sign * (profile[static_cast<std::size_t>(i + kPixel)] - profile[static_cast<std::size_t>(i)]);
    slopes[static_cast<std::size_t>(i)] = slope;
    if (std::isfinite(slope) && slope > best_slope) best_slope = slope, best = i;
  }
  // The step's position is the centroid of the slope around its peak: unlike the peak
  // itself, it moves exactly with the edge whatever blur or interpolation spread it.
  const int half = static_cast<int>(kCentroidHalfPx / kSampleStepPx);
  if (best - half < 0 || best + half >= samples) return std::nan("");
  double moment = 0.0, mass = 0.0;
  for (int i = best - half; i <= best + half; ++i) {
    const double slope = slopes[static_cast<std::size_t>(i)];
    if (!std::isfinite(slope)) return std::nan("");
    const double weight = std::max(0.0, slope);
    moment += weight * i, mass += weight;
  }
  const double radius = first + moment / mass * kSampleStepPx;
  // Both sides of the step: the dark one must be dark against the bright one.
  double inside = 0.0, outside = 0.0;
  for (double d = kSideFromPx; d <= kSideToPx; d += 1.0) {
    inside += at(radius - d);
    outside += at(radius + d);
  }
  if (!std::isfinite(inside) || !std::isfinite(outside)) return std::nan("");
  const double dark = polarity == Polarity::kDarkOutside ? outside : inside;
  const double bright = polarity == Polarity::kDarkOutside ? inside : outside;
  if (!(bright > 0.0) || dark > config.max_dark_share * bright) return std::nan("");
  return radius;
}

std::optional<CircleFit> find_circle(const cv::Mat &image, Eigen::Vector2d centre, double expected_px,
                                     Polarity polarity, const RimConfig &config) {
  std::optional<CircleFit> fit;
  for (int pass = 0; pass < kPasses; ++pass) {
    std::vector<Eigen::Vector2d> points;
    for (int ray = 0; ray < config.rays; ++ray) {
      const double phi = 2.0 * std::numbers::pi * (ray + 0.5) / config.rays;
      const double radius = step_radius(image, centre, phi, expected_px, polarity, config);
      if (std::isfinite(radius))
        points.emplace_back(centre.x() + radius * std::cos(phi), centre.y() + radius * std::sin(phi));
    }
    if (static_cast<double>(points.size()) < config.min_ray_share * config.rays) return std::nullopt;
    fit = fit_circle(points);
    if (!fit || static_cast<double>(fit->inliers) < config.min_ray_share * config.rays) return std::nullopt;
    centre = fit->centre_px;
    expected_px = fit->radius_px;
  }
  return fit;
}

}  // namespace

RimPrediction predict_rim(const mirror::MirrorConfig &camera) {
  // The lobes' layout in the image (mirror.md sec. 0): the central disc ends where the inner
  // lobe begins, the rim where the outer lobe ends.
  const double central_px = camera.discard_px;
  const double rim_px = camera.discard_px + 2.0 * camera.rows_per_lobe;
  const Eigen::Vector2d configured(camera.center_u_px, camera.center_v_px);
  RimPrediction prediction{configured, rim_px, configured, central_px};
  if (camera.rig.nominal()) return prediction;
  const mirror::RigModel rig(camera);
  const auto circle = [&](mirror::Lobe lobe, double radius_px, Eigen::Vector2d &centre, double &radius) {
    std::vector<Eigen::Vector2d> points;
    for (int i = 0; i < kPredictionPoints; ++i) {
      const auto pixel =
          rig.mirror_edge_pixel(lobe, radius_px, 2.0 * std::numbers::pi * i / kPredictionPoints);
      if (pixel) points.emplace_back(pixel->u_px, pixel->v_px);
    }
    if (const std::optional<CircleFit> fit = fit_circle(points))
      centre = fit->centre_px, radius = fit->radius_px;
  };
  circle(mirror::Lobe::kOuter, rim_px, prediction.rim_centre_px, prediction.rim_radius_px);
  circle(mirror::Lobe::kInner, central_px, prediction.central_centre_px, prediction.central_radius_px);
  return prediction;
}

RimEstimate find_rim(const cv::Mat &image, const mirror::MirrorConfig &camera, const RimConfig &config) {
  RimEstimate estimate;
  if (image.empty() || image.type() != CV_8UC1) {
    estimate.error = "not an 8-bit grey image";
    return estimate;
  }
  const RimPrediction predicted = predict_rim(camera);
  estimate.rim =
      find_circle(image, predicted.rim_centre_px, predicted.rim_radius_px, Polarity::kDarkOutside, config);
  estimate.central = find_circle(image, predicted.central_centre_px, predicted.central_radius_px,
                                 Polarity::kDarkInside, config);
  if (!estimate.rim && !estimate.central) {
    estimate.error = "no mirror rim and no central disc found (a dark step on too few of " +
                     std::to_string(config.rays) + " radial profiles)";
    return estimate;
  }
  // Inverse-variance mean per coordinate of the circles found.
  Eigen::Vector2d weighted = Eigen::Vector2d::Zero(), weights = Eigen::Vector2d::Zero();
  for (const std::optional<CircleFit> &circle : {estimate.rim, estimate.central}) {
    if (!circle) continue;
    const Eigen::Vector2d sigma = circle->centre_sigma_px.cwiseMax(1e-6);
    const Eigen::Vector2d weight = sigma.cwiseProduct(sigma).cwiseInverse();
    weighted += weight.cwiseProduct(circle->centre_px);
    weights += weight;
  }
  estimate.centre_px = weighted.cwiseQuotient(weights);
  estimate.centre_sigma_px = weights.cwiseInverse().cwiseSqrt();
  if (!camera.rig.nominal()) {
    // A centre error shifts both circles alike (to first order); their offsets from where
    // the configured rig puts them are the centre's error.
    Eigen::Vector2d offset = Eigen::Vector2d::Zero(), offset_weights = Eigen::Vector2d::Zero();
    const std::pair<const std::optional<CircleFit> *, Eigen::Vector2d> circles[] = {
        {&estimate.rim, predicted.rim_centre_px}, {&estimate.central, predicted.central_centre_px}};
    for (const auto &[circle, expected] : circles) {
      if (!*circle) continue;
      const Eigen::Vector2d sigma = (*circle)->centre_sigma_px.cwiseMax(1e-6);
      const Eigen::Vector2d weight = sigma.cwiseProduct(sigma).cwiseInverse();
      offset += weight.cwiseProduct((*circle)->centre_px - expected);
      offset_weights += weight;
    }
    estimate.centre_px =
        Eigen::Vector2d(camera.center_u_px, camera.center_v_px) + offset.cwiseQuotient(offset_weights);
  }
  return estimate;
}

}  // namespace omnislam::calib
