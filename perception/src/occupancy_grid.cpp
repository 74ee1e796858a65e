#include "egress/perception/occupancy_grid.h"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/text_file.h"

namespace egress::perception {

std::optional<Eigen::Vector2i> GridGeometry::CellOf(const Eigen::Vector2d& p_MQ) const {
  if (!p_MQ.allFinite()) return std::nullopt;
  const Eigen::Vector2d local = (p_MQ - origin) / resolution;
  const int ix = static_cast<int>(std::floor(local.x()));
  const int iy = static_cast<int>(std::floor(local.y()));
  if (!Contains(ix, iy)) return std::nullopt;
  return Eigen::Vector2i(ix, iy);
}

void GridGeometry::Validate() const {
  ThrowUnless(std::isfinite(resolution) && resolution > 0.0, "Invalid grid: resolution (",
              resolution, ") must be > 0.");
  ThrowUnless(origin.allFinite(), "Invalid grid: origin must be finite.");
  ThrowUnless(width > 0 && height > 0, "Invalid grid: width (", width, ") and height (", height,
              ") must be > 0.");
}

OccupancyGrid::OccupancyGrid(GridGeometry geometry, std::uint8_t fill) : geometry_(geometry) {
  geometry_.Validate();
  cells_.assign(geometry_.size(), fill);
}

bool OccupancyGrid::IsOccupied(const Eigen::Vector2d& p_MQ) const {
  const auto cell = geometry_.CellOf(p_MQ);
  return cell && at(cell->x(), cell->y()) == kLethalCost;
}

void OccupancyGrid::AddBox(const Box2& box) {
  const Pose2 X_BoxM = box.X_MBox.Inverse();
  const Eigen::Vector2d half = box.size / 2.0;
  const double reach = half.norm();
  const Eigen::Vector2d c = box.X_MBox.translation();
  const auto lo = geometry_.CellOf(c - Eigen::Vector2d(reach, reach));
  const auto hi = geometry_.CellOf(c + Eigen::Vector2d(reach, reach));
  const int x0 = lo ? lo->x() : 0, y0 = lo ? lo->y() : 0;
  const int x1 = hi ? hi->x() : geometry_.width - 1, y1 = hi ? hi->y() : geometry_.height - 1;
  for (int iy = std::max(0, y0); iy <= std::min(geometry_.height - 1, y1); ++iy) {
    for (int ix = std::max(0, x0); ix <= std::min(geometry_.width - 1, x1); ++ix) {
      const Eigen::Vector2d p = X_BoxM * geometry_.CellCenter(ix, iy);
      if (std::abs(p.x()) <= half.x() && std::abs(p.y()) <= half.y()) at(ix, iy) = kLethalCost;
    }
  }
}

OccupancyGrid OccupancyGrid::FromBoxes(const std::vector<Box2>& boxes,
                                       const Eigen::Vector2d& bounds_min,
                                       const Eigen::Vector2d& bounds_max, double resolution) {
  ThrowUnless(bounds_min.allFinite() && bounds_max.allFinite() &&
                  (bounds_max - bounds_min).minCoeff() > 0.0,
              "Invalid map bounds: max must exceed min in x and y.");
  ThrowUnless(resolution > 0.0, "Invalid map: resolution (", resolution, ") must be > 0.");
  GridGeometry geometry;
  geometry.resolution = resolution;
  geometry.origin = bounds_min;
  geometry.width = static_cast<int>(std::ceil((bounds_max.x() - bounds_min.x()) / resolution));
  geometry.height = static_cast<int>(std::ceil((bounds_max.y() - bounds_min.y()) / resolution));
  OccupancyGrid grid(geometry, kFreeCost);
  for (const Box2& box : boxes)
    grid.AddBox(box);
  return grid;
}

namespace {

// The map_server YAML is flat "key: value" lines; read it without a YAML library (perception
// may use only hsr_interface, OpenCV and OctoMap), with line numbers for errors.
struct YamlField {
  std::string value;
  int line;
};

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

}  // namespace

OccupancyGrid OccupancyGrid::LoadMapServerYaml(const std::filesystem::path& yaml_path) {
  const std::string file = yaml_path.string();
  std::string text;
  try {
    text = ReadTextFile(yaml_path, "map YAML");
  } catch (const LoadError& e) {
    throw LoadError(StrCat("Cannot load map: ", e.what()));
  }
  std::istringstream in(text);
  std::map<std::string, YamlField> fields;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::string content = Trim(line.substr(0, line.find('#')));
    if (content.empty()) continue;
    const auto colon = content.find(':');
    if (colon == std::string::npos) {
      throw LoadError(StrCat(file, ":", number, ": expected 'key: value', found '", content, "'."));
    }
    std::string value = Trim(content.substr(colon + 1));
    if (value.size() >= 2 && (value.front() == '"' || value.front() == '\'') &&
        value.back() == value.front()) {
      value = value.substr(1, value.size() - 2);
    }
    fields[Trim(content.substr(0, colon))] = {value, number};
  }
  const auto require = [&](const char* key) -> const YamlField& {
    auto it = fields.find(key);
    if (it == fields.end())
      throw LoadError(StrCat(file, ": required field '", key, "' is missing."));
    return it->second;
  };
  const auto number = [&](const char* key, std::optional<double> fallback = std::nullopt) {
    auto it = fields.find(key);
    if (it == fields.end()) {
      if (fallback) return *fallback;
      require(key);
    }
    try {
      std::size_t used = 0;
      const double v = std::stod(it->second.value, &used);
      if (used != it->second.value.size() || !std::isfinite(v)) throw std::invalid_argument("");
      return v;
    } catch (const std::exception&) {
      throw LoadError(StrCat(file, ":", it->second.line, ": field '", key, "' (", it->second.value,
                             ") must be a number."));
    }
  };
  const YamlField& image_field = require("image");
  const double resolution = number("resolution");
  if (!(resolution > 0.0)) {
    throw LoadError(
        StrCat(file, ":", fields["resolution"].line, ": field 'resolution' must be > 0."));
  }
  const YamlField& origin_field = require("origin");
  std::vector<double> origin;
  {
    std::string text = origin_field.value;
    if (text.size() < 2 || text.front() != '[' || text.back() != ']') {
      throw LoadError(
          StrCat(file, ":", origin_field.line, ": field 'origin' must be [x, y, yaw]."));
    }
    std::stringstream parts(text.substr(1, text.size() - 2));
    std::string part;
    while (std::getline(parts, part, ',')) {
      try {
        origin.push_back(std::stod(Trim(part)));
      } catch (const std::exception&) {
        throw LoadError(StrCat(file, ":", origin_field.line, ": field 'origin' has a non-number '",
                               Trim(part), "'."));
      }
    }
    if (origin.size() != 3) {
      throw LoadError(StrCat(file, ":", origin_field.line,
                             ": field 'origin' must have 3 numbers [x, y, yaw]."));
    }
    if (std::abs(origin[2]) > 1e-9) {
      throw LoadError(StrCat(file, ":", origin_field.line, ": a rotated map origin (yaw ",
                             origin[2], ") is not supported; rotate the image instead."));
    }
  }
  const bool negate = number("negate", 0.0) != 0.0;
  const double occupied_thresh = number("occupied_thresh", 0.65);
  const double free_thresh = number("free_thresh", 0.196);
  if (auto mode = fields.find("mode"); mode != fields.end() && mode->second.value != "trinary") {
    throw LoadError(StrCat(file, ":", mode->second.line, ": mode '", mode->second.value,
                           "' is not supported (only trinary)."));
  }
  std::filesystem::path image_path = image_field.value;
  if (image_path.is_relative()) image_path = yaml_path.parent_path() / image_path;
  const cv::Mat image = cv::imread(image_path.string(), cv::IMREAD_GRAYSCALE);
  if (image.empty()) {
    throw LoadError(
        StrCat(file, ":", image_field.line, ": image '", image_path.string(), "' cannot be read."));
  }
  return FromImage(image, resolution, {origin[0], origin[1]}, negate, occupied_thresh, free_thresh);
}

