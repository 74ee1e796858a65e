#!/usr/bin/env python3
"""Writes the SDF worlds of the generated test buildings (worlds/clinic, worlds/atrium).

Run from the repository root: `python3 worlds/tools/make_buildings.py`. The SDF files are
committed; this script is how they were drawn (walls as boxes with door gaps, hinged doors,
buttons and plates as thin boxes on wall faces, places as world <frame>s). A whole building can
be turned by an angle about the origin, so that no wall, door or actuator is axis-aligned.
"""

import math
import os
import sys

WALL_T = 0.1     # wall thickness [m]
WALL_H = 2.0     # wall height [m]
LEAF_T = 0.04    # door leaf thickness [m]
JAMB_GAP = 0.025  # hinge and latch gaps to the jambs [m]


class Building:
    def __init__(self, name, turn_deg=0.0):
        self.name = name
        self.turn = math.radians(turn_deg)
        self.models = []
        self.frames = []

    def xy(self, x, y):
        c, s = math.cos(self.turn), math.sin(self.turn)
        return c * x - s * y, s * x + c * y

    def pose(self, x, y, z, yaw):
        px, py = self.xy(x, y)
        return f"{px:.4f} {py:.4f} {z:.4f} 0 0 {yaw + self.turn:.6f}"

    def box(self, name, x, y, z, sx, sy, sz, yaw=0.0, colour="0.75 0.75 0.72 1"):
        self.models.append(
            f"""    <model name="{name}">
      <static>true</static>
      <pose>{self.pose(x, y, z, yaw)}</pose>
      <link name="link">
        <collision name="collision"><geometry><box><size>{sx:.4f} {sy:.4f} {sz:.4f}</size></box></geometry></collision>
        <visual name="visual"><geometry><box><size>{sx:.4f} {sy:.4f} {sz:.4f}</size></box></geometry>
          <material><ambient>{colour}</ambient><diffuse>{colour}</diffuse></material></visual>
      </link>
    </model>""")

    def wall_x(self, name, x0, x1, y, gaps=()):
        """A wall along x from x0 to x1 centred on y, with door gaps (a, b)."""
        cuts = [x0] + [v for g in sorted(gaps) for v in g] + [x1]
        for k in range(0, len(cuts), 2):
            a, b = cuts[k], cuts[k + 1]
            if b - a > 1e-6:
                self.box(f"{name}_{k // 2}", (a + b) / 2, y, WALL_H / 2, b - a, WALL_T, WALL_H)

    def wall_y(self, name, y0, y1, x, gaps=()):
        cuts = [y0] + [v for g in sorted(gaps) for v in g] + [y1]
        for k in range(0, len(cuts), 2):
            a, b = cuts[k], cuts[k + 1]
            if b - a > 1e-6:
                self.box(f"{name}_{k // 2}", x, (a + b) / 2, WALL_H / 2, WALL_T, b - a, WALL_H)

    def door(self, name, hinge, leaf_dir, width, opens_ccw, glass=False):
        """A hinged door: hinge jamb at `hinge`, the closed leaf along `leaf_dir` (one of
        +x, -x, +y, -y) for `width` (the opening), turning counter-clockwise (seen from above)
        to open when `opens_ccw`."""
        yaw = {"+y": 0.0, "-x": math.pi / 2, "-y": math.pi, "+x": -math.pi / 2}[leaf_dir]
        dx, dy = {"+y": (0, 1), "-y": (0, -1), "+x": (1, 0), "-x": (-1, 0)}[leaf_dir]
        hx, hy = hinge[0] + dx * JAMB_GAP, hinge[1] + dy * JAMB_GAP
        leaf = width - 2 * JAMB_GAP
        lower, upper = (0.0, 1.57) if opens_ccw else (-1.57, 0.0)
        colour = "0.6 0.8 0.9 0.4" if glass else "0.55 0.35 0.2 1"
        self.models.append(
            f"""    <model name="{name}">
      <pose>{self.pose(hx, hy, 1.0, yaw)}</pose>
      <link name="frame"/>
      <link name="leaf">
        <inertial><mass>40.0</mass><inertia><ixx>13.4</ixx><iyy>13.4</iyy><izz>12.0</izz></inertia></inertial>
        <collision name="leaf_collision"><pose>0 {leaf / 2:.4f} 0 0 0 0</pose><geometry><box><size>{LEAF_T} {leaf:.4f} 2.0</size></box></geometry></collision>
        <visual name="leaf_visual"><pose>0 {leaf / 2:.4f} 0 0 0 0</pose><geometry><box><size>{LEAF_T} {leaf:.4f} 2.0</size></box></geometry>
          <material><ambient>{colour}</ambient><diffuse>{colour}</diffuse></material></visual>
      </link>
      <joint name="hinge" type="revolute">
        <parent>frame</parent>
        <child>leaf</child>
        <axis>
          <xyz>0 0 1</xyz>
          <limit><lower>{lower}</lower><upper>{upper}</upper><velocity>1.0</velocity><effort>60</effort></limit>
          <dynamics><damping>2.0</damping><friction>0.0</friction></dynamics>
        </axis>
      </joint>
      <joint name="fixed_to_world" type="fixed"><parent>world</parent><child>frame</child></joint>
    </model>""")

    def actuator(self, name, face, facing, z=1.0, plate=False):
        """A button (0.1 x 0.1, 2 cm proud) or plate (0.15 x 0.15) on the wall face at `face`
        (x, y on the face plane), facing `facing` (+x, -x, +y, -y)."""
        size = 0.15 if plate else 0.1
        nx, ny = {"+x": (1, 0), "-x": (-1, 0), "+y": (0, 1), "-y": (0, -1)}[facing]
        cx, cy = face[0] + nx * 0.01, face[1] + ny * 0.01
        sx, sy = (0.02, size) if nx else (size, 0.02)
        colour = "0.1 0.7 0.2 1" if plate else "0.1 0.2 0.9 1"
        self.box(name, cx, cy, z, sx, sy, size, colour=colour)

    def frame(self, name, x, y, yaw_deg=None):
        yaw = math.radians(yaw_deg) if yaw_deg is not None else 0.0
        self.frames.append(
            f'    <frame name="{name}"><pose>{self.pose(x, y, 0.0, yaw)}</pose></frame>')

    def sdf(self, comment):
        body = "\n".join(self.models + self.frames)
        return f"""<?xml version="1.0" ?>
<!-- {comment} Generated by worlds/tools/make_buildings.py. -->
<sdf version="1.7">
  <world name="{self.name}">
    <physics type="ode"><max_step_size>0.004</max_step_size><real_time_update_rate>250</real_time_update_rate></physics>
    <model name="ground_plane">
      <static>true</static>
      <link name="link">
        <collision name="collision"><geometry><plane><normal>0 0 1</normal><size>80 80</size></plane></geometry></collision>
      </link>
    </model>
{body}
  </world>
</sdf>
"""


