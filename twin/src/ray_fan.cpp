#include "ray_fan.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace egress::twin::world_detail {
namespace {

// Bearings as a "diamond angle": a monotone stand-in for the angle round the circle, in [0, 4)
// (a quarter turn each 1), without atan2's cost; a half turn is 2 wherever it starts.
constexpr double kTurn = 4.0;

double PseudoBearing(const Eigen::Vector2d& d) {
  const double x = d.x(), y = d.y();
  const double sum = std::abs(x) + std::abs(y);
  if (!(sum > 0.0)) return 0.0;  // zero or not finite: any bin (those rays meet the all-bin boxes)
  if (y >= 0.0) return x >= 0.0 ? y / sum : 1.0 - x / sum;
  return x < 0.0 ? 2.0 - y / sum : 3.0 + x / sum;
}

long BinOf(double bearing) {
  return std::clamp(long(std::floor(bearing * (double(RayFan::kBins) / kTurn))), 0L,
                    long(RayFan::kBins) - 1);
}

}  // namespace

void RayFan::Build(const Eigen::Vector2d& origin,
                   const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& boxes,
                   double reach) {
  origin_ = origin;
  // Each box's bins as a first bin and a count (wrapping round), then the lists by counting
  // sort, the boxes taken nearest first (ties by index): each bin comes out in that order.
  struct Span {
    long first, count;
    double near;
  };
  thread_local std::vector<Span> spans;
  thread_local std::vector<int> order;
  spans.assign(boxes.size(), Span{0, 0, 0.0});
  order.clear();
  start_.assign(std::size_t(kBins) + 1, 0);
  const bool origin_finite = origin.allFinite();
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const auto& [lo, hi] = boxes[i];
    Span& s = spans[i];
    if (!origin_finite || !lo.allFinite() || !hi.allFinite()) {
      s = {0, kBins, 0.0};
    } else {
      const Eigen::Vector2d gap = (lo - origin).cwiseMax(origin - hi).cwiseMax(0.0);
      s.near = gap.norm();
      if (s.near > reach) continue;  // count 0: in no bin
      // A box this near (or holding the origin) spans half the bearings or more: all of them.
      constexpr double kHoldsOriginM = 1e-6;
      if (s.near <= kHoldsOriginM) {
        s = {0, kBins, 0.0};
      } else {
        // The corners' bearings relative to the first's: a box clear of the origin spans less
        // than a half turn, so the least and greatest of them bound its bearings, whatever the
        // wrap.
        const std::array<Eigen::Vector2d, 4> corners{lo, hi, Eigen::Vector2d(lo.x(), hi.y()),
                                                     Eigen::Vector2d(hi.x(), lo.y())};
        const double b0 = PseudoBearing(corners[0] - origin);
        double least = 0.0, greatest = 0.0;
        for (std::size_t c = 1; c < corners.size(); ++c) {
          const double rel = std::remainder(PseudoBearing(corners[c] - origin) - b0, kTurn);
          least = std::min(least, rel);
          greatest = std::max(greatest, rel);
        }
        double from = b0 + least;
        if (from < 0.0) from += kTurn;
        if (from >= kTurn) from -= kTurn;
        // A bin either side more, for the rounding of the bearings (a ray's and the corners').
        const long count = long(std::ceil((greatest - least) * (double(kBins) / kTurn))) + 3;
        s = {BinOf(from) - 1, std::min<long>(count, kBins), s.near};
      }
    }
    order.push_back(int(i));
    for (long k = 0; k < s.count; ++k)
      ++start_[std::size_t(((s.first + k) % kBins + kBins) % kBins) + 1];
  }
  for (std::size_t b = 1; b < start_.size(); ++b)
    start_[b] += start_[b - 1];
  entries_.resize(start_.back());
  std::sort(order.begin(), order.end(), [&](int x, int y) {
    return std::pair(spans[std::size_t(x)].near, x) < std::pair(spans[std::size_t(y)].near, y);
  });
  thread_local std::vector<std::size_t> fill;
  fill.assign(start_.begin(), start_.end() - 1);
  for (const int i : order) {
    const Span& s = spans[std::size_t(i)];
    for (long k = 0; k < s.count; ++k)
      entries_[fill[std::size_t(((s.first + k) % kBins + kBins) % kBins)]++] = {s.near, i};
  }
}

long RayFan::Bin(const Eigen::Vector2d& d) {
  return BinOf(PseudoBearing(d));
}

std::span<const RayFan::Entry> RayFan::Along(long bin) const {
  if (start_.empty()) return {};
  const std::size_t b = std::size_t(std::clamp(bin, 0L, long(kBins) - 1));
  return {entries_.data() + start_[b], entries_.data() + start_[b + 1]};
}

}  // namespace egress::twin::world_detail
