#include "study_stats.h"

#include <gtest/gtest.h>

namespace egress::apps {
namespace {

TEST(CalcMedianCiTest, TheMedianOfAnOddAndAnEvenCountAndAnIntervalAroundIt) {
  const MedianCi odd = CalcMedianCi({5.0, 1.0, 3.0});
  EXPECT_DOUBLE_EQ(odd.median, 3.0);
  const std::vector<double> twenty = [] {
    std::vector<double> v;
    for (int i = 20; i >= 1; --i)
      v.push_back(double(i));
    return v;
  }();
  const MedianCi even = CalcMedianCi(twenty);
  EXPECT_DOUBLE_EQ(even.median, 10.5);
  // 20 values: ranks 10 -+ 4.4 widened to whole ranks and by one: the 5th and the 16th of 1..20
  // (the exact binomial 95 % interval is the 6th to the 15th: this one errs on the wide side).
  EXPECT_DOUBLE_EQ(even.low, 5.0);
  EXPECT_DOUBLE_EQ(even.high, 16.0);
  EXPECT_DOUBLE_EQ(CalcMedianCi({}).median, 0.0);
}

TEST(CalcQuantileTest, TheMedianOfAnEvenCountIsTheMeanOfTheMiddleTwoAndQuantilesInterpolate) {
  // The batch took the upper middle value as the median: over 100 trials whose middle two were
  // 0.756 and 0.808 it reported 0.81 where the median is 0.78.
  std::vector<double> v;
  for (int i = 0; i < 50; ++i)
    v.push_back(0.75);
  for (int i = 0; i < 50; ++i)
    v.push_back(0.81);
  EXPECT_DOUBLE_EQ(CalcQuantile(v, 0.5), 0.78);
  // 1..11 in any order: rank q (n - 1) between order statistics.
  const std::vector<double> eleven{11, 3, 7, 1, 9, 5, 2, 10, 4, 8, 6};
  EXPECT_DOUBLE_EQ(CalcQuantile(eleven, 0.5), 6.0);
  EXPECT_DOUBLE_EQ(CalcQuantile(eleven, 0.1), 2.0);
  EXPECT_DOUBLE_EQ(CalcQuantile(eleven, 0.95), 10.5);
  EXPECT_DOUBLE_EQ(CalcQuantile(eleven, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(CalcQuantile(eleven, 1.0), 11.0);
  EXPECT_DOUBLE_EQ(CalcQuantile({4.0}, 0.9), 4.0);
  EXPECT_DOUBLE_EQ(CalcQuantile({}, 0.5), 0.0);
}

TEST(CalcPairedDifferenceTest, ASmallShiftHiddenByTheSeedsSpreadShowsInThePairs) {
  // Seeds whose times spread over 40 s; the second condition is 1 s quicker on every seed but
  // two (one a tie, one much slower).
  std::map<std::uint64_t, double> a, b;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    a[seed] = 40.0 + 2.0 * double(seed);
    b[seed] = a[seed] - 1.0;
  }
  b[7] = a[7] + 0.1;   // a tie
  b[9] = a[9] + 20.0;  // slower
  std::vector<double> va, vb;
  for (const auto& [s, t] : a)
    va.push_back(t);
  for (const auto& [s, t] : b)
    vb.push_back(t);
  // The two conditions' own intervals overlap ...
  EXPECT_LT(CalcMedianCi(va).low, CalcMedianCi(vb).high);
  EXPECT_LT(CalcMedianCi(vb).low, CalcMedianCi(va).high);
  // ... while their paired difference is clearly below zero.
  const PairedDifference p = CalcPairedDifference(a, b, 0.15);
  EXPECT_EQ(p.pairs, 20);
  EXPECT_EQ(p.lower, 18);
  EXPECT_EQ(p.higher, 1);
  EXPECT_DOUBLE_EQ(p.diff.median, -1.0);
  EXPECT_LT(p.diff.high, 0.0);
  EXPECT_NEAR(p.mean, (18 * -1.0 + 0.1 + 20.0) / 20.0, 1e-12);
}

TEST(CalcPairedDifferenceTest, OnlySeedsRunUnderBothConditionsArePaired) {
  const std::map<std::uint64_t, double> a = {{1, 10.0}, {2, 20.0}, {3, 30.0}};
  const std::map<std::uint64_t, double> b = {{2, 25.0}, {3, 28.0}, {4, 1.0}};
  const PairedDifference p = CalcPairedDifference(a, b, 0.15);
  EXPECT_EQ(p.pairs, 2);
  EXPECT_EQ(p.lower, 1);
  EXPECT_EQ(p.higher, 1);
  EXPECT_DOUBLE_EQ(p.diff.median, 1.5);
  EXPECT_EQ(CalcPairedDifference(a, {}, 0.15).pairs, 0);
}

}  // namespace
}  // namespace egress::apps
