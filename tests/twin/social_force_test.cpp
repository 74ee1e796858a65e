#include "egress/twin/social_force.h"

#include "egress/hsr_interface/error.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace egress::twin {
namespace {

double MinGap(const std::vector<Walker>& w) {
  double gap = 1e9;
  for (std::size_t i = 0; i < w.size(); ++i) {
    for (std::size_t j = i + 1; j < w.size(); ++j) {
      gap = std::min(gap, (w[i].position - w[j].position).norm() - w[i].radius - w[j].radius);
    }
  }
  return gap;
}

// A 2.4 m wide corridor along x.
std::vector<WallSegment> Corridor() {
  return {{{-10, -1.2}, {10, -1.2}}, {{-10, 1.2}, {10, 1.2}}};
}

// A wall acts out to where its term falls to a thousandth of its value at contact (a gap of
// wall_range ln 1000), as the social terms do; the binned walls give the same sums as all walls,
// and walls binned for less than the model's reach are an error, not a silently dropped wall.
TEST(SocialForceModelTest, AWallActsOutToWhereItsTermIsAThousandthOfItsContactValue) {
  SocialForceModel sfm;
  const double cutoff = sfm.params().wall_range * std::log(1000.0);
  const std::vector<WallSegment> wall = {{{-10, 0}, {10, 0}}};
  const auto wall_push = [&](double gap) {
    Walker w;
    w.position = {0.0, w.radius + gap};
    w.target = w.position;  // no drive
    const Eigen::Vector2d a = sfm.CalcAcceleration(0, {w}, {}, wall);
    const Eigen::Vector2d binned =
        sfm.CalcAccelerations({w}, {}, WallCells(wall, sfm.WallReach()), {}).front();
    EXPECT_EQ(a, binned) << "gap " << gap;
    return a.y();
  };
  const double at_contact = wall_push(1e-6);
  EXPECT_GT(at_contact, 0.0);
  EXPECT_GT(wall_push(cutoff - 0.01), 0.0);
  EXPECT_LT(wall_push(cutoff - 0.01), 1.1e-3 * at_contact);
  EXPECT_EQ(wall_push(cutoff + 0.01), 0.0);
  EXPECT_GE(sfm.WallReach(), 1.0 + cutoff);
  Walker w;
  EXPECT_THROW(sfm.CalcAccelerations({w}, {}, WallCells(wall, 1.0), {}), InvalidArgument);
  EXPECT_THROW(WallCells(wall, 0.0), InvalidArgument);
}

TEST(SocialForceModelTest, TwoPeoplePassHeadOnWithoutOverlap) {
  SocialForceModel sfm;
  std::vector<Walker> w(2);
  w[0].position = {-5, 0.0};
  w[0].target = {5, 0};
  w[1].position = {5, 0.0};
  w[1].target = {-5, 0};
  w[0].desired_speed = w[1].desired_speed = 1.3;
  double min_gap = 1e9;
  for (int i = 0; i < 1500; ++i) {
    sfm.Step(&w, {}, Corridor(), 0.01);
    min_gap = std::min(min_gap, MinGap(w));
  }
  EXPECT_GT(min_gap, 0.0) << "bodies overlapped";
  EXPECT_NEAR(w[0].position.x(), 5.0, 0.5);
  EXPECT_NEAR(w[1].position.x(), -5.0, 0.5);
  for (const auto& x : w)
    EXPECT_LT(std::abs(x.position.y()), 1.2 - x.radius + 0.02);
}

TEST(SocialForceModelTest, AWalkerGoesThroughAOneMetreDoorwayWithoutTouchingTheJambs) {
  SocialForceModel sfm;
  // A wall at x = 0 with a 1 m gap at y −0.5..0.5 (jambs as short segments, 0.1 m thick).
  const std::vector<WallSegment> walls = {
      {{-0.05, -5}, {-0.05, -0.5}, 0},  {{0.05, -5}, {0.05, -0.5}, 0},
      {{-0.05, -0.5}, {0.05, -0.5}, 0}, {{-0.05, 0.5}, {-0.05, 5}, 1},
      {{0.05, 0.5}, {0.05, 5}, 1},      {{-0.05, 0.5}, {0.05, 0.5}, 1}};
  std::vector<Walker> w(1);
  w[0].position = {-3, 0.3};
  w[0].desired_speed = 1.3;
  double min_clearance = 1e9;
  const std::vector<Eigen::Vector2d> route = {{-1.0, 0.0}, {0.0, 0.0}, {1.0, 0.0}, {3.0, 0.5}};
  std::size_t next = 0;
  for (int i = 0; i < 1500 && next < route.size(); ++i) {
    w[0].target = route[next];
    if ((w[0].position - route[next]).norm() < 0.25) ++next;
    sfm.Step(&w, {}, walls, 0.01);
    for (const auto& s : walls) {
      min_clearance =
          std::min(min_clearance,
                   (w[0].position - ClosestPointOnSegment(w[0].position, s)).norm() - w[0].radius);
    }
  }
  EXPECT_EQ(next, route.size()) << "stuck at " << w[0].position.transpose();
  EXPECT_GT(min_clearance, 0.0);
}

TEST(SocialForceModelTest, ARobotDiscIsAvoided) {
  SocialForceModel sfm;
  std::vector<Walker> w(1);
  w[0].position = {-4, 0.05};
  w[0].target = {4, 0};
  w[0].desired_speed = 1.2;
  const std::vector<DiscObstacle> robot = {{{0, 0}, {0, 0}, 0.215}};
  double min_gap = 1e9;
  for (int i = 0; i < 1000; ++i) {
    sfm.Step(&w, robot, {}, 0.01);
    min_gap = std::min(min_gap, (w[0].position - robot[0].position).norm() - 0.215 - w[0].radius);
  }
  EXPECT_GT(min_gap, 0.05);
  EXPECT_GT(w[0].position.x(), 3.0);
}

// A walker's approach to the robot is capped so it could stop short of it: the cap takes away
// only its own speed towards the disc (its sideways speed stays, and a disc driving at a
// standing walker does not push it back: that contact is the disc's).
TEST(SocialForceModelTest, AWalkerCanAlwaysStopShortOfTheRobot) {
  const SocialForceModel sfm;
  const auto& P = sfm.params();
  std::vector<Walker> w(1);
  w[0].radius = 0.25;
  w[0].position = {-0.25 - 0.215 - 0.2, 0.0};  // a 0.2 m gap
  w[0].velocity = {1.6, 0.5};
  w[0].target = {5.0, 0.0};
  const std::vector<DiscObstacle> robot = {{{0, 0}, {0, 0}, 0.215}};
  sfm.Integrate(&w, {Eigen::Vector2d::Zero()}, 0.01, robot);
  EXPECT_NEAR(w[0].velocity.x(),
              std::sqrt(2.0 * P.disc_braking_deceleration * (0.2 - P.disc_keep_gap)), 1e-9);
  EXPECT_EQ(w[0].velocity.y(), 0.5);
  // Without the disc, nothing caps it.
  std::vector<Walker> free = {w[0]};
  free[0].velocity = {1.6, 0.5};
  sfm.Integrate(&free, {Eigen::Vector2d::Zero()}, 0.01);
  EXPECT_EQ(free[0].velocity.x(), 1.6);
  // A disc coming at a walker standing still leaves it standing.
  std::vector<Walker> still(1);
  still[0].position = {-0.5, 0.0};
  still[0].desired_speed = 0.0;
  const std::vector<DiscObstacle> coming = {{{0, 0}, {-0.5, 0}, 0.215}};
  sfm.Integrate(&still, {Eigen::Vector2d::Zero()}, 0.01, coming);
  EXPECT_EQ(still[0].velocity, Eigen::Vector2d::Zero());
  // Step caps as Integrate does: a walker running at the robot stops short of it.
  std::vector<Walker> running = {w[0]};
  running[0].velocity = {1.65, 0.0};
  double min_gap = 1e9;
  for (int i = 0; i < 100; ++i) {
    sfm.Step(&running, robot, {}, 1.0 / 240);
    min_gap = std::min(min_gap, running[0].position.norm() - 0.25 - 0.215);
  }
  EXPECT_GT(min_gap, P.disc_keep_gap - 1e-3);
}

// Step's cell lists (walkers within the social cutoff, walls within reach) give bit for bit
// the accelerations of summing over every walker and every wall, so runs do not change with
// the crowd's size or the building's.
TEST(SocialForceModelTest, ANeighbourPushesOnlyWithinItsReachAndFurtherWhenComingAtYou) {
  // A standing walker at the origin (no drive), another at distance x: the push on the first.
  SocialForceParams params;
  params.field_of_view_deg = 360.0;  // every force in view: one weight
  const SocialForceModel sfm(params);
  auto push = [&](double x, double vx) {
    std::vector<Walker> w(2);
    w[0].desired_speed = 0.0;
    w[1].position = {x, 0.0};
    w[1].velocity = {vx, 0.0};
    w[1].desired_speed = 0.0;
    return sfm.CalcAcceleration(0, w, {}, {}).norm();
  };
  const double b_max = params.social_range * std::log(1000.0);  // 2.07 m
  EXPECT_GT(push(b_max - 0.05, 0.0), 0.0);
  EXPECT_EQ(push(b_max + 0.05, 0.0), 0.0);
  // The push is continuous to within the dropped fraction of its contact value (with the
  // keep-right share, 0.3 of it sideways, for someone ahead).
  const double at_contact = params.drive_factor * params.social_strength / params.social_range;
  EXPECT_LT(push(b_max - 1e-6, 0.0), 1.001e-3 * std::hypot(1.0, params.keep_right) * at_contact);
  // Someone walking at you at 1.3 m/s is felt from further away (HM95's ellipse).
  EXPECT_GT(push(b_max + 0.5, -1.3), 0.0);
  EXPECT_EQ(push(b_max + 0.5, +1.3), 0.0);  // walking away
}

TEST(SocialForceModelTest, StepsCellListsMatchTheSumOverEverything) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> pos(0.0, 40.0), unit(-1.0, 1.0), len(0.2, 8.0);
  std::vector<Walker> walkers(80);
  for (auto& w : walkers) {
    w.position = {pos(rng), pos(rng) / 4.0};  // a dense band: many within the cutoff
    w.velocity = {unit(rng) * 0.3, unit(rng) * 0.3};
    w.target = {pos(rng), pos(rng) / 4.0};
    w.desired_speed = 1.2;
  }
  std::vector<WallSegment> walls;
  for (int k = 0; k < 60; ++k) {
    const Eigen::Vector2d a(pos(rng), pos(rng) / 4.0);
    const Eigen::Vector2d b = a + len(rng) * Eigen::Vector2d(unit(rng), unit(rng)).normalized();
    // Loose segments and obstacles of 1-4 segments, interleaved so that an obstacle's first
    // segment may be far from a walker its later ones reach.
    walls.push_back({a, b, k % 3 == 0 ? -1 : k % 7});
  }
  const std::vector<DiscObstacle> discs = {{{20.0, 5.0}, {0.2, 0.0}, 0.3}};
  SocialForceModel sfm;
  std::vector<Eigen::Vector2d> expected;
  for (std::size_t i = 0; i < walkers.size(); ++i)
    expected.push_back(sfm.CalcAcceleration(i, walkers, discs, walls));
  const double dt = 1e-4;  // small enough that no speed is clipped
  std::vector<Walker> stepped = walkers;
  sfm.Step(&stepped, discs, walls, dt);
  int pushed_by_walls = 0;
  for (std::size_t i = 0; i < walkers.size(); ++i) {
    const Eigen::Vector2d v = walkers[i].velocity + expected[i] * dt;
    EXPECT_EQ(stepped[i].velocity.x(), v.x()) << "walker " << i;
    EXPECT_EQ(stepped[i].velocity.y(), v.y()) << "walker " << i;
    const double gap = [&] {
      double g = 1e9;
      for (const auto& s : walls)
        g = std::min(g,
                     (walkers[i].position - ClosestPointOnSegment(walkers[i].position, s)).norm());
      return g;
    }();
    pushed_by_walls += gap < 3.0;
  }
  EXPECT_GT(pushed_by_walls, 20);  // walls did act
}