OccupancyGrid OccupancyGrid::FromImage(const cv::Mat& gray, double resolution,
                                       const Eigen::Vector2d& origin, bool negate,
                                       double occupied_thresh, double free_thresh) {
  ThrowUnless(!gray.empty() && gray.type() == CV_8UC1,
              "Invalid map image: it must be a non-empty 8-bit gray image.");
  ThrowUnless(std::isfinite(resolution) && resolution > 0.0, "Invalid map: resolution (",
              resolution, ") must be > 0.");
  ThrowUnless(origin.allFinite(), "Invalid map: origin must be finite.");
  ThrowUnless(free_thresh >= 0.0 && occupied_thresh <= 1.0 && free_thresh < occupied_thresh,
              "Invalid map: thresholds must satisfy 0 <= free_thresh (", free_thresh,
              ") < occupied_thresh (", occupied_thresh, ") <= 1.");
  GridGeometry geometry;
  geometry.resolution = resolution;
  geometry.origin = origin;
  geometry.width = gray.cols;
  geometry.height = gray.rows;
  OccupancyGrid grid(geometry, kUnknownCost);
  for (int row = 0; row < gray.rows; ++row) {
    for (int col = 0; col < gray.cols; ++col) {
      const double value = gray.at<std::uint8_t>(row, col) / 255.0;
      const double occupancy = negate ? value : 1.0 - value;  // dark = occupied
      std::uint8_t cost = kUnknownCost;
      if (occupancy > occupied_thresh) cost = kLethalCost;
      if (occupancy < free_thresh) cost = kFreeCost;
      grid.at(col, gray.rows - 1 - row) = cost;  // image row 0 is the top (max y)
    }
  }
  return grid;
}

std::optional<double> RayCast(const OccupancyGrid& grid, const Eigen::Vector2d& p_MO, double angle,
                              double max_range) {
  const double step = grid.geometry().resolution / 4.0;
  const Eigen::Vector2d direction(std::cos(angle), std::sin(angle));
  for (double d = 0.0; d <= max_range; d += step) {
    const auto cell = grid.geometry().CellOf(p_MO + d * direction);
    if (!cell) return std::nullopt;
    if (grid.at(cell->x(), cell->y()) == kLethalCost) return d;
  }
  return std::nullopt;
}

}  // namespace egress::perception
