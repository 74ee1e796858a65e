#include "egress/perception/particle_filter_localizer.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include "egress/hsr_interface/error.h"
#include "egress/perception/door_estimation.h"

namespace egress::perception {
namespace {

// Less motion than this between two scans is the base at rest [m, rad]: 1 cm/s and 0.01 rad/s at
// the laser's 10 Hz, below any speed the base drives at.
constexpr double kAtRestTranslationM = 1e-3;
constexpr double kAtRestRotation = 1e-3;

// A beam's end point p_LQ in M, for the laser at X_ML (c, s: the cosine and sine of its yaw,
// computed once per pose).
Eigen::Vector2d BeamEndInM(const Pose2& X_ML, double c, double s, const Eigen::Vector2d& p_LQ) {
  return {X_ML.x + c * p_LQ.x() - s * p_LQ.y(), X_ML.y + s * p_LQ.x() + c * p_LQ.y()};
}

}  // namespace

void LocalizerConfig::Validate() const {
  ThrowUnless(num_particles >= 10, "Invalid LocalizerConfig: num_particles (", num_particles,
              ") must be >= 10.");
  ThrowUnless(alpha_rot_rot >= 0 && alpha_rot_trans >= 0 && alpha_trans_trans >= 0 &&
                  alpha_trans_rot >= 0 && alpha_strafe_trans >= 0,
              "Invalid LocalizerConfig: the alpha noise terms must be >= 0.");
  ThrowUnless(sigma_hit > 0.0, "Invalid LocalizerConfig: sigma_hit (", sigma_hit, ") must be > 0.");
  ThrowUnless(z_hit > 0.0 && z_hit <= 1.0, "Invalid LocalizerConfig: z_hit (", z_hit,
              ") must be in (0, 1].");
  ThrowUnless(update_min_distance >= 0.0 && update_min_angle >= 0.0 &&
                  moving_update_distance >= update_min_distance &&
                  moving_update_angle >= update_min_angle,
              "Invalid LocalizerConfig: update_min_distance (", update_min_distance,
              ") and update_min_angle (", update_min_angle,
              ") must be >= 0, moving_update_distance (", moving_update_distance,
              ") and moving_update_angle (", moving_update_angle, ") at least as large.");
  ThrowUnless(max_beams >= 1, "Invalid LocalizerConfig: max_beams must be >= 1.");
  ThrowUnless(min_beams >= 1 && min_beams <= max_beams, "Invalid LocalizerConfig: min_beams (",
              min_beams, ") must be in [1, max_beams].");
  ThrowUnless(resample_threshold > 0.0 && resample_threshold <= 1.0,
              "Invalid LocalizerConfig: resample_threshold must be in (0, 1].");
  ThrowUnless(recover_below >= 0.0 && recover_below <= 1.0,
              "Invalid LocalizerConfig: recover_below (", recover_below, ") must be in [0, 1].");
  ThrowUnless(drift_check_below >= 0.0 && drift_check_below <= 1.0,
              "Invalid LocalizerConfig: drift_check_below (", drift_check_below,
              ") must be in [0, 1].");
  if (drift_check_below > 0.0) {
    ThrowUnless(drift_gain > 0.0 && drift_gain <= 1.0, "Invalid LocalizerConfig: drift_gain (",
                drift_gain, ") must be in (0, 1].");
    ThrowUnless(drift_loss >= 0.0 && drift_loss <= 1.0, "Invalid LocalizerConfig: drift_loss (",
                drift_loss, ") must be in [0, 1].");
  }
  if (recover_below > 0.0 || drift_check_below > 0.0) {
    ThrowUnless(fit_distance > 0.0, "Invalid LocalizerConfig: fit_distance (", fit_distance,
                ") must be > 0.");
    ThrowUnless(recover_gain > 0.0 && recover_gain <= 1.0,
                "Invalid LocalizerConfig: recover_gain (", recover_gain, ") must be in (0, 1].");
    ThrowUnless(recover_step > 0.0 && recover_step_yaw > 0.0 && recover_window >= 0.0 &&
                    recover_window_yaw >= 0.0,
                "Invalid LocalizerConfig: recover_step and recover_step_yaw must be > 0, the "
                "recover windows >= 0.");
    ThrowUnless(
        recover_window / recover_step <= 20.0 && recover_window_yaw / recover_step_yaw <= 20.0,
        "Invalid LocalizerConfig: at most 20 recover steps each way (window / step).");
    ThrowUnless(recover_check_scans >= 1, "Invalid LocalizerConfig: recover_check_scans (",
                recover_check_scans, ") must be >= 1.");
    ThrowUnless(recover_min_returns >= 0.0 && recover_min_returns <= 1.0,
                "Invalid LocalizerConfig: recover_min_returns (", recover_min_returns,
                ") must be in [0, 1].");
  }
}

ParticleFilterLocalizer::ParticleFilterLocalizer(const OccupancyGrid& map, const Pose2& X_BL,
                                                 LocalizerConfig config)
    : config_(config), geometry_(map.geometry()), X_BL_(X_BL), random_(config.seed) {
  config_.Validate();
  ThrowUnless(X_BL.IsFinite(), "Invalid laser pose X_BL: must be finite.");
  cv::Mat free_mask(geometry_.height, geometry_.width, CV_8UC1);
  for (int iy = 0; iy < geometry_.height; ++iy) {
    for (int ix = 0; ix < geometry_.width; ++ix) {
      free_mask.at<std::uint8_t>(iy, ix) = map.at(ix, iy) == kLethalCost ? 0 : 255;
    }
  }
  cv::Mat distance;
  cv::distanceTransform(free_mask, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  // Inside an obstacle, the depth below its surface: the laser returns from the surface, and a
  // field of 0 through a wall's whole thickness let a pose put the end points anywhere in it
  // (a 0.1 m wall: the estimate up to 0.1 m off towards a wall seen from one side). An
  // occupied cell's value is its distance to the nearest free cell less one cell, so the
  // bilinear field (less half a cell, below) is 0 from the surface through the first cell and
  // grows beyond it.
  cv::Mat occupied_mask;
  cv::bitwise_not(free_mask, occupied_mask);
  cv::Mat depth;
  cv::distanceTransform(occupied_mask, depth, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  for (int iy = 0; iy < geometry_.height; ++iy) {
    for (int ix = 0; ix < geometry_.width; ++ix) {
      if (free_mask.at<std::uint8_t>(iy, ix) == 0)
        distance.at<float>(iy, ix) = std::max(0.0f, depth.at<float>(iy, ix) - 1.0f);
    }
  }
  distance_stride_ = geometry_.width + 2;
  distance_.resize(std::size_t(distance_stride_) * std::size_t(geometry_.height + 2));
  for (int iy = -1; iy <= geometry_.height; ++iy) {
    for (int ix = -1; ix <= geometry_.width; ++ix) {
      const int cx = std::clamp(ix, 0, geometry_.width - 1);
      const int cy = std::clamp(iy, 0, geometry_.height - 1);
      distance_[std::size_t((iy + 1) * distance_stride_ + ix + 1)] =
          distance.at<float>(cy, cx) * float(geometry_.resolution);
    }
  }
  // exp and log per beam per particle cost more than the rest of the correction; beyond
  // 8 sigma the hit term is negligible next to the uniform one.
  const double inv_2sigma2 = 1.0 / (2.0 * config_.sigma_hit * config_.sigma_hit);
  const double uniform = (1.0 - config_.z_hit) / config_.laser_max_range;
  const auto entries = std::size_t(std::ceil(8.0 * config_.sigma_hit / kBeamTableStep)) + 2;
  beam_log_likelihood_.resize(entries);
  for (std::size_t i = 0; i < entries; ++i) {
    const double d = double(i) * kBeamTableStep;
    beam_log_likelihood_[i] = std::log(config_.z_hit * std::exp(-d * d * inv_2sigma2) + uniform);
  }
}

double ParticleFilterLocalizer::BeamLogLikelihood(double d) const {
  if (!(d < double(beam_log_likelihood_.size() - 1) * kBeamTableStep))  // far, or off the map
    return beam_log_likelihood_.back();
  const double x = d / kBeamTableStep;
  const auto i = std::size_t(x);
  const double f = x - double(i);
  return (1.0 - f) * beam_log_likelihood_[i] + f * beam_log_likelihood_[i + 1];
}

void ParticleFilterLocalizer::Initialize(const Pose2& X_MB, const Eigen::Matrix3d& covariance) {
  ForgetSummary();
  ThrowUnless(X_MB.IsFinite(), "Invalid initial pose: must be finite.");
  ThrowUnless(
      covariance.allFinite() && (covariance - covariance.transpose()).cwiseAbs().maxCoeff() < 1e-12,
      "Invalid initial covariance: must be finite and symmetric.");
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  ThrowUnless(eigen.eigenvalues().minCoeff() >= 0.0,
              "Invalid initial covariance: must be positive semi-definite.");
  const Eigen::Matrix3d L = eigen.eigenvectors() * eigen.eigenvalues().cwiseSqrt().asDiagonal();
  std::normal_distribution<double> normal(0.0, 1.0);
  particles_.clear();
  for (int i = 0; i < config_.num_particles; ++i) {
    const Eigen::Vector3d z(normal(random_), normal(random_), normal(random_));
    const Eigen::Vector3d d = L * z;
    particles_.push_back({{X_MB.x + d.x(), X_MB.y + d.y(), WrapAngle(X_MB.yaw + d.z())},
                          1.0 / config_.num_particles});
  }
  moved_since_correction_ = true;
}

void ParticleFilterLocalizer::Predict(const Pose2& X_OB_previous, const Pose2& X_OB_current) {
  ForgetSummary();
  ThrowUnless(X_OB_previous.IsFinite() && X_OB_current.IsFinite(),
              "Invalid odometry: poses must be finite.");
  ThrowUnless(initialized(), "ParticleFilterLocalizer::Predict: call Initialize first.");
  const Eigen::Vector2d delta = X_OB_current.translation() - X_OB_previous.translation();
  const double translation = delta.norm();
  const double rotation = WrapAngle(X_OB_current.yaw - X_OB_previous.yaw);
  // Bearing of the translation relative to the base's previous heading.
  const double bearing =
      translation < 1e-9 ? 0.0 : WrapAngle(std::atan2(delta.y(), delta.x()) - X_OB_previous.yaw);
  moved_distance_ += translation;
  moved_angle_ += std::abs(rotation);
  const double t2 = translation * translation, r2 = rotation * rotation;
  constexpr double kMinStd = 1e-12;  // a normal distribution needs a positive deviation
  std::normal_distribution<double> trans_noise(
      0.0, kMinStd + std::sqrt(config_.alpha_trans_trans * t2 + config_.alpha_trans_rot * r2));
  std::normal_distribution<double> rot_noise(
      0.0, kMinStd + std::sqrt(config_.alpha_rot_rot * r2 + config_.alpha_rot_trans * t2));
  std::normal_distribution<double> strafe_noise(
      0.0, kMinStd + std::sqrt(config_.alpha_strafe_trans * t2 + config_.alpha_trans_rot * r2));
  const bool still = t2 + r2 == 0.0;
  for (Particle& p : particles_) {
    const double heading = p.X_MB.yaw + bearing;
    const double t = translation + (still ? 0.0 : trans_noise(random_));
    const double strafe = still ? 0.0 : strafe_noise(random_);
    const double r = rotation + (still ? 0.0 : rot_noise(random_));
    p.X_MB.x += t * std::cos(heading) - strafe * std::sin(heading);
    p.X_MB.y += t * std::sin(heading) + strafe * std::cos(heading);
    p.X_MB.yaw = WrapAngle(p.X_MB.yaw + r);
  }
  const bool at_rest = translation < kAtRestTranslationM && std::abs(rotation) < kAtRestRotation;
  const double min_distance =
      at_rest ? config_.update_min_distance : config_.moving_update_distance;
  const double min_angle = at_rest ? config_.update_min_angle : config_.moving_update_angle;
  if (moved_distance_ >= min_distance || moved_angle_ >= min_angle) moved_since_correction_ = true;
}

double ParticleFilterLocalizer::LikelihoodFieldDistance(const Eigen::Vector2d& p_MQ) const {
  // Bilinear between cell centres, less half a cell: the distance to an obstacle's surface, not
  // to its nearest cell centre. A per-cell step would favour poses that put the beam endpoints
  // inside the walls, and bias the estimate by up to half a cell towards them.
  const double res = geometry_.resolution;
  const double gx = (p_MQ.x() - geometry_.origin.x()) / res;
  const double gy = (p_MQ.y() - geometry_.origin.y()) / res;
  // Outside the grid (or not finite: every comparison fails).
  if (!(gx >= 0.0 && gy >= 0.0 && gx < geometry_.width && gy < geometry_.height))
    return std::numeric_limits<double>::infinity();
  const double u = gx - 0.5;
  const double v = gy - 0.5;
  const int i0 = int(std::floor(u)), j0 = int(std::floor(v));
  const double fu = u - i0, fv = v - j0;
  // i0, j0 >= -1 and i0 + 1 <= width, j0 + 1 <= height: within the border.
  const float* row = distance_.data() + std::ptrdiff_t(j0 + 1) * distance_stride_ + (i0 + 1);
  const float* next_row = row + distance_stride_;
  const double d = (1 - fu) * (1 - fv) * double(row[0]) + fu * (1 - fv) * double(row[1]) +
                   (1 - fu) * fv * double(next_row[0]) + fu * fv * double(next_row[1]);
  return std::max(0.0, d - 0.5 * res);
}

bool ParticleFilterLocalizer::Correct(const LaserScan& scan) {
  ForgetSummary();
  scan.Validate();
  ThrowUnless(initialized(), "ParticleFilterLocalizer::Correct: call Initialize first.");
  ++scans_since_search_;
  // Standing, nothing to correct — unless the robot was carried off (a kidnap): checked every
  // recover_check_scans scans, as nothing else would ever move the cloud.
  const bool checks = config_.recover_below > 0.0 || config_.drift_check_below > 0.0;
  if (!moved_since_correction_ && (!checks || scans_since_search_ < config_.recover_check_scans))
    return false;
  std::size_t considered = 0;
  const std::vector<Eigen::Vector2d> beams = UsableBeams(scan, &considered);
  if (beams.empty()) return false;
  if (!moved_since_correction_) {
    if (!MaybeRecover(beams, considered)) {
      scans_since_search_ = 0;
      return false;
    }
  } else if (checks && scans_since_search_ >= config_.recover_check_scans) {
    MaybeRecover(beams, considered);
  }
  std::vector<double> log_weights(particles_.size());
  for (std::size_t k = 0; k < particles_.size(); ++k) {
    log_weights[k] =
        std::log(particles_[k].weight) + CalcFit(particles_[k].X_MB, beams).log_likelihood;
  }
  const double max_log = *std::max_element(log_weights.begin(), log_weights.end());
  double total = 0.0;
  for (std::size_t k = 0; k < particles_.size(); ++k) {
    particles_[k].weight = std::exp(log_weights[k] - max_log);
    total += particles_[k].weight;
  }
  double sum_sq = 0.0;
  for (Particle& p : particles_) {
    p.weight /= total;
    sum_sq += p.weight * p.weight;
  }
  const double n_eff = 1.0 / sum_sq;
  if (n_eff < config_.resample_threshold * double(particles_.size())) Resample();
  moved_distance_ = moved_angle_ = 0.0;
  moved_since_correction_ = false;
  return true;
}

std::vector<Eigen::Vector2d> ParticleFilterLocalizer::UsableBeams(const LaserScan& scan,
                                                                  std::size_t* considered) const {
  std::vector<Eigen::Vector2d> beams;  // end points in L
  const std::vector<Eigen::Vector2d>& u_L = BeamDirections(scan);
  const std::size_t n = scan.ranges.size();
  const std::size_t step = std::max<std::size_t>(1, n / std::size_t(config_.max_beams));
  *considered = (n + step - 1) / step;
  for (std::size_t i = 0; i < n; i += step) {
    if (!scan.IsValidReturn(i) || scan.ranges[i] > config_.laser_max_range) continue;
    beams.emplace_back(scan.ranges[i] * u_L[i]);
  }
  if (beams.size() < std::size_t(config_.min_beams)) beams.clear();
  return beams;
}

ParticleFilterLocalizer::Fit ParticleFilterLocalizer::CalcFit(
    const Pose2& X_MB, const std::vector<Eigen::Vector2d>& beams, double to_beat) const {
  const Pose2 X_ML = X_MB * X_BL_;
  const double c = std::cos(X_ML.yaw), s = std::sin(X_ML.yaw);
  // No beam scores more than one ending on an obstacle's surface.
  const double best_beam = beam_log_likelihood_.front();
  Fit fit{0.0, 0};
  for (std::size_t i = 0; i < beams.size(); ++i) {
    const double d = LikelihoodFieldDistance(BeamEndInM(X_ML, c, s, beams[i]));
    fit.log_likelihood += BeamLogLikelihood(d);
    if (d <= config_.fit_distance) ++fit.inliers;
    // Checked every kBoundEveryBeams beams; the margin covers the rounding of the sum.
    if (i % kBoundEveryBeams == kBoundEveryBeams - 1 &&
        fit.log_likelihood + double(beams.size() - 1 - i) * best_beam < to_beat - kBoundMargin)
      return {-std::numeric_limits<double>::infinity(), fit.inliers};
  }
  return fit;
}

int ParticleFilterLocalizer::CountLostInliers(const Pose2& from, const Pose2& to,
                                              const std::vector<Eigen::Vector2d>& beams) const {
  const Pose2 X_ML_from = from * X_BL_, X_ML_to = to * X_BL_;
  const double c_from = std::cos(X_ML_from.yaw), s_from = std::sin(X_ML_from.yaw);
  const double c_to = std::cos(X_ML_to.yaw), s_to = std::sin(X_ML_to.yaw);
  int lost = 0;
  for (const Eigen::Vector2d& p_LQ : beams) {
    if (LikelihoodFieldDistance(BeamEndInM(X_ML_from, c_from, s_from, p_LQ)) <=
            config_.fit_distance &&
        LikelihoodFieldDistance(BeamEndInM(X_ML_to, c_to, s_to, p_LQ)) > config_.fit_distance)
      ++lost;
  }
  return lost;
}

bool ParticleFilterLocalizer::MaybeRecover(const std::vector<Eigen::Vector2d>& beams,
                                           std::size_t considered) {
  if (double(beams.size()) < config_.recover_min_returns * double(considered)) return false;
  const Pose2 estimate = Estimate();
  const Fit now = CalcFit(estimate, beams);
  const double n = double(beams.size());
  const bool kidnapped = double(now.inliers) < config_.recover_below * n;
  const bool drifted = double(now.inliers) < config_.drift_check_below * n;
  if (!kidnapped && !drifted) return false;
  scans_since_search_ = 0;
  // A coarse grid over the window, then a fine one (a quarter of the steps) round its best.
  // Ranked by likelihood (smooth in the pose); ties go to the nearer pose, by the loop order.
  Pose2 best = estimate;
  Fit best_fit = now;
  const auto search = [&](const Pose2& centre, double window, double window_yaw, double step,
                          double step_yaw) {
    const int k = int(std::floor(window / step + 1e-9));
    const int k_yaw = int(std::floor(window_yaw / step_yaw + 1e-9));
    for (int iyaw = 0; iyaw <= 2 * k_yaw; ++iyaw) {
      // 0, +1, -1, +2, -2, ...: the nearer offsets first.
      const int jyaw = (iyaw + 1) / 2 * (iyaw % 2 == 1 ? 1 : -1);
      for (int ix = 0; ix <= 2 * k; ++ix) {
        const int jx = (ix + 1) / 2 * (ix % 2 == 1 ? 1 : -1);
        for (int iy = 0; iy <= 2 * k; ++iy) {
          const int jy = (iy + 1) / 2 * (iy % 2 == 1 ? 1 : -1);
          const Pose2 X_MB{centre.x + jx * step, centre.y + jy * step,
                           WrapAngle(centre.yaw + jyaw * step_yaw)};
          const Fit fit = CalcFit(X_MB, beams, best_fit.log_likelihood);
          if (fit.log_likelihood > best_fit.log_likelihood) {
            best = X_MB;
            best_fit = fit;
          }
        }
      }
    }
  };
  search(estimate, config_.recover_window, config_.recover_window_yaw, config_.recover_step,
         config_.recover_step_yaw);
  search(best, config_.recover_step, config_.recover_step_yaw, config_.recover_step / 4.0,
         config_.recover_step_yaw / 4.0);
  const double gain = double(best_fit.inliers - now.inliers);
  const bool take = (kidnapped && gain >= config_.recover_gain * n) ||
                    (drifted && gain >= config_.drift_gain * n &&
                     double(CountLostInliers(estimate, best, beams)) <= config_.drift_loss * n);
  if (!take) return false;
  // Spread over what the fine grid cannot tell apart; the corrections that follow narrow it.
  const double sigma = config_.recover_step / 8.0, sigma_yaw = config_.recover_step_yaw / 8.0;
  Initialize(best,
             Eigen::Vector3d(sigma * sigma, sigma * sigma, sigma_yaw * sigma_yaw).asDiagonal());
  ++recover_count_;
  last_recovery_ = estimate.Inverse() * best;
  return true;
}

void ParticleFilterLocalizer::Resample() {
  ForgetSummary();
  // Low-variance (systematic) resampling.
  const std::size_t n = particles_.size();
  std::vector<Particle> resampled;
  resampled.reserve(n);
  const double step = 1.0 / double(n);
  double u = std::uniform_real_distribution<double>(0.0, step)(random_);
  double cumulative = particles_[0].weight;
  std::size_t i = 0;
  for (std::size_t m = 0; m < n; ++m) {
    while (u > cumulative && i + 1 < n)
      cumulative += particles_[++i].weight;
    resampled.push_back({particles_[i].X_MB, step});
    u += step;
  }
  particles_ = std::move(resampled);
  ++resample_count_;
}

void ParticleFilterLocalizer::Update(const Pose2& X_OB, const LaserScan& scan) {
  if (last_odometry_) Predict(*last_odometry_, X_OB);
  last_odometry_ = X_OB;
  Correct(scan);
}

void ParticleFilterLocalizer::ForgetSummary() {
  estimate_.reset();
  covariance_.reset();
}

Pose2 ParticleFilterLocalizer::Estimate() const {
  if (!estimate_) estimate_ = CalcEstimate();
  return *estimate_;
}

Pose2 ParticleFilterLocalizer::CalcEstimate() const {
  ThrowUnless(initialized(), "ParticleFilterLocalizer::Estimate: call Initialize first.");
  double x = 0, y = 0, c = 0, s = 0;
  for (const Particle& p : particles_) {
    x += p.weight * p.X_MB.x;
    y += p.weight * p.X_MB.y;
    c += p.weight * std::cos(p.X_MB.yaw);
    s += p.weight * std::sin(p.X_MB.yaw);
  }
  return {x, y, std::atan2(s, c)};
}

Eigen::Matrix3d ParticleFilterLocalizer::Covariance() const {
  if (covariance_) return *covariance_;
  const Pose2 mean = Estimate();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Particle& p : particles_) {
    const Eigen::Vector3d d(p.X_MB.x - mean.x, p.X_MB.y - mean.y, WrapAngle(p.X_MB.yaw - mean.yaw));
    covariance += p.weight * d * d.transpose();
  }
  covariance_ = covariance;
  return covariance;
}

}  // namespace egress::perception