// A person not yet set off is a walker the others meet as any other, but no force moves them:
// their own sum is skipped (a group waiting for its alarm was a twelfth of the crowd bench's
// social force cost, summed and thrown away).
TEST(SocialForceModelTest, AHeldWalkerPushesTheOthersButIsNotMoved) {
  std::vector<Walker> walkers(3);
  walkers[0].position = {0.0, 0.0};
  walkers[1].position = {0.6, 0.05};  // near enough to push and be pushed
  walkers[2].position = {-0.5, 0.4};
  for (auto& w : walkers) {
    w.target = {5.0, 0.0};
    w.desired_speed = 1.2;
  }
  SocialForceModel sfm;
  const WallCells no_walls(std::vector<WallSegment>{});
  const std::vector<Eigen::Vector2d> free = sfm.CalcAccelerations(walkers, {}, no_walls, {});
  walkers[1].held = true;
  const std::vector<Eigen::Vector2d> held = sfm.CalcAccelerations(walkers, {}, no_walls, {});
  EXPECT_GT(free[1].norm(), 0.1);
  EXPECT_EQ(held[1], Eigen::Vector2d::Zero());
  // The others' sums are unchanged, bit for bit: the held walker still acts on them.
  for (const std::size_t i : {0u, 2u}) {
    EXPECT_EQ(held[i].x(), free[i].x()) << i;
    EXPECT_EQ(held[i].y(), free[i].y()) << i;
  }
  walkers[1].velocity = {0.3, 0.0};
  std::vector<Walker> stepped = walkers;
  sfm.Step(&stepped, {}, no_walls, {}, 0.01);
  EXPECT_EQ(stepped[1].position, walkers[1].position);
  EXPECT_EQ(stepped[1].velocity, walkers[1].velocity);
  EXPECT_NE(stepped[0].position, walkers[0].position);
}

