#pragma once
/// @file
/// Names of the frames egress exchanges data in. Link names follow the HSR-B URDF, so data
/// from the real robot's topics and from the twin carry the same frame ids.

#include <string_view>

namespace egress::frames {

inline constexpr std::string_view kMap = "map";                       ///< M: the static map.
inline constexpr std::string_view kOdom = "odom";                     ///< O: wheel odometry.
inline constexpr std::string_view kBase = "base_footprint";           ///< B: base on the floor.
inline constexpr std::string_view kLaser = "base_range_sensor_link";  ///< L: planar laser.
/// C: head RGB-D camera, optical convention (z forward, x right, y down).
inline constexpr std::string_view kHeadCamera = "head_rgbd_sensor_link";
inline constexpr std::string_view kPalm = "hand_palm_link";  ///< G: palm; +z is the approach.

}  // namespace egress::frames
