#include "egress/perception/occupancy_grid.h"

#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/text_file.h"
#include "egress/perception/image_io.h"

namespace egress::perception {

std::optional<Eigen::Vector2i> GridGeometry::CellOf(const Eigen::Vector2d& p_MQ) const {
  if (!p_MQ.allFinite()) return std::nullopt;
  const Eigen::Vector2d local = (p_MQ - origin) / resolution;
  const double fx = std::floor(local.x());
  const double fy = std::floor(local.y());
  // Range first: a far point (1e174 m, found by fuzzing navd) does not fit an int.
  if (!(fx >= 0.0 && fx < double(width) && fy >= 0.0 && fy < double(height))) return std::nullopt;
  return Eigen::Vector2i(static_cast<int>(fx), static_cast<int>(fy));
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

namespace {

// Width and height from a PGM (P2/P5) or PNG header, or nullopt for another format.
std::optional<std::pair<std::int64_t, std::int64_t>> MapImageDimensions(std::string_view bytes,
                                                                        std::string_view what) {
  static constexpr std::string_view kPngSignature{"\x89PNG\r\n\x1a\n", 8};
  if (bytes.substr(0, 8) == kPngSignature) {
    // The first chunk is IHDR: length (4), type (4), width (4, big-endian), height (4).
    if (bytes.size() < 24 || bytes.substr(12, 4) != "IHDR")
      throw LoadError(StrCat(what, ": a PNG without its IHDR header"));
    const auto be32 = [&](std::size_t at) {
      std::int64_t v = 0;
      for (std::size_t i = 0; i < 4; ++i)
        v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
      return v;
    };
    return std::pair{be32(16), be32(20)};
  }
  if (bytes.size() >= 2 && bytes[0] == 'P' && (bytes[1] == '5' || bytes[1] == '2')) {
    // P5/P2, then width, height and maxval as decimal tokens separated by whitespace, with
    // '#' comments to the end of a line.
    std::size_t at = 2;
    std::int64_t values[2] = {0, 0};
    for (std::int64_t& value : values) {
      while (at < bytes.size()) {
        if (std::isspace(static_cast<unsigned char>(bytes[at]))) {
          ++at;
        } else if (bytes[at] == '#') {
          while (at < bytes.size() && bytes[at] != '\n')
            ++at;
        } else {
          break;
        }
      }
      const std::size_t begin = at;
      while (at < bytes.size() && at - begin < 10 &&
             std::isdigit(static_cast<unsigned char>(bytes[at]))) {
        value = value * 10 + (bytes[at] - '0');
        ++at;
      }
      if (at == begin) throw LoadError(StrCat(what, ": a PGM header without its width and height"));
    }
    return std::pair{values[0], values[1]};
  }
  return std::nullopt;
}

}  // namespace

cv::Mat OccupancyGrid::DecodeMapImage(std::string_view bytes, std::int64_t max_cells,
                                      std::string_view what) {
  const auto size = MapImageDimensions(bytes, what);
  if (!size) throw LoadError(StrCat(what, ": not a PGM or PNG image (the formats egress reads)"));
  const auto [width, height] = *size;
  if (width <= 0 || height <= 0 || width > max_cells || height > max_cells ||
      width * height > max_cells) {
    throw LoadError(
        StrCat(what, ": ", width, " x ", height, " cells; the limit is ", max_cells, " cells"));
  }
  const cv::Mat encoded(1, int(bytes.size()), CV_8UC1,
                        const_cast<char*>(bytes.data()));  // decoding only reads it
  cv::Mat image = DecodeGrayImage(encoded);
  if (image.empty()) throw LoadError(StrCat(what, ": the image cannot be decoded"));
  return image;
}

OccupancyGrid OccupancyGrid::LoadMapServerYaml(const std::filesystem::path& yaml_path,
                                               std::int64_t max_cells) {
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
  const std::string where =
      StrCat(file, ":", image_field.line, ": image '", image_path.string(), "'");
  std::string bytes;
  try {
    bytes = ReadTextFile(image_path, "map image");
  } catch (const PathOutsideRoot&) {
    throw;
  } catch (const LoadError& e) {
    throw LoadError(StrCat(where, " cannot be read (", e.what(), ")."));
  }
  const cv::Mat image = DecodeMapImage(bytes, max_cells, where);
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
