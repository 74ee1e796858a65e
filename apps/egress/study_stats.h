#pragma once
// Order statistics for `egress evac study` and `egress sim batch`: a median with its 95 %
// interval, a quantile, and the paired difference between two conditions run on the same seeds
// (what one buys over the other).

#include <cstdint>
#include <map>
#include <vector>

namespace egress::apps {

// A median and its 95 % interval from the order statistics (binomial, distribution-free).
struct MedianCi {
  double median{0.0};
  double low{0.0};
  double high{0.0};
};
// Of `v` (any order; empty: all zero).
MedianCi CalcMedianCi(std::vector<double> v);

// The q-quantile (0 <= q <= 1) of `v` (any order; empty: 0), interpolated linearly between the
// order statistics at rank q (n - 1), as numpy and R's default do: q = 0.5 is the median (of an
// even count, the mean of the middle two), not the upper of the two.
double CalcQuantile(std::vector<double> v, double q);

// `b - a` per seed run under both conditions: the effect of the change from a to b with the
// variation between seeds (how fast that seed's people walk, where they stand) taken out. Two
// conditions' own intervals overlap long before their paired difference stops excluding zero.
struct PairedDifference {
  int pairs{0};      // seeds run under both conditions
  int lower{0};      // seeds where b's value is below a's (by more than the tie tolerance)
  int higher{0};     // seeds where it is above
  MedianCi diff;     // of b - a over the pairs [the values' unit]
  double mean{0.0};  // of b - a
};
// `tie` [the values' unit]: differences within it count as neither lower nor higher.
PairedDifference CalcPairedDifference(const std::map<std::uint64_t, double>& a,
                                      const std::map<std::uint64_t, double>& b, double tie);

}  // namespace egress::apps
