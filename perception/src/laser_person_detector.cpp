#include "egress/perception/laser_person_detector.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include <Eigen/Dense>

#include "egress/hsr_interface/error.h"
#include "egress/perception/door_estimation.h"

namespace egress::perception {
namespace {

// A circle seen from outside shows its near half; the centroid of that arc lies this fraction of
// the radius short of the centre, towards the laser (2/pi for a half circle).
constexpr double kArcCentroidOffset = 0.64;

struct Circle {
  Eigen::Vector2d centre;
  double radius;
  double residual;  // RMS distance of the points from it [m]
};

// Algebraic (Kasa) least-squares circle through the points, or nullopt when they are
// (nearly) collinear.
std::optional<Circle> FitCircle(const std::vector<Eigen::Vector2d>& points) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points)
    mean += p;
  mean /= double(points.size());
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (const auto& p : points) {
    const Eigen::Vector2d q = p - mean;
    const Eigen::Vector3d row(q.x(), q.y(), 1.0);
    normal += row * row.transpose();
    rhs -= row * q.squaredNorm();
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(normal);
  if (ldlt.info() != Eigen::Success || std::abs(normal.determinant()) < 1e-12) return std::nullopt;
  const Eigen::Vector3d s = ldlt.solve(rhs);
  const Eigen::Vector2d centre(-s.x() / 2, -s.y() / 2);
  const double r2 = centre.squaredNorm() - s.z();
  if (!std::isfinite(r2) || r2 <= 0.0) return std::nullopt;
  const double radius = std::sqrt(r2);
  double squares = 0.0;
  for (const auto& p : points) {
    const double off = (p - mean - centre).norm() - radius;
    squares += off * off;
  }
  return Circle{centre + mean, radius, std::sqrt(squares / double(points.size()))};
}

}  // namespace

void LaserPersonDetectorConfig::Validate() const {
  const auto positive = [](double v, const char* field) {
    ThrowUnless(std::isfinite(v) && v > 0.0,
                StrCat("LaserPersonDetectorConfig: ", field, " must be finite and > 0"));
  };
  positive(cluster_gap, "cluster_gap");
  positive(leg_min_width, "leg_min_width");
  positive(leg_pair_max_gap, "leg_pair_max_gap");
  positive(body_min_radius, "body_min_radius");
  positive(body_max_residual, "body_max_residual");
  positive(max_range, "max_range");
  ThrowUnless(min_points >= 2, "LaserPersonDetectorConfig: min_points must be >= 2");
  ThrowUnless(leg_min_width < leg_max_width && leg_max_width < body_max_width,
              "LaserPersonDetectorConfig: need leg_min_width < leg_max_width < body_max_width");
  ThrowUnless(std::isfinite(body_max_radius) && body_min_radius < body_max_radius,
              "LaserPersonDetectorConfig: need body_min_radius < body_max_radius");
}

LaserPersonDetector::LaserPersonDetector(LaserPersonDetectorConfig config)
    : config_(std::move(config)) {
  config_.Validate();
}

