#pragma once
/// @file
/// Mobility classes of evacuees: how fast each walks on the level, how much room they take, and
/// whether and how quickly they can operate an ADA door actuator (a push button or a proximity
/// plate beside the door).
///
/// Speeds: mean horizontal speeds (± one standard deviation, clipped to the observed ranges)
/// measured by Boyce, Shields & Silcock, "Toward the characterization of building occupancies
/// for fire safety engineering: capabilities of disabled people moving horizontally and on an
/// incline", Fire Technology 35(1), 1999, pp. 35-50 (reproduced in the SFPE Handbook of Fire
/// Protection Engineering, the chapter on people movement): no disability 1.24 m/s, walking
/// stick 0.81, walking frame or rollator 0.57, manual wheelchair (self-propelled) 0.69. Boyce et
/// al. give no level speed for a wheelchair pushed by a helper; we take the helper's, slowed to
/// 1.0 m/s (an assumption, marked as such below).
/// Sizes: a standing adult's body ellipse 0.46 x 0.33 m (Fruin, "Pedestrian Planning and
/// Design", 1971) as a disc of radius 0.23 m; a frame 0.6 m wide; a manual wheelchair about
/// 0.66 m wide (typical adult chairs are 0.6-0.7 m; the ADA's 0.76 x 1.22 m is the clear floor
/// space it needs, ADA Standards 2010 §305.3), pushed a little wider with the helper's elbows.
/// The disc model takes the width for the diameter: queues and doorways are about widths.
/// Operating an actuator (reach and time): modelling assumptions, not measured data — an ADA
/// actuator is mounted within a wheelchair user's reach (ADA §308), but reaching one beside the
/// door means manoeuvring the chair alongside it, which some users cannot do in a queue.

#include <string>
#include <string_view>
#include <vector>

#include "egress/twin/scenario.h"

namespace egress::twin {

struct MobilityClass {
  std::string name;           ///< As scenario files name it.
  Range speed;                ///< Desired walking speed [m/s], drawn uniformly.
  double radius{0.23};        ///< Body disc [m].
  double operate_share{1.0};  ///< Share of the class able to operate an actuator [0, 1].
  Range operate_time;         ///< From standing at the actuator to the door triggering [s].
};

/// Every class: walker, cane, frame, wheelchair, wheelchair_pushed.
const std::vector<MobilityClass>& MobilityClasses();
/// The class named `name`, or nullptr.
const MobilityClass* FindMobilityClass(std::string_view name);
/// The class names, comma-separated (for error messages).
std::string MobilityClassNames();

}  // namespace egress::twin