TEST(SocialForceModelTest, CellListsMatchTheSumOverEverythingWhateverTheSpeedsAndSpread) {
  // Fast walkers reach farther (their step ellipse) than slow ones: each cell lists everyone
  // whose own reach overlaps it. A crowd spread over more cells than the grid holds densely
  // (two walkers 2e7 m apart) is summed as one cell: the same sums, only slower.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> pos(0.0, 12.0), unit(-1.0, 1.0);
  for (const double far : {0.0, 1e7}) {
    std::vector<Walker> walkers(60);
    for (std::size_t i = 0; i < walkers.size(); ++i) {
      Walker& w = walkers[i];
      w.position = {pos(rng), pos(rng) / 3.0};
      const double speed = i % 4 == 0 ? 1.6 : 0.2;  // a quarter at a run
      w.velocity = speed * Eigen::Vector2d(unit(rng), unit(rng)).normalized();
      w.target = {pos(rng), pos(rng) / 3.0};
      w.desired_speed = 1.2;
    }
    if (far > 0.0) {
      walkers.front().position.x() = -far;
      walkers.back().position.x() = far;
    }
    SocialForceModel sfm;
    const std::vector<Eigen::Vector2d> grid =
        sfm.CalcAccelerations(walkers, {}, WallCells(std::vector<WallSegment>{}), {});
    int pushed = 0;
    for (std::size_t i = 0; i < walkers.size(); ++i) {
      const Eigen::Vector2d all = sfm.CalcAcceleration(i, walkers, {}, {});
      EXPECT_EQ(grid[i].x(), all.x()) << "walker " << i << ", spread " << far;
      EXPECT_EQ(grid[i].y(), all.y()) << "walker " << i << ", spread " << far;
      Walker alone = walkers[i];
      pushed += (all - SocialForceModel().CalcAcceleration(0, {alone}, {}, {})).norm() > 1e-3;
    }
    EXPECT_GT(pushed, 30) << "the walkers did push each other";
  }
}

