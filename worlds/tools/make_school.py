#!/usr/bin/env python3
"""Writes an L-shaped school, a building none of the scenarios use, for checking the brain on a
floor plan it was not tuned on (stop 67 found two faults with it). Run from the repository root:
`python3 worlds/tools/make_school.py OUT.sdf [TURN_DEG]` (default 17 degrees), then e.g.
`build/apps/egress sim run OUT.sdf --start c1_west --goal outside --time-limit 300`.

A 1.6 m corridor east (c1, y 0-1.6, x 0-16) with two classrooms north of it and a lab south;
at its east end a corridor south (c2, x 14.4-16) through mid_door to the exit. Doors of 0.9 and
1.1 m; class_2 has plates and opens into the corridor; mid_door's south button stands in its
leaf's sweep (the robot pressing it is struck: a building fault an ADA survey would flag); the
exit has a button inside only.
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_buildings import Building  # noqa: E402


def school(turn_deg):
    b = Building("egress_school", turn_deg=turn_deg)
    b.wall_x("c1_south", 0.0, 14.45, -0.05, gaps=[(5.0, 5.9)])
    b.wall_x("c1_north", 0.0, 16.05, 1.65, gaps=[(2.0, 3.1), (8.0, 8.9)])
    b.wall_y("west", -4.1, 6.1, 0.05)
    b.wall_x("rooms_north", 0.1, 16.05, 6.05)
    b.wall_y("wall_12", 1.7, 6.0, 6.55)
    b.wall_y("east", -9.1, 6.0, 16.05)
    b.wall_y("c2_west", -9.1, -0.05, 14.35)
    b.wall_x("lab_south", 0.0, 14.4, -4.05)
    b.wall_x("c2_mid", 14.4, 16.0, -4.55, gaps=[(14.75, 15.65)])
    b.wall_x("exit_wall", 14.3, 16.1, -9.05, gaps=[(14.7, 15.8)])
    b.door("class_1_door", (2.0, 1.65), "+x", 1.1, opens_ccw=True)
    b.actuator("class_1_button_corridor", (4.3, 1.6), "-y")
    b.actuator("class_1_button_room", (4.3, 1.7), "+y")
    b.door("class_2_door", (8.9, 1.65), "-x", 0.9, opens_ccw=True)
    b.actuator("class_2_plate_corridor", (7.4, 1.6), "-y", plate=True)
    b.actuator("class_2_plate_room", (7.4, 1.7), "+y", plate=True)
    b.door("lab_door", (5.0, -0.05), "+x", 0.9, opens_ccw=False)
    b.actuator("lab_button_corridor", (4.75, 0.0), "+y")
    b.actuator("lab_button_room", (4.75, -0.1), "-y")
    b.door("mid_door", (14.75, -4.55), "+x", 0.9, opens_ccw=False)
    b.actuator("mid_button_north", (15.95, -3.9), "-x")
    b.actuator("mid_button_south", (14.45, -5.2), "+x")
    b.door("exit_door", (14.7, -9.05), "+x", 1.1, opens_ccw=False)
    b.actuator("exit_button", (15.95, -8.6), "-x")
    b.frame("c1_west", 1.0, 0.8)
    b.frame("c1_middle", 7.0, 0.8)
    b.frame("c1_east", 15.2, 0.8)
    b.frame("class_1", 3.0, 4.0)
    b.frame("class_2", 9.0, 4.0)
    b.frame("lab", 6.0, -2.0)
    b.frame("c2_south", 15.2, -6.5)
    b.frame("outside", 15.2, -11.0)
    return b.sdf("egress school: an L-shaped building for checking on an unseen floor plan.")


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    if os.path.exists(out):
        sys.exit(f"{out} exists: not overwritten")
    turn = float(sys.argv[2]) if len(sys.argv) > 2 else 17.0
    with open(out, "w") as f:
        f.write(school(turn))


if __name__ == "__main__":
    main()
