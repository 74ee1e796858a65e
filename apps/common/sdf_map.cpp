#include "sdf_map.h"

#include <cmath>

#include "egress/hsr_interface/error.h"

namespace egress::apps {

SdfMap RasterizeSdfWorld(const twin::WorldDescription& world, double resolution,
                         std::int64_t max_cells) {
  ThrowUnless(resolution >= 0.01 && resolution <= 1.0, "resolution must be in [0.01, 1] m, got ",
              resolution);
  std::vector<perception::Box2> boxes;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e18), hi = -lo;
  for (const auto& f : twin::CalcFloorFootprints(world)) {
    boxes.push_back({f.X_WF, f.size});
    const Eigen::Vector2d half = f.X_WF.rotation().cwiseAbs() * (f.size / 2);
    lo = lo.cwiseMin(f.X_WF.translation() - half);
    hi = hi.cwiseMax(f.X_WF.translation() + half);
  }
  ThrowUnless(!boxes.empty(), world.source.string(),
              ": the world has no walls or furniture to map");
  // Snap the bounds to the cell grid so walls on whole metres land on cell edges.
  lo = (lo / resolution).array().floor() * resolution;
  hi = (hi / resolution).array().ceil() * resolution;
  const double cells = ((hi - lo) / resolution).prod();
  ThrowUnless(cells <= double(max_cells), world.source.string(), ": the world needs ",
              std::int64_t(cells), " cells at ", resolution, " m, more than the limit ", max_cells);
  SdfMap out{perception::OccupancyGrid::FromBoxes(boxes, lo, hi, resolution), {}};
  for (const auto& d : world.doors) {
    perception::Doorway doorway{d.name, d.p_WH.head<2>(), d.CalcFreeEdge(0.0).head<2>()};
    doorway.swing_sign = d.open_sign * (d.axis_W.z() > 0 ? 1.0 : -1.0);  // counter-clockwise = +1
    out.doors.push_back(doorway);
  }
  return out;
}

}  // namespace egress::apps
