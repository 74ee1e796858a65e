#pragma once
// Pictures for the command line: the costmap as a colour image, with paths drawn over it.

#include <vector>

#include <opencv2/core.hpp>

#include "egress/hsr_interface/geometry.h"
#include "egress/perception/costmap.h"

namespace egress::apps {

/// Black lethal, dark gray inscribed, gray decaying cost, white free, blue unknown; doorway
/// lines in green. Row 0 is the map's top (highest y).
cv::Mat RenderCostmap(const perception::Costmap2D& costmap);
/// Pixel of a point in M on an image from RenderCostmap.
cv::Point ToPixel(const perception::GridGeometry& grid, const Eigen::Vector2d& p_M);
/// Draws a path (red), its start (green) and goal (blue) onto `image`.
void DrawPath(cv::Mat& image, const perception::GridGeometry& grid, const std::vector<Pose2>& path);

}  // namespace egress::apps
