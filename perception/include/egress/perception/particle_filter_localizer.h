#pragma once
/// @file
/// ParticleFilterLocalizer: AMCL-style Monte Carlo localization of the base on the static map.
/// Motion model: the omnidirectional odometry model (AMCL's "omni"): each increment is a
/// translation along its bearing, a strafe across it and a rotation, each with Gaussian noise
/// growing with the translation and rotation of the increment. Measurement model: likelihood field
/// (distance from each beam endpoint to the nearest occupied cell, Gaussian with sigma_hit, mixed
/// with a uniform term). Resampling: low-variance, when the effective sample size falls below a
/// fraction of N. Deterministic for a given seed.

#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/sensor_types.h"
#include "egress/perception/occupancy_grid.h"

namespace egress::perception {

struct LocalizerConfig {
  int num_particles{500};
  /// Odometry noise (variance per squared motion): rotation from rotation, rotation from
  /// translation, translation from translation, translation from rotation, strafe from
  /// translation.
  double alpha_rot_rot{0.05};
  double alpha_rot_trans{0.02};
  /// 0.01: a 10 % s.d. per increment. With 0.05 (22 %) the cloud spread along a corridor, where
  /// the scan hardly fixes the position along it, faster than the scan could pull it back: the
  /// estimate wandered 1-3 m behind the robot over 15 m of the clinic's corridor.
  double alpha_trans_trans{0.01};
  double alpha_trans_rot{0.02};
  double alpha_strafe_trans{0.02};
  double sigma_hit{0.08};  ///< Std. dev. of the likelihood field [m].
  double z_hit{0.9};       ///< Weight of the hit term; the rest is uniform.
  int max_beams{60};       ///< Beams used per scan (evenly spread).
  /// Fewer usable beams than this and the correction is skipped (odometry carries the pose):
  /// a handful of returns (open ground beyond an exit, with an unmapped leaf or a person in
  /// view) pulls the estimate onto whatever they hit.
  int min_beams{12};
  double laser_max_range{20.0};      ///< Returns beyond this are ignored [m].
  double resample_threshold{0.5};    ///< Resample when N_eff < threshold * N.
  double update_min_distance{0.02};  ///< Skip a correction unless the base moved this far [m]…
  double update_min_angle{0.02};     ///< …or turned this much [rad].
  /// While the base moves, corrections are spaced wider: once it has moved this far [m] or
  /// turned this much [rad] since the last (AMCL's update_min_d and update_min_a; Nav2's
  /// defaults are 0.25 m and 0.2 rad). A scan that finds the base at rest (it moved less than
  /// 1 mm and 1 mrad since the previous scan) gets the correction at update_min_distance and
  /// update_min_angle, so precise acts, which start from rest, start from a fresh fix. A
  /// correction weighs every particle against the scan: at every scan while driving it was
  /// a tenth of a 100-resident crowd run's time.
  double moving_update_distance{0.1};
  double moving_update_angle{0.1};
  /// Relocalization after a kidnap (the base pushed, or its wheels slipping, without odometry
  /// knowing): the cloud, a few centimetres wide, cannot reach a pose decimetres away, and a
  /// standing base does not correct at all. When fewer than `recover_below` of the usable beams
  /// end within `fit_distance` of the map's obstacles at the estimate, poses on a grid around it
  /// (±`recover_window`, ±`recover_window_yaw`, refined once at a quarter of the steps) are
  /// scored; if the best of them fits `recover_gain` more of the beams, the cloud is spread
  /// anew there. Checked at every correction and, standing, every `recover_check_scans`
  /// scans; searched at most once per `recover_check_scans` scans. 0 disables it.
  double recover_below{0.6};
  double fit_distance{0.1};        ///< [m]
  double recover_gain{0.25};       ///< fraction of the usable beams
  double recover_window{0.5};      ///< [m]
  double recover_window_yaw{0.2};  ///< [rad]
  double recover_step{0.1};        ///< [m]
  double recover_step_yaw{0.05};   ///< [rad]
  int recover_check_scans{10};
  /// Searched only when at least this fraction of the beams considered have a usable return.
  /// Out in the open (past an exit) the few returns left lie on one far wall: a pose decimetres
  /// along it, turned a little, fits them as well as the true one (the clinic's exit: a jump of
  /// 0.35 m from an estimate 1 cm off, on 15 returns of 180).
  double recover_min_returns{0.3};
  /// Drift: the estimate decimetres off along a corridor, where the side walls fit either way
  /// (two wards: 0.25 m behind after 9 m east, the end wall's returns read as someone standing
  /// in the way). Too many beams still fit for the check above, and the cloud, a few
  /// centimetres wide, creeps towards the truth by no more than its width per correction (a
  /// standing base not at all). When fewer than `drift_check_below` of the usable beams fit, the
  /// same search runs, and a pose that fits `drift_gain` more of the beams while losing no more
  /// than `drift_loss` of those that fit at the estimate is taken: what fitted still fits, and a
  /// wall that did not fit now does. People in view fit no wall at any pose nearby. 0 disables it.
  double drift_check_below{0.9};
  double drift_gain{0.08};  ///< fraction of the usable beams
  double drift_loss{0.02};  ///< fraction of the usable beams
  std::uint64_t seed{1};
  void Validate() const;
};

class ParticleFilterLocalizer {
 public:
  /// `X_BL` is the laser's pose in the base frame.
  ParticleFilterLocalizer(const OccupancyGrid& map, const Pose2& X_BL, LocalizerConfig config = {});

