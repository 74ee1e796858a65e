#pragma once
#include "cross_doorway.h"

namespace egress::twin::people {

/// A group of `count` people crossing the doorway together (an evacuation), each as
/// CrossDoorway, starting 0.3 s apart.
class Evacuate final : public CrossDoorway {
 public:
  int GroupSize(const PersonSpec& spec) const override { return spec.count; }
};

}  // namespace egress::twin::people
