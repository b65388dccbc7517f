#include "omnislam/mirror/rig_model.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace omnislam::mirror {
namespace {

// Distance from the axis. Not std::hypot: its care against overflow costs a quarter of a
// ray-mirror intersection, and the values here are millimetres.
double radial(double x, double y) { return std::sqrt(x * x + y * y); }

constexpr double kMmPerM = 1000.0;
constexpr int kMaxNewtonSteps = 30;
constexpr double kSurfaceTolMm = 1e-11;  // Newton step along the camera ray
constexpr int kMaxGaussNewtonSteps = 20;
constexpr double kPixelTolPx = 1e-9;  // Gauss-Newton step on the pixel
constexpr double kJacobianStepPx = 1e-4;

// The lobe's meridian profile (mirror.md sec. 2, eq. 2-5) and its gradient in (r, z):
// g = ((z_E - c)/a)^2 - (r_E/b)^2 - 1 with the lobe frame rotated by beta.
struct Profile {
  double value = 0.0;
  double d_r = 0.0;
  double d_z = 0.0;
  double z_lobe = 0.0;  // z_E: the mirror branch has z_E > c
};

// sb, cb: sin and cos of k.beta_rad (hoisted out of the intersection's Newton steps).
Profile profile(const MirrorModel::LobeConstants &k, double sb, double cb, double r, double z) {
  const double r_e = r * cb - z * sb;
  const double z_e = r * sb + z * cb;
  const double p = (z_e - k.c_mm) / (k.a_mm * k.a_mm);
  const double q = r_e / (k.b_mm * k.b_mm);
  Profile out;
  out.value = (z_e - k.c_mm) * p - r_e * q - 1.0;
  out.d_r = 2.0 * (p * sb - q * cb);
  out.d_z = 2.0 * (p * cb + q * sb);
  out.z_lobe = z_e;
  return out;
}

// The designed lobe's mirror radius seen at image radius radius_px (mirror.md sec. 2:
// |M F0| = b^2 / (c cos(gamma - beta) - a)).
double design_mirror_radius_mm(const MirrorModel &design, Lobe lobe, double radius_px) {
  const MirrorModel::LobeConstants &k = design.constants(lobe);
  const double gamma = std::atan(radius_px * design.config().pixel_pitch_mm / design.config().focal_mm);
  return k.b_mm * k.b_mm / (k.c_mm * std::cos(gamma - k.beta_rad) - k.a_mm) * std::sin(gamma);
}

}  // namespace