def clinic():
    """A long corridor (y 0-2, x 0-22) with rooms off it, turning north at its east end into a
    short corridor that leads to the exit; six doors."""
    b = Building("egress_clinic")
    # Corridor C1 and the rooms north of it (y 2.1-7): A (x 0.1-7), B (7.1-13), C (13.1-19.9).
    b.wall_x("corridor_south", 0.0, 22.1, -0.05, gaps=[(6.5, 7.5)])
    b.wall_x("corridor_north", 0.0, 19.95, 2.05, gaps=[(3.5, 4.5), (9.5, 10.5), (15.5, 16.5)])
    b.wall_y("west", -5.1, 7.1, 0.05)
    b.wall_x("rooms_north", 0.1, 19.95, 7.05)
    b.wall_y("wall_ab", 2.1, 7.0, 7.05)
    b.wall_y("wall_bc", 2.1, 7.0, 13.05)
    # Corridor C2 (x 20-22, y 2-9) north from C1's east end; the exit at its north end.
    b.wall_y("c2_west", 2.0, 9.1, 19.95)
    b.wall_y("east", -0.1, 9.1, 22.05)
    b.wall_x("c2_door", 20.0, 22.0, 2.65, gaps=[(20.5, 21.5)])
    b.wall_x("exit_wall", 19.9, 22.1, 9.05, gaps=[(20.5, 21.5)])
    # Room D south of the corridor (x 0.1-13, y -5 to -0.1).
    b.wall_x("room_d_south", 0.0, 13.1, -5.05)
    b.wall_y("room_d_east", -5.1, -0.1, 13.05)

    # door_a: push buttons both sides beside the latch, opens into room A (north: away from the
    # corridor). Hinge at x 3.5, leaf along +x; counter-clockwise takes the latch north.
    b.door("door_a", (3.5, 2.05), "+x", 1.0, opens_ccw=True)
    b.actuator("door_a_button_corridor", (4.9, 2.0), "-y")
    b.actuator("door_a_button_room", (4.9, 2.1), "+y")
    # door_b: glass, proximity plates both sides, opens into the corridor (south). Hinge at
    # x 10.5, leaf along -x; counter-clockwise takes the latch south.
    b.door("door_b", (10.5, 2.05), "-x", 1.0, opens_ccw=True, glass=True)
    b.actuator("door_b_plate_corridor", (9.0, 2.0), "-y", plate=True)
    b.actuator("door_b_plate_room", (9.0, 2.1), "+y", plate=True)
    # door_c: the button on the hinge side, 0.25 m from the hinge, both sides; opens into room
    # C (north). Hinge at x 15.5, leaf along +x.
    b.door("door_c", (15.5, 2.05), "+x", 1.0, opens_ccw=True)
    b.actuator("door_c_button_corridor", (15.25, 2.0), "-y")
    b.actuator("door_c_button_room", (15.25, 2.1), "+y")
    # door_d: push buttons both sides, opens into room D (south). Hinge at x 7.5, leaf along -x:
    # clockwise takes the latch... counter-clockwise takes it south.
    b.door("door_d", (7.5, -0.05), "-x", 1.0, opens_ccw=True)
    b.actuator("door_d_button_corridor", (8.0, 0.0), "+y")
    b.actuator("door_d_button_room", (8.0, -0.1), "-y")
    # door_e: across C2 just past the corner, opening south (towards a robot coming from C1);
    # its buttons on the corridor's side walls. Hinge at x 20.5, leaf along +x; clockwise takes
    # the latch south.
    b.door("door_e", (20.5, 2.65), "+x", 1.0, opens_ccw=False)
    b.actuator("door_e_button_south", (22.0, 1.9), "-x")
    b.actuator("door_e_button_north", (20.0, 3.4), "+x")
    # exit_door: the way out, opening outwards (north); its button only inside.
    b.door("exit_door", (20.5, 9.05), "+x", 1.0, opens_ccw=True)
    b.actuator("exit_door_button", (21.85, 9.0), "-y")

    b.frame("corridor_west", 1.2, 1.0)
    b.frame("walk_west", 2.5, 0.6)
    b.frame("walk_east", 13.5, 0.6)
    b.frame("corridor_middle", 12.0, 1.0)
    b.frame("corridor_east", 21.0, 1.0)
    b.frame("room_a", 4.0, 5.0)
    b.frame("room_b", 10.0, 5.0)
    b.frame("room_c", 16.0, 5.0)
    b.frame("room_d", 7.0, -3.0)
    b.frame("post_north", 21.0, 6.5)
    b.frame("exit_outside", 21.0, 11.0)
    return b.sdf(
        "egress clinic: a corridor (y 0-2, x 0-22) with rooms A, B, C north and D south of it "
        "(door_a push; door_b glass, plates; door_c push, button on the hinge side; door_d "
        "push), turning north at x 20-22 through door_e (just past the corner, opening towards "
        "the corridor, buttons on the side walls) to the exit_door (button inside only).")


