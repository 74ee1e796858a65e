#include "twin_world_impl.h"

namespace egress::twin {

void TwinWorld::Impl::BuildStatics() {
  for (const StaticConvex& c : fixed.convex_statics) {
    ray_targets.push_back(AddBodyWithShape(c.shape.get(), c.X_WS, 0.0, c.floor ? kGFloor : kGStatic,
                                           c.floor ? kMaskFloor : kMaskStatic, c.entity));
    ray_target_polytopes.push_back(nullptr);
  }
  if (fixed.static_mesh_shape) {
    static_mesh_body = AddBodyWithShape(fixed.static_mesh_shape.get(), Pose3(), 0.0, kGStatic,
                                        kMaskStatic, kMergedStatic);
  }
}

void TwinWorld::Impl::AddRayProxy(const btCollisionObject* source,
                                  const std::vector<btVector3>& triangles_local) {
  // The triangles give the proxy's bounds (its mesh shape's AABB, for the ray bins); rays are
  // cast at the polytope they bound.
  auto mesh = std::make_unique<btTriangleMesh>(true, false);
  std::vector<Eigen::Vector3d> vertices;
  vertices.reserve(triangles_local.size());
  for (std::size_t i = 0; i + 2 < triangles_local.size(); i += 3) {
    mesh->addTriangle(triangles_local[i], triangles_local[i + 1], triangles_local[i + 2]);
    for (std::size_t k = i; k < i + 3; ++k)
      vertices.push_back(FromBt(triangles_local[k]));
  }
  auto shape = std::make_unique<btBvhTriangleMeshShape>(mesh.get(), true);
  auto proxy = std::make_unique<btCollisionObject>();
  proxy->setCollisionShape(shape.get());
  proxy->setUserIndex(source->getUserIndex());
  proxy->setWorldTransform(source->getWorldTransform());
  auto body = std::make_unique<world_detail::ConvexPolytope>(
      world_detail::ConvexPolytope::FromTriangles(vertices));
  ray_targets.push_back(proxy.get());
  ray_target_polytopes.push_back(body.get());
  ray_proxies.push_back({std::move(proxy), source, std::move(body)});
  meshes.push_back(std::move(mesh));
  shapes.push_back(std::move(shape));
}

std::vector<btVector3> TwinWorld::Impl::BoxTriangles(const btVector3& h) {
  auto corner = [&](int i) {
    return btVector3((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z());
  };
  static constexpr int kFaces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                       {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  std::vector<btVector3> t;
  for (const auto& f : kFaces) {
    for (int k : {f[0], f[1], f[2], f[0], f[2], f[3]})
      t.push_back(corner(k));
  }
  return t;
}

std::vector<btVector3> TwinWorld::Impl::PrismTriangles(double radius, double half_length,
                                                       int axis) {
  constexpr int kSides = 16;
  const double r = radius / std::cos(M_PI / kSides);
  auto point = [&](int k, double h) {
    const double a = 2 * M_PI * k / kSides;
    const double u = r * std::cos(a), v = r * std::sin(a);
    return axis == 0 ? btVector3(h, u, v) : btVector3(u, v, h);
  };
  std::vector<btVector3> t;
  const btVector3 top = axis == 0 ? btVector3(half_length, 0, 0) : btVector3(0, 0, half_length);
  for (int k = 0; k < kSides; ++k) {
    const btVector3 a0 = point(k, -half_length), a1 = point(k + 1, -half_length);
    const btVector3 b0 = point(k, half_length), b1 = point(k + 1, half_length);
    for (const auto& p : {a0, a1, b1, a0, b1, b0, top, b0, b1, -top, a1, a0})
      t.push_back(p);
  }
  return t;
}

void TwinWorld::Impl::BuildRayProxies() {
  for (const auto& d : doors)
    AddRayProxy(d.leaf, BoxTriangles(ToBt(d.fixed->desc->leaf_size / 2)));
  for (const auto& p : people)
    AddRayProxy(p.body, PrismTriangles(p.state.radius, kPersonHeight / 2, 2));
  for (const auto& p : payloads) {
    AddRayProxy(p.body, p.spec.kind == PayloadKind::kWaterBottle ? PrismTriangles(0.033, 0.105, 2)
                                                                 : PrismTriangles(0.02, 0.1, 0));
  }
}

void TwinWorld::Impl::SyncRayProxies() const {
  ray_proxies_stale = false;
  for (auto& p : ray_proxies)
    p.proxy->setWorldTransform(p.source->getWorldTransform());
  ray_target_aabbs.resize(ray_targets.size());
  for (std::size_t i = 0; i < ray_targets.size(); ++i) {
    ray_targets[i]->getCollisionShape()->getAabb(
        ray_targets[i]->getWorldTransform(), ray_target_aabbs[i].first, ray_target_aabbs[i].second);
  }
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& extents = ray_target_extents;
  extents.clear();
  extents.reserve(ray_target_aabbs.size());
  for (std::size_t i = 0; i < ray_targets.size(); ++i) {
    const bool plane =
        ray_targets[i]->getCollisionShape()->getShapeType() == STATIC_PLANE_PROXYTYPE;
    const auto& [lo, hi] = ray_target_aabbs[i];
    // A plane is tested by every ray (its bounds are not its extent).
    extents.emplace_back(
        plane ? Eigen::Vector2d::Constant(-INFINITY) : Eigen::Vector2d(lo.x(), lo.y()),
        plane ? Eigen::Vector2d::Constant(INFINITY) : Eigen::Vector2d(hi.x(), hi.y()));
  }
  ray_target_bins.Build(extents, kRayBinCellM);
}

}  // namespace egress::twin
