#include "egress/planning/movingai.h"

#include <fstream>
#include <sstream>

#include "egress/hsr_interface/error.h"

namespace egress::planning {

perception::OccupancyGrid LoadMovingAiMap(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path);
  if (!in)
    throw LoadError(
        StrCat("Cannot load MovingAI map: '", file, "' does not exist or cannot be read."));
  std::string line, word;
  int width = -1, height = -1, number = 0;
  while (std::getline(in, line)) {
    ++number;
    std::istringstream header(line);
    header >> word;
    if (word == "type") continue;
    if (word == "height") header >> height;
    if (word == "width") header >> width;
    if (word == "map") break;
    if (word != "height" && word != "width") {
      throw LoadError(StrCat(file, ":", number, ": unexpected header line '", line, "'"));
    }
  }
  if (word != "map" || width <= 0 || height <= 0) {
    throw LoadError(StrCat(file, ": the header must give positive width and height, then 'map'"));
  }
  perception::GridGeometry geometry;
  geometry.resolution = 1.0;
  geometry.width = width;
  geometry.height = height;
  perception::OccupancyGrid grid(geometry, perception::kFreeCost);
  for (int y = 0; y < height; ++y) {
    if (!std::getline(in, line))
      throw LoadError(StrCat(file, ": the map has ", y, " rows, the header says ", height));
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (int(line.size()) != width) {
      throw LoadError(
          StrCat(file, ":", number, ": row has ", line.size(), " cells, the header says ", width));
    }
    for (int x = 0; x < width; ++x) {
      const char c = line[std::size_t(x)];
      const bool passable = c == '.' || c == 'G' || c == 'S';
      const bool blocked = c == '@' || c == 'O' || c == 'T' || c == 'W';
      if (!passable && !blocked)
        throw LoadError(StrCat(file, ":", number, ": unknown terrain '", c, "' at x ", x));
      if (blocked) grid.at(x, height - 1 - y) = perception::kLethalCost;
    }
  }
  return grid;
}

std::vector<MovingAiScenario> LoadMovingAiScenarios(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path);
  if (!in)
    throw LoadError(
        StrCat("Cannot load MovingAI scenarios: '", file, "' does not exist or cannot be read."));
  std::string line;
  int number = 0;
  std::vector<MovingAiScenario> scenarios;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line.rfind("version", 0) == 0) continue;
    std::istringstream fields(line);
    MovingAiScenario s;
    std::string map_name;
    int map_width, map_height;
    if (!(fields >> s.bucket >> map_name >> map_width >> map_height >> s.start.x() >> s.start.y() >>
          s.goal.x() >> s.goal.y() >> s.optimal_length)) {
      throw LoadError(StrCat(file, ":", number,
                             ": expected 9 fields: bucket map width height sx sy gx gy length"));
    }
    scenarios.push_back(s);
  }
  return scenarios;
}

Eigen::Vector2d MovingAiCellCenter(const Eigen::Vector2i& cell, int height) {
  return {cell.x() + 0.5, height - cell.y() - 0.5};
}

}  // namespace egress::planning
