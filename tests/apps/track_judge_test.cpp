#include "track_judge.h"

#include <gtest/gtest.h>

namespace egress::apps {
namespace {

using Judge = StandingTrackJudge;

// Two people: one standing at the origin from the start, one walking along x at 1 m/s.
std::vector<PersonSample> People(double t) {
  return {{{0.0, 0.0}, {0.0, 0.0}}, {{5.0 + t, 0.0}, {1.0, 0.0}}};
}

TEST(StandingTrackJudgeTest, CountsTracksOnSomeoneStandingStillAndThoseReadWalking) {
  Judge judge;
  // The first second someone stands still is not yet counted (a track's velocity settles).
  for (double t = 0.0; t < Judge::kStandingForSec; t += 0.1)
    judge.Step(t, 0.0, 0.0, {{{0.1, 0.0}, {0.5, 0.0}}}, People(t));
  EXPECT_EQ(judge.counts().still_samples, 0);
  const double t = 2.0;
  // A track on the standing person reading 0.5 m/s walks; one reading 0.1 m/s does not; one on
  // the walker, or on nobody within kMatchM, is not counted.
  judge.Step(t, 0.0, 0.0,
             {{{0.1, 0.0}, {0.5, 0.0}},
              {{-0.2, 0.1}, {0.1, 0.0}},
              {{5.0 + t, 0.1}, {1.0, 0.0}},
              {{0.0, Judge::kMatchM + 0.01}, {0.5, 0.0}}},
             People(t));
  EXPECT_EQ(judge.counts().still_samples, 2);
  EXPECT_EQ(judge.counts().still_walking, 1);
  EXPECT_EQ(judge.counts().moving_samples, 0);
  // The robot driving, or turning on the spot: the moving column.
  judge.Step(t + 0.1, 0.3, 0.0, {{{0.1, 0.0}, {0.5, 0.0}}}, People(t + 0.1));
  judge.Step(t + 0.2, 0.0, -0.4, {{{0.1, 0.0}, {0.0, 0.0}}}, People(t + 0.2));
  EXPECT_EQ(judge.counts().moving_samples, 2);
  EXPECT_EQ(judge.counts().moving_walking, 1);
  EXPECT_EQ(judge.counts().still_samples, 2);
}

TEST(StandingTrackJudgeTest, SomeoneWhoStopsStandsStillOnlyAfterTheSettlingTime) {
  Judge judge;
  const std::vector<PersonSample> track{{{0.0, 0.0}, {0.6, 0.0}}};
  judge.Step(0.0, 0.0, 0.0, track, {{{0.0, 0.0}, {1.0, 0.0}}});  // walking
  judge.Step(0.5, 0.0, 0.0, track, {{{0.0, 0.0}, {0.0, 0.0}}});  // stopped at 0.5 s
  judge.Step(1.2, 0.0, 0.0, track, {{{0.0, 0.0}, {0.0, 0.0}}});  // 0.7 s still: lag
  EXPECT_EQ(judge.counts().still_samples, 0);
  judge.Step(1.6, 0.0, 0.0, track, {{{0.0, 0.0}, {0.0, 0.0}}});  // 1.1 s still
  EXPECT_EQ(judge.counts().still_samples, 1);
  EXPECT_EQ(judge.counts().still_walking, 1);
  judge.Step(1.7, 0.0, 0.0, track, {{{0.0, 0.0}, {0.3, 0.0}}});  // walks again
  judge.Step(2.0, 0.0, 0.0, track, {{{0.0, 0.0}, {0.0, 0.0}}});
  EXPECT_EQ(judge.counts().still_samples, 1);
}

TEST(StandingTrackJudgeTest, CountsAddUp) {
  StandingReadWalking a{4, 1, 10, 2};
  a += StandingReadWalking{1, 1, 5, 0};
  EXPECT_EQ(a.moving_samples, 5);
  EXPECT_EQ(a.moving_walking, 2);
  EXPECT_EQ(a.still_samples, 15);
  EXPECT_EQ(a.still_walking, 2);
}

}  // namespace
}  // namespace egress::apps
