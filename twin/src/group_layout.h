#pragma once
/// @file
/// Where the members of a group (a PersonSpec with `count` > 1) stand when a run starts.
///
/// A group of `count` stands in a square grid around its start: `columns` = ceil(sqrt(count))
/// places a row, `spacing` apart, member k in column k % columns and row k / columns, the grid's
/// first row and column (columns - 1) / 2 places before the start (the layout TwinWorld has always
/// used). A building does not always leave room for it: a group of 12 put 1.75 m from a wall of a
/// building turned 23° had one member's place 0.2 m beyond that wall, outside the building,
/// where they stood to the time limit, "left behind". So a member whose grid place is unfit —
/// it lies beyond a wall, furniture or a doorway's line, i.e. no chain of grid steps from the
/// start reaches it without crossing one, or their body would stand in a doorway or on the
/// robot — stands instead at the nearest fit place of the same grid, extended around it, that is
/// no other member's grid place. A group whose every place is fit stands as it always has.
/// Everything in W [m].

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "egress/twin/social_force.h"

namespace egress::twin::world_detail {

/// Grid places searched around the group's own grid, on every side, for members whose place is
/// unfit: at the 0.99 m of a mixed group, 6 m.
constexpr int kGroupLayoutExtraRings = 6;

class GroupLayout {
 public:
  /// A group around `p_WS` whose member k has the grid place `grid_places[k]` (as the caller
  /// has always computed them, to the bit: the grid's own places are used as given), the grid
  /// `spacing` (> 0) apart. No place may lie beyond `barriers` (walls, furniture) or `keep_off`
  /// from the start; a body may touch `barriers` at its own grid place, never `keep_off` (a
  /// doorway's line, the robot).
  GroupLayout(const Eigen::Vector2d& p_WS, const std::vector<Eigen::Vector2d>& grid_places,
              double spacing, const std::vector<WallSegment>& barriers,
              const std::vector<WallSegment>& keep_off = {});

  /// Places a row of a group of `count`: ceil(sqrt(count)).
  static int Columns(int count);
  /// Member k's grid place relative to the group's start, in units of the grid's spacing.
  static Eigen::Vector2d GridUnit(int k, int count);

  /// Member k's place (0 ≤ k < count), for a body of `radius`: its grid place if that is fit
  /// (reached, not in a barrier, clear of keep_off by `radius`) and not taken, else the nearest
  /// place that clears both by `radius`, is no member's grid place and is not taken (ties: row,
  /// then column). The place is then taken. nullopt when none is left within
  /// kGroupLayoutExtraRings.
  std::optional<Eigen::Vector2d> Place(int k, double radius);

 private:
  struct Node {
    int i{0}, j{0};         // column, row (may lie outside the group's own grid)
    Eigen::Vector2d p_W;    // [m]
    double clearance{0.0};  // to the nearest barrier [m]
    double keep_off{0.0};   // to the nearest keep_off segment [m]
    bool reached{false};    // from the start without crossing a barrier
    bool taken{false};
    bool someones_grid_place{false};
  };
  Node& At(int i, int j) { return nodes_[std::size_t((j - lo_) * side_ + (i - lo_))]; }

  Eigen::Vector2d p_WS_;
  int columns_{1};
  int count_{1};
  int lo_{0};    // the lowest column and row index searched
  int side_{1};  // columns (and rows) searched
  std::vector<Node> nodes_;
};

}  // namespace egress::twin::world_detail
