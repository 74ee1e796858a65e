#pragma once
/// @file
/// RayBins: a uniform grid over the ground plane (x, y in W) that tells a ray cast which boxes it
/// may cross, so that a cast tests a handful of the twin's ray targets instead of all of them
/// (a hundred evacuees are a hundred targets). A superset, never a miss: every box whose XY
/// extent the segment's XY projection touches is returned.

#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace egress::twin::world_detail {

/// The cell of the twin's ray bins [m]: about a person's width, so a short ray meets few.
constexpr double kRayBinCellM = 1.0;

class RayBins {
 public:
  /// Bins `boxes` (XY lower and upper corners in W) in square cells of `cell` [m]. A box that is
  /// not finite or spans more than kMaxCellsPerBox cells (a ground plane) is returned by every
  /// query.
  void Build(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& boxes, double cell);

  /// The indices of the boxes the segment a-b (XY in W) may cross, ascending, each once.
  void Query(const Eigen::Vector2d& a, const Eigen::Vector2d& b, std::vector<int>* out) const;

  static constexpr long kMaxCellsPerBox = 4096;

 private:
  // Appends the boxes of every cell the segment a-b crosses (a grid walk).
  void WalkCells(const Eigen::Vector2d& a, const Eigen::Vector2d& b, std::vector<int>* out) const;
  long CellX(double x) const;
  long CellY(double y) const;

  double cell_{1.0};
  Eigen::Vector2d origin_{Eigen::Vector2d::Zero()};
  long nx_{0}, ny_{0};
  std::vector<std::vector<int>> bins_;  // row-major, nx_ * ny_
  std::vector<int> everywhere_;
};

}  // namespace egress::twin::world_detail
