#pragma once
/// @file
/// A 2D grid in the map frame M, and the static occupancy map: loaded from a PGM + YAML pair
/// (ROS map_server convention) or rasterized from wall boxes (an SDF world's walls, extracted by
/// the twin or by apps/).

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "egress/hsr_interface/geometry.h"

namespace egress::perception {

/// Costs shared by every grid in perception (Nav2's convention).
inline constexpr std::uint8_t kFreeCost = 0;
inline constexpr std::uint8_t kInscribedCost = 253;  ///< Robot centre here touches an obstacle.
inline constexpr std::uint8_t kLethalCost = 254;     ///< An obstacle.
inline constexpr std::uint8_t kUnknownCost = 255;

/// Cell (ix, iy) covers [origin + (ix, iy) * resolution, + resolution) in M; row-major storage
/// with iy as the row. The grid is axis-aligned with M.
struct GridGeometry {
  double resolution{0.05};                          ///< Cell size [m], > 0.
  Eigen::Vector2d origin{Eigen::Vector2d::Zero()};  ///< Corner of cell (0, 0) in M [m].
  int width{0};
  int height{0};

  bool Contains(int ix, int iy) const { return ix >= 0 && iy >= 0 && ix < width && iy < height; }
  /// The cell holding p_MQ, or nullopt outside the grid.
  std::optional<Eigen::Vector2i> CellOf(const Eigen::Vector2d& p_MQ) const;
  Eigen::Vector2d CellCenter(int ix, int iy) const {
    return origin + Eigen::Vector2d((ix + 0.5) * resolution, (iy + 0.5) * resolution);
  }
  std::size_t Index(int ix, int iy) const {
    return std::size_t(iy) * std::size_t(width) + std::size_t(ix);
  }
  std::size_t size() const { return std::size_t(width) * std::size_t(height); }
  /// @throws InvalidArgument naming the field.
  void Validate() const;
};

/// An oriented box in the plane (a wall, a table): centre, yaw, full size [m].
struct Box2 {
  Pose2 X_MBox;
  Eigen::Vector2d size{Eigen::Vector2d::Zero()};
};

/// Static occupancy: kLethalCost (occupied), kFreeCost or kUnknownCost per cell.
class OccupancyGrid {
 public:
  OccupancyGrid() = default;
  OccupancyGrid(GridGeometry geometry, std::uint8_t fill);

  /// Loads a map_server YAML (image, resolution, origin [x, y, yaw], negate, occupied_thresh,
  /// free_thresh; mode trinary). The image path is relative to the YAML file. Origin yaw must be
  /// 0. @throws LoadError naming the file, line and field.
  /// `max_cells` bounds the image, checked on its header before it is decoded (a small PNG
  /// can decode to gigabytes).
  static OccupancyGrid LoadMapServerYaml(const std::filesystem::path& yaml_path,
                                         std::int64_t max_cells = kMaxMapImageCells);
  /// The most cells a map image may have unless a caller says otherwise (64 M: 400 m x 400 m
  /// at 5 cm).
  static constexpr std::int64_t kMaxMapImageCells = 64'000'000;
  /// Decodes a map image (PGM P2/P5 or PNG) to 8-bit gray after reading its width and height
  /// from the header alone. `what` names it in errors. @throws LoadError for another format, a
  /// malformed header, more than `max_cells` cells or undecodable bytes.
  static cv::Mat DecodeMapImage(std::string_view bytes, std::int64_t max_cells,
                                std::string_view what);
  /// A map_server image (8-bit gray, row 0 at the top) with its YAML parameters: dark cells
  /// (occupancy > occupied_thresh) are occupied, light ones (< free_thresh) free, the rest
  /// unknown. @throws InvalidArgument for an empty image or bad parameters.
  static OccupancyGrid FromImage(const cv::Mat& gray, double resolution,
                                 const Eigen::Vector2d& origin, bool negate = false,
                                 double occupied_thresh = 0.65, double free_thresh = 0.196);
  /// A free grid covering `bounds_min`..`bounds_max` with every box rasterized as occupied.
  static OccupancyGrid FromBoxes(const std::vector<Box2>& boxes, const Eigen::Vector2d& bounds_min,
                                 const Eigen::Vector2d& bounds_max, double resolution);

  const GridGeometry& geometry() const { return geometry_; }
  std::uint8_t at(int ix, int iy) const { return cells_[geometry_.Index(ix, iy)]; }
  std::uint8_t& at(int ix, int iy) { return cells_[geometry_.Index(ix, iy)]; }
  const std::vector<std::uint8_t>& cells() const { return cells_; }
  bool IsOccupied(const Eigen::Vector2d& p_MQ) const;
  /// Marks every cell whose centre lies inside `box` as occupied.
  void AddBox(const Box2& box);

 private:
  GridGeometry geometry_;
  std::vector<std::uint8_t> cells_;
};

/// Distance [m] along the ray from p_MO at angle `angle` (in M) to the first occupied cell,
/// or nullopt when nothing is hit within max_range. Steps at a quarter cell.
std::optional<double> RayCast(const OccupancyGrid& grid, const Eigen::Vector2d& p_MO, double angle,
                              double max_range);

}  // namespace egress::perception