TEST(SocialForceModelTest, BinnedFixedWallsAndMovingOnesStepAsAllTheWallsTogether) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> pos(0.0, 30.0), unit(-1.0, 1.0), len(0.2, 6.0);
  std::vector<Walker> walkers(60);
  for (auto& w : walkers) {
    w.position = {pos(rng), pos(rng) / 3.0};
    w.velocity = {unit(rng) * 0.5, unit(rng) * 0.5};
    w.target = {pos(rng), pos(rng) / 3.0};
  }
  auto segments = [&](int n, bool obstacles) {
    std::vector<WallSegment> out;
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector2d a(pos(rng), pos(rng) / 3.0);
      out.push_back({a, a + len(rng) * Eigen::Vector2d(unit(rng), unit(rng)).normalized(),
                     obstacles && k % 3 ? k % 5 : -1});
    }
    return out;
  };
  const std::vector<WallSegment> fixed = segments(50, true), leaves = segments(4, false);
  std::vector<WallSegment> together = fixed;
  together.insert(together.end(), leaves.begin(), leaves.end());
  const std::vector<DiscObstacle> discs = {{{15.0, 5.0}, {0.0, 0.3}, 0.25}};
  SocialForceModel sfm;
  std::vector<Walker> a = walkers, b = walkers;
  const WallCells cells(fixed);
  for (int step = 0; step < 50; ++step) {
    sfm.Step(&a, discs, together, 1.0 / 240);
    sfm.Step(&b, discs, cells, leaves, 1.0 / 240);
  }
  double moved = 0.0;
  for (std::size_t i = 0; i < walkers.size(); ++i) {
    EXPECT_EQ(a[i].position, b[i].position) << "walker " << i;
    EXPECT_EQ(a[i].velocity, b[i].velocity) << "walker " << i;
    moved += (a[i].position - walkers[i].position).norm();
  }
  EXPECT_GT(moved, 1.0);  // they walked
}

