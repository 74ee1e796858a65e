#include "render.h"

#include <opencv2/imgproc.hpp>

namespace egress::apps {

using namespace perception;

cv::Point ToPixel(const GridGeometry& g, const Eigen::Vector2d& p) {
  return {int((p.x() - g.origin.x()) / g.resolution),
          g.height - 1 - int((p.y() - g.origin.y()) / g.resolution)};
}

cv::Mat RenderCostmap(const Costmap2D& costmap) {
  const cv::Mat costs = costmap.ToImage();
  cv::Mat image(costs.size(), CV_8UC3);
  for (int r = 0; r < costs.rows; ++r) {
    for (int c = 0; c < costs.cols; ++c) {
      const std::uint8_t cost = costs.at<std::uint8_t>(r, c);
      cv::Vec3b color;
      if (cost == kUnknownCost) {
        color = {160, 90, 40};
      } else if (cost == kLethalCost) {
        color = {0, 0, 0};
      } else if (cost == kInscribedCost) {
        color = {60, 60, 60};
      } else {
        const auto v = static_cast<std::uint8_t>(255 - cost * 150 / 252);
        color = {v, v, v};
      }
      image.at<cv::Vec3b>(r, c) = color;
    }
  }
  for (const auto& [id, doorway] : costmap.doorways()) {
    cv::line(image, ToPixel(costmap.geometry(), doorway.p_MHinge),
             ToPixel(costmap.geometry(), doorway.p_MLatch), cv::Scalar(60, 180, 60), 2);
  }
  return image;
}

void DrawPath(cv::Mat& image, const GridGeometry& grid, const std::vector<Pose2>& path) {
  for (std::size_t i = 1; i < path.size(); ++i) {
    cv::line(image, ToPixel(grid, path[i - 1].translation()), ToPixel(grid, path[i].translation()),
             cv::Scalar(40, 40, 220), 2, cv::LINE_AA);
  }
  if (!path.empty()) {
    cv::circle(image, ToPixel(grid, path.front().translation()), 4, cv::Scalar(60, 180, 60),
               cv::FILLED);
    cv::circle(image, ToPixel(grid, path.back().translation()), 4, cv::Scalar(200, 80, 20),
               cv::FILLED);
  }
}

}  // namespace egress::apps
