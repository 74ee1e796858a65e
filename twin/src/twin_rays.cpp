#include "twin_world_impl.h"

#include <BulletCollision/NarrowPhaseCollision/btRaycastCallback.h>

namespace egress::twin {

namespace {

class TwinRayCallback : public btCollisionWorld::RayResultCallback {
 public:
  TwinRayCallback(const btVector3& dir, GlassMode mode, double glass_max_incidence,
                  const std::function<bool(int)>& is_glass,
                  const std::function<int(const btCollisionObject*, int)>& entity_of)
      : dir_(dir),
        mode_(mode),
        glass_max_incidence_(glass_max_incidence),
        is_glass_(is_glass),
        entity_of_(entity_of) {}

  btScalar addSingleResult(btCollisionWorld::LocalRayResult& r, bool normal_in_world) override {
    const btVector3 n =
        normal_in_world ? r.m_hitNormalLocal
                        : r.m_collisionObject->getWorldTransform().getBasis() * r.m_hitNormalLocal;
    const int entity =
        entity_of_(r.m_collisionObject,
                   r.m_localShapeInfo != nullptr ? r.m_localShapeInfo->m_triangleIndex : -1);
    return Offer(r.m_hitFraction, n, r.m_collisionObject, entity) ? r.m_hitFraction
                                                                  : m_closestHitFraction;
  }

  // A hit at `fraction` of the ray on a face of normal n_W of `entity`: kept unless the ray
  // passes through it (glass); false when passed. The caller has checked it is the closest.
  bool Offer(btScalar fraction, const btVector3& n_W, const btCollisionObject* object, int entity) {
    const bool glass = is_glass_(entity);
    if (glass && (mode_ == GlassMode::kTransparent ||
                  (mode_ == GlassMode::kLaser && std::abs(n_W.normalized().dot(dir_.normalized())) <
                                                     std::cos(glass_max_incidence_)))) {
      return false;  // the ray passes through the glass
    }
    m_closestHitFraction = fraction;
    m_collisionObject = object;
    normal = n_W;
    this->entity = entity;
    this->glass = glass;
    return true;
  }

  btVector3 normal{0, 0, 0};
  int entity{-1};
  bool glass{false};

 private:
  btVector3 dir_;  // the ray's; normalized only where a glass hit needs it (few rays do)
  GlassMode mode_;
  double glass_max_incidence_;  // [rad]; its cosine is needed only on a glass hit
  const std::function<bool(int)>& is_glass_;
  const std::function<int(const btCollisionObject*, int)>& entity_of_;
};

// The static triangle mesh's hits, passed on to the twin's ray callback. The mesh may be cast on
// a piece [0, scale] of the twin's ray; fractions are rescaled to the whole ray.
class StaticMeshRayCallback : public btTriangleRaycastCallback {
 public:
  StaticMeshRayCallback(const btVector3& from, const btVector3& to, btScalar scale,
                        const btCollisionObject* mesh, TwinRayCallback* out,
                        const std::vector<int>& triangle_entity)
      : btTriangleRaycastCallback(from, to),
        scale_(scale),
        mesh_(mesh),
        out_(out),
        triangle_entity_(triangle_entity) {}
  btScalar reportHit(const btVector3& normal, btScalar fraction, int, int triangle) override {
    const btScalar whole = fraction * scale_;
    if (whole >= out_->m_closestHitFraction) return m_hitFraction;
    out_->m_closestHitFraction = whole;
    out_->m_collisionObject = mesh_;
    out_->normal = normal;
    out_->entity = triangle >= 0 && std::size_t(triangle) < triangle_entity_.size()
                       ? triangle_entity_[std::size_t(triangle)]
                       : -1;
    out_->glass = false;
    return fraction;
  }