TEST(SocialForceModelTest, SocialTermsSummedNowAddUpToTheWholeAcceleration) {
  // The split the twin uses is the same model: social terms plus the drive and contact summed
  // from the same state give CalcAccelerations (to rounding: the sums are in another order).
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> pos(0.0, 8.0), unit(-1.0, 1.0);
  std::vector<Walker> walkers(40);
  for (auto& w : walkers) {
    w.position = {pos(rng), pos(rng) / 2.0};  // dense: many touch
    w.velocity = {unit(rng), unit(rng)};
    w.target = {pos(rng), pos(rng) / 2.0};
  }
  const WallCells walls(
      {{{-1.0, -0.2}, {9.0, -0.2}, 0}, {{9.0, -0.2}, {9.0, 4.2}, 0}, {{2.0, 4.2}, {6.0, 4.2}, -1}});
  const std::vector<WallSegment> leaves = {{{4.0, 1.0}, {4.0, 2.0}}};
  const std::vector<DiscObstacle> discs = {{{3.0, 2.0}, {0.2, 0.0}, 0.25}};
  SocialForceModel sfm;
  const auto whole = sfm.CalcAccelerations(walkers, discs, walls, leaves);
  const auto social = sfm.CalcSocialAccelerations(walkers, discs, walls, leaves);
  const auto split = sfm.CalcAccelerationsWithSocial(social, walkers, discs, walls, leaves);
  ASSERT_EQ(split.size(), whole.size());
  int touching = 0;
  for (std::size_t i = 0; i < walkers.size(); ++i) {
    EXPECT_NEAR((split[i] - whole[i]).norm(), 0.0, 1e-9 * (1.0 + whole[i].norm())) << i;
    for (std::size_t j = 0; j < i; ++j) {
      touching += (walkers[i].position - walkers[j].position).norm() <
                  walkers[i].radius + walkers[j].radius;
    }
  }
  EXPECT_GT(touching, 3) << "bodies did touch: contact terms were summed";
  EXPECT_THROW(sfm.CalcAccelerationsWithSocial({}, walkers, discs, walls, leaves), InvalidArgument);
}