Eigen::Matrix3d tilt_rotation(double tilt_x_rad, double tilt_y_rad) {
  return (Eigen::AngleAxisd(tilt_y_rad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(tilt_x_rad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

RigModel::RigModel(const MirrorConfig &config) : design_(config) {
  const RigConfig &rig = config.rig;
  rotation_ = tilt_rotation(rig.mirror_tilt_x_rad, rig.mirror_tilt_y_rad);
  level_ = tilt_rotation(rig.level_tilt_x_rad, rig.level_tilt_y_rad);
  pivot_mm_ = Eigen::Vector3d(0.0, 0.0, design_.constants(Lobe::kInner).focus_z_mm);
  shift_mm_ = Eigen::Vector3d(rig.mirror_offset_x_mm, rig.mirror_offset_y_mm, rig.mirror_dz_mm);
  focal_px_ = rig.focal_scale * config.focal_mm / config.pixel_pitch_mm;
  for (const Lobe lobe : {Lobe::kInner, Lobe::kOuter}) {
    const MirrorModel::RadiusRange annulus = design_.radius_range(lobe);
    Extent &extent = lobe == Lobe::kInner ? inner_extent_ : outer_extent_;
    extent.min_mm = design_mirror_radius_mm(design_, lobe, annulus.min_px);
    extent.max_mm = design_mirror_radius_mm(design_, lobe, annulus.max_px);
    extent.mm_per_px = (extent.max_mm - extent.min_mm) / (annulus.max_px - annulus.min_px);
  }
}

bool RigModel::sees_lobe(Lobe lobe, const Pixel &pixel, double margin_px) const {
  const std::optional<double> radius_mm = mirror_radius_mm(lobe, pixel);
  if (!radius_mm) return false;
  const Extent &extent = lobe == Lobe::kInner ? inner_extent_ : outer_extent_;
  const double margin_mm = margin_px * extent.mm_per_px;
  if (*radius_mm < extent.min_mm + margin_mm || *radius_mm > extent.max_mm - margin_mm) return false;
  if (lobe == Lobe::kInner) return true;
  // The inner lobe hangs below the outer one, its rim on the camera rays of the outer lobe's
  // inner edge (mirror.md sec. 2); once the mirror has moved it hides some of them.
  const std::optional<double> inner_mm = mirror_radius_mm(Lobe::kInner, pixel);
  return !inner_mm || *inner_mm > inner_extent_.max_mm + margin_px * inner_extent_.mm_per_px;
}

std::optional<RigModel::MirrorHit> RigModel::hit(Lobe lobe, const Pixel &pixel) const {
  const MirrorConfig &config = design_.config();
  const MirrorModel::LobeConstants &k = design_.constants(lobe);
  const Eigen::Vector3d dir_camera =
      Eigen::Vector3d(pixel.u_px - config.center_u_px, pixel.v_px - config.center_v_px, focal_px_)
          .normalized();
  // The pinhole and the camera ray in the mirror's design frame.
  const Eigen::Vector3d origin = rotation_.transpose() * (-pivot_mm_ - shift_mm_) + pivot_mm_;
  const Eigen::Vector3d dir = rotation_.transpose() * dir_camera;
  // Start at the designed mirror point of this ray's angle (mirror.md sec. 2).
  const double gamma = std::atan2(radial(dir.x(), dir.y()), dir.z());
  const double denominator = k.c_mm * std::cos(gamma - k.beta_rad) - k.a_mm;
  if (!(denominator > 0.0)) return std::nullopt;
  const double sb = std::sin(k.beta_rad), cb = std::cos(k.beta_rad);
  double t = k.b_mm * k.b_mm / denominator;
  bool converged = false;
  for (int step = 0; step < kMaxNewtonSteps && !converged; ++step) {
    const Eigen::Vector3d p = origin + t * dir;
    const double r = radial(p.x(), p.y());
    if (!(r > 1e-9)) return std::nullopt;
    const Profile g = profile(k, sb, cb, r, p.z());
    const double slope = g.d_r * (p.x() * dir.x() + p.y() * dir.y()) / r + g.d_z * dir.z();
    if (!(std::abs(slope) > 0.0)) return std::nullopt;
    const double dt = g.value / slope;
    t -= dt;
    converged = std::abs(dt) < kSurfaceTolMm;
  }
  if (!converged || !(t > 0.0)) return std::nullopt;
  const Eigen::Vector3d p = origin + t * dir;
  const double r = radial(p.x(), p.y());
  const Profile g = profile(k, sb, cb, r, p.z());
  if (!(g.z_lobe > k.c_mm) || !(r > 1e-9)) return std::nullopt;  // the other sheet
  const Eigen::Vector3d normal = Eigen::Vector3d(g.d_r * p.x() / r, g.d_r * p.y() / r, g.d_z).normalized();
  return MirrorHit{p, normal, dir};
}

std::optional<Ray3> RigModel::back_project(Lobe lobe, const Pixel &pixel) const {
  const std::optional<MirrorHit> h = hit(lobe, pixel);
  if (!h) return std::nullopt;
  // Law of reflection: the camera ray reversed is the light's path, so the world ray
  // leaves the mirror point along the reflected camera ray.
  const Eigen::Vector3d reflected = h->ray_dir - 2.0 * h->ray_dir.dot(h->normal) * h->normal;
  Ray3 ray;
  ray.origin_m = level_ * (rotation_ * (h->point_mm - pivot_mm_) + pivot_mm_ + shift_mm_) / kMmPerM;
  ray.direction = (level_ * (rotation_ * reflected)).normalized();
  return ray;
}

std::optional<double> RigModel::mirror_radius_mm(Lobe lobe, const Pixel &pixel) const {
  const std::optional<MirrorHit> h = hit(lobe, pixel);
  if (!h) return std::nullopt;
  return std::hypot(h->point_mm.x(), h->point_mm.y());
}

std::optional<Pixel> RigModel::mirror_edge_pixel(Lobe lobe, double radius_px, double phi_rad) const {
  const MirrorConfig &config = design_.config();
  const MirrorModel::LobeConstants &k = design_.constants(lobe);
  // The designed mirror point of that image radius (mirror.md sec. 2), in the mirror's pose.
  const double gamma = std::atan(radius_px * config.pixel_pitch_mm / config.focal_mm);
  const double distance_mm = k.b_mm * k.b_mm / (k.c_mm * std::cos(gamma - k.beta_rad) - k.a_mm);
  const double r_mm = distance_mm * std::sin(gamma);
  const Eigen::Vector3d design(r_mm * std::cos(phi_rad), r_mm * std::sin(phi_rad),
                               distance_mm * std::cos(gamma));
  const Eigen::Vector3d camera = rotation_ * (design - pivot_mm_) + pivot_mm_ + shift_mm_;
  if (!(camera.z() > 0.0)) return std::nullopt;
  return Pixel{config.center_u_px + focal_px_ * camera.x() / camera.z(),
               config.center_v_px + focal_px_ * camera.y() / camera.z()};
}

std::optional<Pixel> RigModel::project(Lobe lobe, const Eigen::Vector3d &point_m) const {
  if (!point_m.allFinite()) return std::nullopt;
  const MirrorConfig &config = design_.config();
  const MirrorModel::LobeConstants &k = design_.constants(lobe);
  // Start at the designed model's pixel (mirror.md sec. 4) of the point in the camera frame.
  const Eigen::Vector3d in_camera = level_.transpose() * point_m;
  const double range_mm = std::hypot(in_camera.x(), in_camera.y()) * kMmPerM;
  const double theta = std::atan2(range_mm - k.focus_r_mm, k.focus_z_mm - in_camera.z() * kMmPerM);
  const std::optional<double> radius_px = design_.radius_px_of_theta(lobe, theta);
  if (!radius_px) return std::nullopt;
  const double phi = std::atan2(in_camera.y(), in_camera.x());
  Eigen::Vector2d uv(config.center_u_px + *radius_px * std::cos(phi),
                     config.center_v_px + *radius_px * std::sin(phi));
  // Residual: the unit direction from the ray's origin to the point minus the ray's
  // direction (zero when the pixel's ray passes through the point; radians).
  const auto residual = [&](const Eigen::Vector2d &at) -> std::optional<Eigen::Vector3d> {
    const std::optional<Ray3> ray = back_project(lobe, {at.x(), at.y()});
    if (!ray) return std::nullopt;
    const Eigen::Vector3d to_point = point_m - ray->origin_m;
    if (!(to_point.dot(ray->direction) > 0.0)) return std::nullopt;
    return Eigen::Vector3d(to_point.normalized() - ray->direction);
  };
  for (int step = 0; step < kMaxGaussNewtonSteps; ++step) {
    const std::optional<Eigen::Vector3d> e = residual(uv);
    const std::optional<Eigen::Vector3d> e_u = residual(uv + Eigen::Vector2d(kJacobianStepPx, 0.0));
    const std::optional<Eigen::Vector3d> e_v = residual(uv + Eigen::Vector2d(0.0, kJacobianStepPx));
    if (!e || !e_u || !e_v) return std::nullopt;
    Eigen::Matrix<double, 3, 2> jacobian;
    jacobian.col(0) = (*e_u - *e) / kJacobianStepPx;
    jacobian.col(1) = (*e_v - *e) / kJacobianStepPx;
    const Eigen::Matrix2d normal = jacobian.transpose() * jacobian;
    if (!(std::abs(normal.determinant()) > 0.0)) return std::nullopt;
    const Eigen::Vector2d delta = normal.ldlt().solve(-jacobian.transpose() * *e);
    if (!delta.allFinite()) return std::nullopt;
    uv += delta;
    if (delta.norm() < kPixelTolPx) return Pixel{uv.x(), uv.y()};
  }
  return std::nullopt;
}

std::optional<RayIntersection> RigModel::intersect(const Ray3 &inner, const Ray3 &outer) {
  // Closest points o_i + s d_i and o_e + t d_e of two lines with unit directions.
  const Eigen::Vector3d w = inner.origin_m - outer.origin_m;
  const double b = inner.direction.dot(outer.direction);
  const double d = inner.direction.dot(w);
  const double e = outer.direction.dot(w);
  const double denominator = 1.0 - b * b;
  if (!(denominator > 1e-12)) return std::nullopt;
  const double s = (b * e - d) / denominator;
  const double t = (e - b * d) / denominator;
  if (!(s > 0.0 && t > 0.0)) return std::nullopt;
  const Eigen::Vector3d on_inner = inner.origin_m + s * inner.direction;
  const Eigen::Vector3d on_outer = outer.origin_m + t * outer.direction;
  return RayIntersection{(on_inner + on_outer) / 2.0, (on_inner - on_outer).norm()};
}

}  // namespace omnislam::mirror