 private:
  btScalar scale_;
  const btCollisionObject* mesh_;
  TwinRayCallback* out_;
  const std::vector<int>& triangle_entity_;
};

}  // namespace

double TwinWorld::Impl::PlaneClip(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const {
  double clip = 1.0;
  for (const std::size_t k : fixed.ray_planes) {
    const RayBox& plane = fixed.ray_boxes[k];
    const Eigen::Vector3d o = plane.R_SW * (from - plane.p_WS);
    const Eigen::Vector3d v = plane.R_SW * (to - from);
    if (std::abs(v.z()) < 1e-12) continue;  // along the plane
    const double t = -o.z() / v.z();
    if (t < 0.0 || t >= clip) continue;
    const Eigen::Vector2d q = o.head<2>() + t * v.head<2>();
    if (std::abs(q.x()) > plane.half.x() || std::abs(q.y()) > plane.half.y()) continue;
    // A margin as the mesh's clip has: the plane's own test must still meet it.
    clip = std::min(clip, t * 1.001 + 1e-6);
  }
  return std::min(clip, 1.0);
}

RayHit TwinWorld::Impl::CastSegment(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                    GlassMode mode, double glass_max_incidence,
                                    const RayFanBins* fan, long fan_bin) const {
  const btVector3 a = ToBt(from), b = ToBt(to);
  TwinRayCallback cb(b - a, mode, glass_max_incidence, ray_is_glass, ray_entity_of);
  // Bullet's ray tests, object by object rather than through the broadphase: first the cheap
  // targets (the ground plane, and every other target whose bounding box the ray still crosses
  // before its closest hit so far), then the static triangle mesh on the ray clipped just past
  // that hit: the mesh's BVH walk costs in proportion to the ray's length. Dynamic bodies are
  // cast as convex polytopes of their shapes (see BuildRayProxies): exact, and much cheaper than
  // Bullet's iterative convex cast or a BVH walk of their triangles.
  // Only the targets and boxes the ray's ground track may cross, cell by cell from `from`.
  // The walks stop once the closest hit so far lies before every cell still to come (less a
  // margin for rounding: a box on a cell line is binned in the cell beyond it).
  constexpr double kWalkMargin = 1e-9;
  thread_local std::vector<int> near;
  const btTransform from_T(btMatrix3x3::getIdentity(), a), to_T(btMatrix3x3::getIdentity(), b);
  // Nothing past an opaque plane's crossing can be the closest hit: the ground track is walked
  // only that far (most of a downward camera's rays end on the floor a few metres out).
  const double plane_clip = PlaneClip(from, to);
  // A fan's candidates come nearest first by ground distance from its origin: none beyond the
  // ground distance of fraction t of this segment can be hit before t (the margin, for rounding,
  // in metres: the walks' 1e-9 in t is less than that on a ray of up to 30 m).
  const Eigen::Vector2d ground = (to - from).head<2>();
  const double ground_from = fan ? (from.head<2>() - fan->targets.origin()).norm() : 0.0;
  const double ground_length = fan ? ground.norm() : 0.0;
  constexpr double kFanMarginM = 1e-6;
  const auto beyond = [&](double near, double t) {
    return near > ground_from + t * ground_length + kFanMarginM;
  };
  // The targets a walk step yields, in its order: a hit closer than the closest so far is kept.
  const auto test_targets = [&](const auto& candidates) {
    for (const auto& candidate : candidates) {
      int k = 0;
      if constexpr (std::is_same_v<std::decay_t<decltype(candidate)>, int>) {
        k = candidate;
      } else {
        if (beyond(candidate.near, std::min(double(cb.m_closestHitFraction), plane_clip))) break;
        k = candidate.box;
      }
      const std::size_t i = std::size_t(k);
      const btCollisionObject* target = ray_targets[i];
      btVector3 normal;
      btScalar param = cb.m_closestHitFraction;
      const bool plane = target->getCollisionShape()->getShapeType() == STATIC_PLANE_PROXYTYPE;
      if (!plane &&
          !btRayAabb(a, b, ray_target_aabbs[i].first, ray_target_aabbs[i].second, param, normal))
        continue;
      if (const world_detail::ConvexPolytope* body = ray_target_polytopes[i]) {
        // A moving body: its faces analytically, in its own frame. The nearer crossing first; the
        // far one counts when the near one is glass the ray passes through.
        const btTransform& X_WT = target->getWorldTransform();
        const Eigen::Vector3d o = FromBt(X_WT.invXform(a));
        const Eigen::Vector3d v = FromBt((b - a) * X_WT.getBasis());  // R^T (b - a)
        std::array<world_detail::ConvexPolytope::Crossing, 2> crossings;
        const int n = body->Cross(o, v, &crossings);
        const int entity = ray_entity_of(target, -1);
        for (int k = 0; k < n; ++k) {
          const auto& c = crossings[std::size_t(k)];
          if (c.t >= cb.m_closestHitFraction) break;
          if (cb.Offer(btScalar(c.t), X_WT.getBasis() * ToBt(c.normal), target, entity)) break;
        }
        continue;
      }
      btCollisionWorld::rayTestSingle(from_T, to_T, const_cast<btCollisionObject*>(target),
                                      target->getCollisionShape(), target->getWorldTransform(), cb);
    }
  };
  double t_beyond = 0.0;
  if (fan) {
    test_targets(fan->targets.Along(fan_bin));
  } else {
    world_detail::RayBins::Walk targets(ray_target_bins, from.head<2>(),
                                        from.head<2>() + ground * plane_clip);
    while (targets.Next(&near, &t_beyond)) {
      test_targets(near);
      if (cb.m_closestHitFraction < t_beyond * plane_clip - kWalkMargin) break;
    }
  }
  // Static boxes and planes: slab tests in each shape's frame, on the ray as a segment t in
  // [0, 1]. A ray starting inside a box hits its far side (as the triangles' did).
  const Eigen::Vector3d d = to - from;
  // Nor can a box past the closest hit so far be closer (the same margin).
  const double box_clip = std::min(1.0, double(cb.m_closestHitFraction) * 1.001 + 1e-6);
  const double box_reach = std::min(box_clip, plane_clip);
  const double target_t = cb.m_closestHitFraction;
  // The closest box; a tie goes to the lower index, as a test in index order gives it.
  struct {
    double t{std::numeric_limits<double>::infinity()};
    int k{-1};
    Eigen::Vector3d n_W{Eigen::Vector3d::Zero()};
  } closest_box;
  const auto test_box = [&](int k) {
    const RayBox& box = fixed.ray_boxes[std::size_t(k)];
    const Eigen::Vector3d o = box.R_SW * (from - box.p_WS);
    const Eigen::Vector3d v = box.R_SW * d;
    double t_in = -std::numeric_limits<double>::infinity();
    double t_out = std::numeric_limits<double>::infinity();
    int axis_in = -1, axis_out = -1;
    bool miss = false;
    for (int i = 0; i < 3 && !miss; ++i) {
      if (std::abs(v[i]) < 1e-12) {
        miss = std::abs(o[i]) > box.half[i] || box.half[i] == 0.0;
        continue;
      }
      double ta = (-box.half[i] - o[i]) / v[i], tb = (box.half[i] - o[i]) / v[i];
      if (ta > tb) std::swap(ta, tb);
      if (ta > t_in) {
        t_in = ta;
        axis_in = i;
      }
      if (tb < t_out) {
        t_out = tb;
        axis_out = i;
      }
      miss = t_in > t_out;
    }
    if (miss) return;
    const bool inside = t_in < 0.0;
    const double t = inside ? t_out : t_in;
    const int axis = inside ? axis_out : axis_in;
    if (axis < 0 || t < 0.0 || t >= target_t) return;
    if (t > closest_box.t || (t == closest_box.t && k > closest_box.k)) return;
    // Outward normal of the face the ray meets.
    const double sign = (v[axis] > 0.0) == inside ? 1.0 : -1.0;
    closest_box.t = t;
    closest_box.k = k;
    closest_box.n_W = box.R_SW.row(axis).transpose() * sign;
  };
  if (fan) {
    for (const auto& candidate : fan->boxes.Along(fan_bin)) {
      if (beyond(candidate.near, std::min({box_reach, target_t, closest_box.t}))) break;
      test_box(candidate.box);
    }
  } else {
    world_detail::RayBins::Walk boxes(fixed.ray_box_bins, from.head<2>(),
                                      from.head<2>() + ground * box_reach);
    while (boxes.Next(&near, &t_beyond)) {
      for (const int k : near)
        test_box(k);
      if (std::min(target_t, closest_box.t) < t_beyond * box_reach - kWalkMargin) break;
    }
  }
  if (closest_box.k >= 0) {
    cb.m_closestHitFraction = btScalar(closest_box.t);
    cb.m_collisionObject = static_mesh_body;
    cb.normal = ToBt(closest_box.n_W);
    cb.entity = fixed.ray_boxes[std::size_t(closest_box.k)].entity;
    cb.glass = false;
  }
  if (fixed.ray_mesh_shape != nullptr) {
    // A hair past the closest hit, so that a mesh standing on the floor still wins the tie.
    const btScalar scale = std::min<btScalar>(1.0, cb.m_closestHitFraction * 1.001 + 1e-6);
    const btVector3 b_clipped = a + (b - a) * scale;
    StaticMeshRayCallback mesh_cb(a, b_clipped, scale, static_mesh_body, &cb,
                                  fixed.ray_triangle_entity);
    fixed.ray_mesh_shape->performRaycast(&mesh_cb, a, b_clipped);
  }
  RayHit hit;
  if (!cb.hasHit()) return hit;
  hit.hit = true;
  hit.distance = cb.m_closestHitFraction * (to - from).norm();
  hit.point = from + cb.m_closestHitFraction * (to - from);
  hit.normal = FromBt(cb.normal).normalized();
  hit.entity = cb.entity;
  hit.glass = cb.glass;
  return hit;
}

RayHit TwinWorld::Impl::CastRayInPieces(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                        GlassMode mode, double glass_max_incidence,
                                        const RayFanBins* fan) const {
  // Cast near first, then the rest: most rays indoors hit within a few metres, and a hit in the
  // near piece skips the far piece's walk of the BVH.
  constexpr double kNearSegment = 3.0;  // [m]
  const double length = (to - from).norm();
  // Both pieces in the ray's bin of the fan (the far piece's own direction may round into the
  // next; either bin holds all it may cross).
  const long bin = fan ? world_detail::RayFan::Bin((to - from).head<2>()) : 0;
  if (length > 1.5 * kNearSegment) {
    const Eigen::Vector3d mid = from + (to - from) * (kNearSegment / length);
    RayHit near = CastSegment(from, mid, mode, glass_max_incidence, fan, bin);
    if (near.hit) return near;
    RayHit far = CastSegment(mid, to, mode, glass_max_incidence, fan, bin);
    if (far.hit) far.distance += kNearSegment;
    return far;
  }
  return CastSegment(from, to, mode, glass_max_incidence, fan, bin);
}

RayHit TwinWorld::CastRay(const Eigen::Vector3d& from, const Eigen::Vector3d& to, GlassMode mode,
                          double glass_max_incidence) const {
  // The sensors see doors, people and payloads where they are now.
  if (impl_->ray_proxies_stale) impl_->SyncRayProxies();
  return impl_->CastRayInPieces(from, to, mode, glass_max_incidence, nullptr);
}

void TwinWorld::CastRayFan(const Eigen::Vector3d& from, std::span<const Eigen::Vector3d> tos,
                           GlassMode mode, std::vector<RayHit>* hits,
                           double glass_max_incidence) const {
  ThrowUnless(hits != nullptr, "CastRayFan: no output");
  if (impl_->ray_proxies_stale) impl_->SyncRayProxies();
  // The candidates by bearing from `from`, once for the fan, as far as its longest ray reaches
  // on the ground.
  double reach = 0.0;
  for (const Eigen::Vector3d& to : tos)
    reach = std::max(reach, (to - from).head<2>().norm());
  thread_local Impl::RayFanBins fan;
  fan.targets.Build(from.head<2>(), impl_->ray_target_extents, reach);
  fan.boxes.Build(from.head<2>(), impl_->fixed.ray_box_extents, reach);
  hits->resize(tos.size());
  for (std::size_t k = 0; k < tos.size(); ++k)
    (*hits)[k] = impl_->CastRayInPieces(from, tos[k], mode, glass_max_incidence, &fan);
}

EntityKind TwinWorld::entity_kind(int entity) const {
  return impl_->entities.at(std::size_t(entity)).kind;
}
const std::string& TwinWorld::entity_name(int entity) const {
  return impl_->entities.at(std::size_t(entity)).name;
}

const Scenario& TwinWorld::scenario() const {
  return impl_->scenario;
}
const WorldDescription& TwinWorld::world() const {
  return impl_->world;
}
const TwinConfig& TwinWorld::config() const {
  return impl_->config;
}
const std::shared_ptr<const TwinModel>& TwinWorld::model() const {
  return impl_->twin_model;
}
std::uint64_t TwinWorld::seed() const {
  return impl_->seed;
}

}  // namespace egress::twin