TEST(SocialForceModelTest, SocialTermsHeldOverStepsStayNearTermsSummedEveryStep) {
  // What the twin does with TwinConfig::crowd_social_rate_hz below the physics rate: at 60 Hz,
  // the social terms every fourth step, the drive and contact every step. Two walkers crossing near
  // a wall for 3 s end within a few centimetres of where summing every step takes them, and still
  // keep apart.
  const WallCells walls({{{-5.0, -1.0}, {5.0, -1.0}}});
  std::vector<Walker> every(2);
  every[0].position = {-3.0, 0.0};
  every[0].target = {3.0, 0.0};
  every[1].position = {3.0, 0.2};
  every[1].target = {-3.0, 0.2};
  std::vector<Walker> held = every;
  SocialForceModel sfm;
  const double dt = 1.0 / 240;
  std::vector<Eigen::Vector2d> social;
  double closest = 1e9;
  for (int step = 0; step < 720; ++step) {
    sfm.Step(&every, {}, walls, {}, dt);
    if (step % 4 == 0) social = sfm.CalcSocialAccelerations(held, {}, walls, {});
    sfm.Integrate(&held, sfm.CalcAccelerationsWithSocial(social, held, {}, walls, {}), dt);
    closest = std::min(closest, (held[0].position - held[1].position).norm());
  }
  for (std::size_t i = 0; i < every.size(); ++i) {
    EXPECT_LT((held[i].position - every[i].position).norm(), 0.05) << "walker " << i;
    EXPECT_GT(
        (every[i].position - (i == 0 ? Eigen::Vector2d(-3.0, 0.0) : Eigen::Vector2d(3.0, 0.2)))
            .norm(),
        2.0);  // they walked
  }
  EXPECT_GT(closest, every[0].radius + every[1].radius);  // no overlap
}

TEST(SocialForceModelTest, ContactIsSummedFreshUnderHeldSocialTerms) {
  // Two bodies pressed together, with social terms held from when they were apart (zero): the
  // contact still pushes them apart at once, and a body in a wall is pushed out of it.
  std::vector<Walker> walkers(2);
  walkers[0].position = {0.0, 0.0};
  walkers[1].position = {0.4, 0.0};  // radii 0.25: 0.1 m of overlap
  for (auto& w : walkers) {
    w.desired_speed = 0.0;
    w.target = w.position;
  }
  SocialForceModel sfm;
  const std::vector<Eigen::Vector2d> zero(2, Eigen::Vector2d::Zero());
  const WallCells none(std::vector<WallSegment>{});
  const auto a = sfm.CalcAccelerationsWithSocial(zero, walkers, {}, none, {});
  EXPECT_LT(a[0].x(), -1.0);
  EXPECT_GT(a[1].x(), 1.0);
  const WallCells wall({{{-1.0, 0.1}, {1.0, 0.1}}});  // 0.15 m into walker 0
  const auto b =
      sfm.CalcAccelerationsWithSocial({Eigen::Vector2d::Zero()}, {walkers[0]}, {}, wall, {});
  EXPECT_LT(b[0].y(), -1.0);
}

}  // namespace
}  // namespace egress::twin
