// ConvexPolytope (twin/src/ray_convex.h): where a ray segment crosses a convex body's surface.
#include "ray_convex.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

namespace egress::twin::world_detail {
namespace {

using Vec = Eigen::Vector3d;

std::vector<Vec> Box(const Vec& h) {
  auto corner = [&](int i) {
    return Vec((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z());
  };
  const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  std::vector<Vec> t;
  for (const auto& f : faces) {
    for (int k : {f[0], f[1], f[2], f[0], f[2], f[3]})
      t.push_back(corner(k));
  }
  return t;
}

// A vertical prism of `sides` sides round the z axis (a person's body in the twin).
std::vector<Vec> Prism(double r, double half_height, int sides) {
  std::vector<Vec> t;
  auto at = [&](int k, double z) {
    const double a = 2 * M_PI * k / sides;
    return Vec(r * std::cos(a), r * std::sin(a), z);
  };
  const Vec top(0, 0, half_height);
  for (int k = 0; k < sides; ++k) {
    const Vec a0 = at(k, -half_height), a1 = at(k + 1, -half_height);
    const Vec b0 = at(k, half_height), b1 = at(k + 1, half_height);
    for (const Vec& p : {a0, a1, b1, a0, b1, b0, top, b0, b1, Vec(-top), a1, a0})
      t.push_back(p);
  }
  return t;
}

// Möller–Trumbore: the segment parameter where o + t v meets triangle abc, and how far inside the
// triangle (the smallest barycentric coordinate), or nothing.
struct TriangleHit {
  double t;
  double margin;
  Vec normal;
};
std::optional<TriangleHit> HitTriangle(const Vec& o, const Vec& v, const Vec& a, const Vec& b,
                                       const Vec& c) {
  const Vec e1 = b - a, e2 = c - a, p = v.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-14) return std::nullopt;
  const Vec s = o - a;
  const double u = s.dot(p) / det;
  const Vec q = s.cross(e1);
  const double w = v.dot(q) / det;
  const double t = e2.dot(q) / det;
  if (u < 0 || w < 0 || u + w > 1 || t <= 0 || t >= 1) return std::nullopt;
  Vec n = e1.cross(e2).normalized();
  if (n.dot(v) > 0) n = -n;  // facing the segment's start
  return TriangleHit{t, std::min({u, w, 1 - u - w}), n};
}

TEST(ConvexPolytopeTest, ABoxHasSixFacesAndIsEnteredAndLeftThroughThem) {
  const auto box = ConvexPolytope::FromTriangles(Box(Vec(0.5, 0.1, 1.0)));
  EXPECT_EQ(box.num_faces(), 6u);
  std::array<ConvexPolytope::Crossing, 2> c;
  // Along x through the middle: in at x = -0.5, out at x = +0.5 (segment from -2 to 2).
  ASSERT_EQ(box.Cross(Vec(-2, 0, 0), Vec(4, 0, 0), &c), 2);
  EXPECT_NEAR(c[0].t, 1.5 / 4, 1e-12);
  EXPECT_TRUE(c[0].normal.isApprox(Vec(-1, 0, 0)));
  EXPECT_NEAR(c[1].t, 2.5 / 4, 1e-12);
  EXPECT_TRUE(c[1].normal.isApprox(Vec(-1, 0, 0)));  // the far face, seen from inside
  // Starting inside: only the exit.
  ASSERT_EQ(box.Cross(Vec(0, 0, 0), Vec(0, 1, 0), &c), 1);
  EXPECT_NEAR(c[0].t, 0.1, 1e-12);
  EXPECT_TRUE(c[0].normal.isApprox(Vec(0, -1, 0)));
  // Ending inside: only the entry.
  ASSERT_EQ(box.Cross(Vec(0, -1, 0), Vec(0, 1, 0), &c), 1);
  EXPECT_NEAR(c[0].t, 0.9, 1e-12);
  // Passing beside it, parallel to a face, or stopping short: nothing.
  EXPECT_EQ(box.Cross(Vec(-2, 0.2, 0), Vec(4, 0, 0), &c), 0);
  EXPECT_EQ(box.Cross(Vec(-2, 0, 1.5), Vec(4, 0, 0), &c), 0);
  EXPECT_EQ(box.Cross(Vec(-2, 0, 0), Vec(1, 0, 0), &c), 0);
}

TEST(ConvexPolytopeTest, CrossesWhereTheTrianglesAre) {
  const std::vector<Vec> triangles = Prism(0.25, 0.85, 16);
  const auto prism = ConvexPolytope::FromTriangles(triangles);
  EXPECT_EQ(prism.num_faces(), 18u);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  int compared = 0, crossing = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Vec o(u(rng), u(rng), u(rng));
    // Every other ray aimed at a point near the body's axis, past it.
    const Vec v = trial % 2 ? Vec(Vec(u(rng), u(rng), u(rng)) * 1.5)
                            : Vec((Vec(0.15 * u(rng), 0.15 * u(rng), 0.5 * u(rng)) - o) * 2.0);
    std::vector<TriangleHit> hits;
    bool near_edge = false;
    for (std::size_t i = 0; i < triangles.size(); i += 3) {
      if (auto h = HitTriangle(o, v, triangles[i], triangles[i + 1], triangles[i + 2])) {
        near_edge = near_edge || h->margin < 1e-6;
        hits.push_back(*h);
      }
    }
    if (near_edge) continue;  // a ray through an edge meets two triangles or one: no oracle
    std::sort(hits.begin(), hits.end(), [](const auto& a, const auto& b) { return a.t < b.t; });
    std::array<ConvexPolytope::Crossing, 2> c;
    const int n = prism.Cross(o, v, &c);
    ASSERT_EQ(n, int(hits.size())) << "trial " << trial;
    for (int k = 0; k < n; ++k) {
      EXPECT_NEAR(c[std::size_t(k)].t, hits[std::size_t(k)].t, 1e-9) << "trial " << trial;
      EXPECT_TRUE(c[std::size_t(k)].normal.isApprox(hits[std::size_t(k)].normal, 1e-9))
          << "trial " << trial;
    }
    ++compared;
    crossing += n > 0;
  }
  EXPECT_GT(compared, 19000);
  EXPECT_GT(crossing, 8000);  // the sample meets the body often enough to mean something
}

TEST(ConvexPolytopeTest, RefusesASurfaceNotRoundTheOriginOrWithADegenerateTriangle) {
  std::vector<Vec> shifted = Box(Vec(0.5, 0.5, 0.5));
  for (Vec& p : shifted)
    p.x() += 0.5;  // one face through the origin
  EXPECT_THROW(ConvexPolytope::FromTriangles(shifted), std::invalid_argument);
  const std::vector<Vec> flat = {Vec(1, 0, 0), Vec(1, 0, 0), Vec(1, 1, 0)};
  EXPECT_THROW(ConvexPolytope::FromTriangles(flat), std::invalid_argument);
}

}  // namespace
}  // namespace egress::twin::world_detail