std::vector<LaserPersonDetection> LaserPersonDetector::Detect(
    const LaserScan& scan, const Pose2& X_ML,
    const std::function<bool(const Eigen::Vector2d&)>& is_background,
    const std::function<bool(const std::vector<Eigen::Vector2d>&)>& is_structure) const {
  scan.Validate();
  ThrowUnless(X_ML.IsFinite(), "LaserPersonDetector: the laser pose X_ML must be finite");
  const Eigen::Vector2d p_ML = X_ML.translation();
  const Eigen::Matrix2d R_ML = X_ML.rotation();
  const std::vector<Eigen::Vector2d>& u_L = BeamDirections(scan);

  // Clusters of returns off the map on neighbouring beams, closer than cluster_gap in turn. A
  // cluster on the scan's first or last beam may go on past the field of view's edge (unless the
  // scan goes all round).
  const std::size_t n = scan.ranges.size();
  const bool has_edges = double(n) * scan.angle_increment < 2 * std::numbers::pi - 1e-9;
  struct Cluster {
    std::vector<Eigen::Vector2d> points;
    bool at_edge{false};
  };
  std::vector<Cluster> clusters;
  Cluster current;
  std::size_t last_beam = 0;
  const auto close_cluster = [&] {
    if (int(current.points.size()) >= config_.min_points) {
      current.at_edge = current.at_edge || (has_edges && last_beam + 1 == n);
      clusters.push_back(current);
    }
    current = {};
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (!scan.IsValidReturn(i) || scan.ranges[i] > config_.max_range) continue;
    const Eigen::Vector2d p_M = R_ML * (scan.ranges[i] * u_L[i]) + p_ML;
    if (is_background && is_background(p_M)) continue;
    if (!current.points.empty() &&
        (i != last_beam + 1 || (p_M - current.points.back()).norm() > config_.cluster_gap)) {
      close_cluster();
    }
    if (current.points.empty()) current.at_edge = has_edges && i == 0;
    current.points.push_back(p_M);
    last_beam = i;
  }
  close_cluster();

  std::vector<LaserPersonDetection> people;
  std::vector<LaserPersonDetection> legs;
  for (const auto& [points, at_edge] : clusters) {
    const double width = (points.back() - points.front()).norm();
    if (width < config_.leg_min_width || width > config_.body_max_width) continue;
    if (is_structure && is_structure(points)) continue;
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
    for (const auto& p : points)
      centroid += p;
    centroid /= double(points.size());
    const Eigen::Vector2d away = (centroid - p_ML).normalized();  // from the laser, through it
    if (width <= config_.leg_max_width) {
      // Leg-wide at the field of view's edge may be the edge of a wider body (a wheelchair user
      // beside and behind the robot), whose centre is a body's radius further on: marked, for
      // the tracker to weigh (FusedPersonTrackerConfig::edge_gate).
      const double radius = width / 2;
      legs.push_back(
          {centroid + away * kArcCentroidOffset * radius, radius, 1, int(points.size()), at_edge});
      continue;
    }
    // A body section: an arc whose circle's centre lies beyond it, seen from the laser. A
    // straight run of returns (a cabinet's face) or a box's corner (S7's phantom person beside
    // the robot, "entering" the door zone) fits no such circle and is not a person.
    const std::optional<Circle> circle = points.size() >= 5 ? FitCircle(points) : std::nullopt;
    if (!circle || circle->radius < config_.body_min_radius ||
        circle->radius > config_.body_max_radius || circle->residual > config_.body_max_residual ||
        (circle->centre - centroid).dot(away) <= 0.0)
      continue;
    people.push_back({circle->centre, circle->radius, 0, int(points.size())});
  }

  // Legs a stride apart at most are one person's: closest pairs first.
  std::vector<bool> paired(legs.size(), false);
  while (true) {
    double best = config_.leg_pair_max_gap;
    std::size_t a = legs.size(), b = legs.size();
    for (std::size_t i = 0; i < legs.size(); ++i) {
      for (std::size_t j = i + 1; j < legs.size(); ++j) {
        if (paired[i] || paired[j]) continue;
        const double d = (legs[i].p_MP - legs[j].p_MP).norm();
        if (d <= best) {
          best = d;
          a = i;
          b = j;
        }
      }
    }
    if (a == legs.size()) break;
    paired[a] = paired[b] = true;
    people.push_back({(legs[a].p_MP + legs[b].p_MP) / 2,
                      best / 2 + std::max(legs[a].radius, legs[b].radius), 2,
                      legs[a].points + legs[b].points, legs[a].at_edge || legs[b].at_edge});
  }
  for (std::size_t i = 0; i < legs.size(); ++i) {
    if (!paired[i]) people.push_back(legs[i]);
  }
  return people;
}

}  // namespace egress::perception