  /// Spreads the particles as a Gaussian around X_MB with the given (x, y, yaw) covariance.
  /// @throws InvalidArgument for a non-finite pose or a covariance that is not PSD.
  void Initialize(const Pose2& X_MB, const Eigen::Matrix3d& covariance);
  /// Moves the particles by the odometry increment from X_OB_previous to X_OB_current.
  void Predict(const Pose2& X_OB_previous, const Pose2& X_OB_current);
  /// Weighs the particles by the scan and resamples if needed. Returns false when skipped
  /// (not moved enough since the last correction, or no usable beam).
  bool Correct(const LaserScan& scan);
  /// Convenience for one cycle: Predict from the last odometry seen, then Correct.
  void Update(const Pose2& X_OB, const LaserScan& scan);

  /// Weighted mean pose (circular mean for yaw).
  Pose2 Estimate() const;
  /// Weighted covariance of (x, y, yaw) [m², rad²].
  Eigen::Matrix3d Covariance() const;
  bool initialized() const { return !particles_.empty(); }
  int resample_count() const { return resample_count_; }
  /// How often the cloud was spread anew at a pose that fits the scan better (relocalized).
  int recover_count() const { return recover_count_; }
  /// The last relocalization's jump of the estimate (zero before any) [m, rad].
  const Pose2& last_recovery() const { return last_recovery_; }

 private:
  struct Particle {
    Pose2 X_MB;
    double weight;
  };
  double LikelihoodFieldDistance(const Eigen::Vector2d& p_MQ) const;
  /// log(z_hit·exp(−d²/2σ²) + (1 − z_hit)/range_max) of the beam end point's distance d
  /// (an end point off the map: the uniform part only), from a table.
  double BeamLogLikelihood(double d) const;
  void Resample();
  // The beam end points in L of the usable returns; empty if fewer than min_beams. `considered`:
  // how many beams were looked at.
  std::vector<Eigen::Vector2d> UsableBeams(const LaserScan& scan, std::size_t* considered) const;
  struct Fit {
    double log_likelihood;  // summed over the beams
    int inliers;            // beams ending within fit_distance of an obstacle
  };
  // `to_beat`: a search's best so far. Once the beams left cannot lift the sum above it, even
  // all ending on a surface, the rest is not summed and the fit's log_likelihood is -inf (the
  // relocalization search scores ~1800 poses; most fall short after a fraction of the beams).
  Fit CalcFit(const Pose2& X_MB, const std::vector<Eigen::Vector2d>& beams,
              double to_beat = -std::numeric_limits<double>::infinity()) const;
  static constexpr std::size_t kBoundEveryBeams = 8;
  static constexpr double kBoundMargin = 1e-6;
  // How many beams end within fit_distance of an obstacle at `from` but not at `to`.
  int CountLostInliers(const Pose2& from, const Pose2& to,
                       const std::vector<Eigen::Vector2d>& beams) const;
  // The relocalization check (see LocalizerConfig::recover_below). True if it spread the cloud.
  bool MaybeRecover(const std::vector<Eigen::Vector2d>& beams, std::size_t considered);
  Pose2 CalcEstimate() const;
  // Empties the cached Estimate and Covariance: the particles moved or were reweighed.
  void ForgetSummary();

  LocalizerConfig config_;
  GridGeometry geometry_;
  // To the nearest occupied cell [m], per cell, with a border of one cell round the grid that
  // repeats its edge: the bilinear lookup reads its four cells without clamping their indices.
  std::vector<float> distance_;
  int distance_stride_{0};  // cells per row of distance_ (the grid's width + 2)
  // BeamLogLikelihood at d = i·kBeamTableStep, out to where the hit term no longer counts.
  static constexpr double kBeamTableStep = 0.0005;  // [m]
  std::vector<double> beam_log_likelihood_;
  Pose2 X_BL_;
  std::vector<Particle> particles_;
  std::mt19937_64 random_;
  std::optional<Pose2> last_odometry_;
  double moved_distance_{0.0};
  double moved_angle_{0.0};
  bool moved_since_correction_{true};
  int resample_count_{0};
  int recover_count_{0};
  Pose2 last_recovery_;
  int scans_since_search_{0};  // scans since the last relocalization search (or check, standing)
  // Estimate and Covariance of the particles as they are (the executive asks at its own rate,
  // 8x the scans'); emptied by whatever moves or reweighs a particle.
  mutable std::optional<Pose2> estimate_;
  mutable std::optional<Eigen::Matrix3d> covariance_;
};

}  // namespace egress::perception
