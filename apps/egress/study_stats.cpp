#include "study_stats.h"

#include <algorithm>
#include <cmath>

namespace egress::apps {

MedianCi CalcMedianCi(std::vector<double> v) {
  MedianCi out;
  if (v.empty()) return out;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  out.median = n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
  // Ranks n/2 -+ 1.96 sqrt(n)/2 (the normal approximation of the binomial), rounded outwards,
  // the lower one a rank further out (it errs on the wide side).
  const double half = 1.96 * std::sqrt(double(n)) / 2;
  const long lo = std::max(0L, long(std::floor(double(n) / 2 - half)) - 1);
  const long hi = std::min(long(n) - 1, long(std::ceil(double(n) / 2 + half)));
  out.low = v[std::size_t(lo)];
  out.high = v[std::size_t(hi)];
  return out;
}

double CalcQuantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double rank = std::clamp(q, 0.0, 1.0) * double(v.size() - 1);
  const std::size_t below = std::size_t(std::floor(rank));
  const std::size_t above = std::min(below + 1, v.size() - 1);
  return v[below] + (rank - double(below)) * (v[above] - v[below]);
}

PairedDifference CalcPairedDifference(const std::map<std::uint64_t, double>& a,
                                      const std::map<std::uint64_t, double>& b, double tie) {
  PairedDifference out;
  std::vector<double> d;
  for (const auto& [seed, value] : b) {
    const auto other = a.find(seed);
    if (other == a.end()) continue;
    d.push_back(value - other->second);
    if (d.back() < -tie) ++out.lower;
    if (d.back() > tie) ++out.higher;
    out.mean += d.back();
  }
  out.pairs = int(d.size());
  if (d.empty()) return out;
  out.mean /= double(d.size());
  out.diff = CalcMedianCi(std::move(d));
  return out;
}

}  // namespace egress::apps
