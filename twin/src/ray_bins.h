#pragma once
/// @file
/// RayBins: a uniform grid over the ground plane (x, y in W) that tells a ray cast which boxes it
/// may cross, so that a cast tests a handful of the twin's ray targets instead of all of them
/// (a hundred evacuees are a hundred targets). A superset, never a miss: every box whose XY
/// extent the segment's XY projection touches is returned.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
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

  /// The boxes the segment a-b (XY in W) may cross, cell by cell from a towards b (Amanatides &
  /// Woo's grid walk), each once: a ray cast tests them in that order and stops once its closest
  /// hit lies before every cell still to come. Walks interleaved on one thread still miss
  /// nothing, but may yield a box twice (the marks of what was yielded are per thread).
  class Walk {
   public:
    Walk(const RayBins& bins, const Eigen::Vector2d& a, const Eigen::Vector2d& b);
    /// The boxes of the next cell(s) not yielded before (the unbinned ones first), and
    /// `t_beyond`: no box still to come touches the segment before a + t_beyond (b - a).
    /// False when the walk is over.
    bool Next(std::vector<int>* boxes, double* t_beyond);

   private:
    void Add(long x, long y, std::vector<int>* out) const;
    enum class Phase { kStart, kWalking, kDone };
    const RayBins& bins_;
    std::uint32_t walk_{0};
    Phase phase_{Phase::kStart};
    bool gridded_{false};
    double t0_{0.0}, t1_{1.0};  // the segment's piece inside the grid, in t on a-b
    long x_{0}, y_{0}, x_end_{0}, y_end_{0}, step_x_{0}, step_y_{0}, left_{0};
    double t_x_{0.0}, t_y_{0.0}, dt_x_{0.0}, dt_y_{0.0};  // in t on the piece inside
  };

 private:
  // By the reciprocal (a walk's set-up finds four cells): exact for a cell of a power of two
  // metres, as kRayBinCellM is, and the same function bins and walks whatever the cell.
  long CellX(double x) const {
    return std::clamp(long(std::floor((x - origin_.x()) * per_metre_)), 0L, nx_ - 1);
  }
  long CellY(double y) const {
    return std::clamp(long(std::floor((y - origin_.y()) * per_metre_)), 0L, ny_ - 1);
  }

  std::size_t box_count_{0};
  double cell_{1.0};
  double per_metre_{1.0};  // 1 / cell_
  Eigen::Vector2d origin_{Eigen::Vector2d::Zero()};
  long nx_{0}, ny_{0};
  std::vector<std::vector<int>> bins_;  // row-major, nx_ * ny_
  std::vector<int> everywhere_;
};

}  // namespace egress::twin::world_detail