def atrium():
    """A square atrium (x, y in -2.9..2.9) with a door on each side, its four walls running on
    to the outer walls like a pinwheel: four L-shaped rooms round it, two of the pinwheel walls
    with doors (so two rooms each have two ways in); turned 30 degrees."""
    b = Building("egress_atrium", turn_deg=30.0)
    b.wall_x("outer_south", -8.1, 8.1, -8.05)
    b.wall_x("outer_north", -8.1, 8.1, 8.05, gaps=[(-0.5, 0.5)])
    b.wall_y("outer_west", -8.0, 8.0, -8.05)
    b.wall_y("outer_east", -8.0, 8.0, 8.05)
    b.wall_x("pinwheel_south", -8.0, 3.0, -2.95, gaps=[(-6.0, -5.0), (-0.5, 0.5)])
    b.wall_x("pinwheel_north", -3.0, 8.0, 2.95, gaps=[(-0.5, 0.5), (5.0, 6.0)])
    b.wall_y("pinwheel_west", -2.9, 8.0, -2.95, gaps=[(-0.5, 0.5)])
    b.wall_y("pinwheel_east", -8.0, 2.9, 2.95, gaps=[(-0.5, 0.5)])

    # The atrium's doors: push buttons both sides (south, north), plates (west: glass; east).
    b.door("atrium_south_door", (-0.5, -2.95), "+x", 1.0, opens_ccw=False)  # opens south (out)
    b.actuator("atrium_south_button_out", (0.9, -3.0), "-y")
    b.actuator("atrium_south_button_in", (0.9, -2.9), "+y")
    b.door("atrium_north_door", (0.5, 2.95), "-x", 1.0, opens_ccw=True)  # opens south (in)
    b.actuator("atrium_north_button_out", (-0.9, 3.0), "+y")
    b.actuator("atrium_north_button_in", (-0.9, 2.9), "-y")
    b.door("atrium_west_door", (-2.95, 0.5), "-y", 1.0, opens_ccw=False, glass=True)  # out
    b.actuator("atrium_west_plate_out", (-3.0, -0.95), "-x", plate=True)
    b.actuator("atrium_west_plate_in", (-2.9, -0.95), "+x", plate=True)
    b.door("atrium_east_door", (2.95, -0.5), "+y", 1.0, opens_ccw=True)  # opens west (in)
    b.actuator("atrium_east_plate_out", (3.0, 0.95), "+x", plate=True)
    b.actuator("atrium_east_plate_in", (2.9, 0.95), "-x", plate=True)
    # The pinwheel's doors: west room <-> south room, north room <-> east room.
    b.door("ring_sw_door", (-6.0, -2.95), "+x", 1.0, opens_ccw=True)  # opens north
    b.actuator("ring_sw_button_west", (-4.6, -2.9), "+y")
    b.actuator("ring_sw_button_south", (-4.6, -3.0), "-y")
    b.door("ring_ne_door", (6.0, 2.95), "-x", 1.0, opens_ccw=False)  # opens north
    b.actuator("ring_ne_plate_north", (4.6, 3.0), "+y", plate=True)
    b.actuator("ring_ne_plate_east", (4.6, 2.9), "-y", plate=True)
    # The exit in the north wall, opening out; its button only inside.
    b.door("exit_door", (-0.5, 8.05), "+x", 1.0, opens_ccw=True)
    b.actuator("exit_button", (0.9, 8.0), "-y")

    b.frame("atrium", 0.0, 0.0)
    b.frame("atrium_sw", -1.6, -1.6)
    b.frame("atrium_ne", 1.6, 1.6)
    b.frame("room_west", -6.0, 1.0)
    b.frame("room_south", -1.0, -6.0)
    b.frame("room_east", 6.0, -1.0)
    b.frame("room_north", 1.0, 6.0)
    b.frame("exit_outside", 0.0, 10.0)
    return b.sdf(
        "egress atrium: a square atrium with a door on each side (push buttons south and north, "
        "plates west (glass) and east), its walls running on to the outer walls as a pinwheel "
        "of four rooms, two of them joined by ring doors, and an exit north opening outwards; "
        "the whole building turned 30 degrees.")


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else "worlds"
    for folder, text in (("clinic", clinic()), ("atrium", atrium())):
        os.makedirs(os.path.join(root, folder), exist_ok=True)
        with open(os.path.join(root, folder, f"{folder}.sdf"), "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
