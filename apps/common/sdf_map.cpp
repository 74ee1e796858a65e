#include "sdf_map.h"

#include <cmath>

#include "egress/hsr_interface/error.h"
#include "egress/twin/building.h"

namespace egress::apps {

SdfMap RasterizeSdfWorld(const twin::WorldDescription& world, double resolution,
                         std::int64_t max_cells, const std::vector<Eigen::Vector2d>& cover,
                         double cover_margin) {
  ThrowUnless(resolution >= 0.01 && resolution <= 1.0, "resolution must be in [0.01, 1] m, got ",
              resolution);
  ThrowUnless(cover_margin >= 0.0 && cover_margin <= 100.0,
              "map cover margin must be in [0, 100] m, got ", cover_margin);
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
  // Points inside the walls' bounds are on the map already; one outside brings its margin.
  const Eigen::Vector2d wall_lo = lo, wall_hi = hi;
  for (const auto& p : cover) {
    ThrowUnless(p.allFinite(), world.source.string(), ": a point to map is not finite");
    if ((p.array() >= wall_lo.array()).all() && (p.array() <= wall_hi.array()).all()) continue;
    lo = lo.cwiseMin(p - Eigen::Vector2d::Constant(cover_margin));
    hi = hi.cwiseMax(p + Eigen::Vector2d::Constant(cover_margin));
  }
  // Snap the bounds to the cell grid so walls on whole metres land on cell edges.
  lo = (lo / resolution).array().floor() * resolution;
  hi = (hi / resolution).array().ceil() * resolution;
  ThrowUnless(lo.allFinite() && hi.allFinite(), world.source.string(),
              ": the walls' and furniture's bounds are not finite (a shape of infinite or NaN "
              "size or pose)");
  // A double, not an integer: a world of absurd extent must give its count, not overflow it.
  const double cells = ((hi - lo) / resolution).prod();
  ThrowUnless(cells <= double(max_cells), world.source.string(), ": the world (x ", lo.x(), "..",
              hi.x(), ", y ", lo.y(), "..", hi.y(), " m) needs ", cells, " cells at ", resolution,
              " m, more than the limit ", max_cells);
  SdfMap out{perception::OccupancyGrid::FromBoxes(boxes, lo, hi, resolution), {}};
  for (const auto& d : world.doors) {
    const twin::BuildingDoor door = twin::DescribeDoor(d);
    perception::Doorway doorway{door.model, door.p_WHinge, door.p_WLatch};
    doorway.swing_sign = door.swing_sign;
    out.doors.push_back(doorway);
  }
  return out;
}

}  // namespace egress::apps
