#pragma once
// Greedy data association shared by the trackers: every (track, detection) pair within the gate,
// nearest first, each track and each detection used at most once.

#include <algorithm>
#include <cstddef>
#include <tuple>
#include <utility>
#include <vector>

namespace egress::perception::internal {

struct Association {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;  ///< (track, detection), nearest first.
  std::vector<bool> track_matched;
  std::vector<bool> detection_matched;
};

/// `distance(t, k)` between track t and detection k [m]; +inf (or anything beyond `gate`) never
/// pairs them. Ties go to the lower track, then the lower detection index.
template <typename Distance>
Association AssociateNearestFirst(std::size_t tracks, std::size_t detections, double gate,
                                  const Distance& distance) {
  std::vector<std::tuple<double, std::size_t, std::size_t>> candidates;
  for (std::size_t t = 0; t < tracks; ++t) {
    for (std::size_t k = 0; k < detections; ++k) {
      const double d = distance(t, k);
      if (d <= gate) candidates.emplace_back(d, t, k);
    }
  }
  std::sort(candidates.begin(), candidates.end());
  Association a{{}, std::vector<bool>(tracks, false), std::vector<bool>(detections, false)};
  for (const auto& [d, t, k] : candidates) {
    if (a.track_matched[t] || a.detection_matched[k]) continue;
    a.track_matched[t] = a.detection_matched[k] = true;
    a.pairs.emplace_back(t, k);
  }
  return a;
}

}  // namespace egress::perception::internal
