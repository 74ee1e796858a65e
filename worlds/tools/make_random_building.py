#!/usr/bin/env python3
"""Writes a random corridor building, one per seed, for checking the brain on floor plans it was
never tuned on. Run from the repository root:

    python3 worlds/tools/make_random_building.py OUT_DIR SEED

writes OUT_DIR/building_SEED.sdf (and refuses to overwrite it), OUT_DIR/escort_SEED.yaml (an
evacuation of one or two rooms through their doors and the exit, the robot escorting: run it
with `egress evac study` or `egress sim run`: each group of 6-12 stands towards the back of its
room, the robot 0.8 m inside the first room's door wall) and OUT_DIR/places_SEED.txt (the building's places,
one per line, for `egress sim run OUT.sdf --start A --goal B`).

The building: a straight corridor (1.8-2.6 m wide) with one to three rooms north of it and none
to two south, each 4-6.5 m deep, with one door into the corridor (0.9-1.1 m, hinged on either
jamb, opening into the room or, in a corridor of 2.2 m or more, into the corridor), push buttons
or proximity plates on both sides (on the latch side, 0.3-0.6 m past the opening, or now and
then on the hinge side, 0.25-0.4 m from it), and an exit door in the corridor's east end opening
outwards with its actuator inside only (on the end wall beside the latch, or on a side wall
before it). The whole building is turned by 0-90 degrees, so that no wall is axis-aligned.
Every choice is drawn from the seed (Python's random.Random: the same seed, the same building).
"""

import math
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_buildings import Building  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
WALL_HALF = 0.05  # half a wall's thickness [m]


def room_row(rng, count, length=None):
    """Widths of `count` rooms side by side (4-7 m each), stretched to `length` if given."""
    widths = [rng.uniform(4.0, 7.0) for _ in range(count)]
    if length is not None and widths:
        widths[-1] += length - sum(widths)
    return widths


def random_building(seed):
    rng = random.Random(seed)
    turn = rng.uniform(0.0, 90.0)
    b = Building(f"egress_random_{seed}", turn_deg=turn)
    width = rng.uniform(1.8, 2.6)  # corridor, y in [0, width]
    north = room_row(rng, rng.randint(1, 3))
    south = room_row(rng, rng.randint(0, 2))
    length = max(sum(north), sum(south)) + rng.uniform(1.5, 3.0)  # corridor, x in [0, length]
    north = room_row(rng, len(north), length)
    south = room_row(rng, len(south), length) if south else []
    depth_n, depth_s = rng.uniform(4.0, 6.5), rng.uniform(4.0, 6.5)
    y_n = width + 2 * WALL_HALF  # the north rooms' floor starts here
    y_s = -2 * WALL_HALF  # the south rooms' floor ends here
    rooms = []  # (name, side, x0, x1)
    x = 0.0
    for k, w in enumerate(north):
        rooms.append((f"room_n{k + 1}", +1, x, x + w))
        x += w
    x = 0.0
    for k, w in enumerate(south):
        rooms.append((f"room_s{k + 1}", -1, x, x + w))
        x += w

    gaps = {+1: [], -1: []}
    doors = []  # (door name, room name, side, gap centre x)
    for name, side, x0, x1 in rooms:
        door_w = rng.choice([0.9, 1.0, 1.1])
        # Keep the exit end of the corridor free of room doors (its actuator may stand there).
        hi = min(x1, length - 1.5) - door_w - 0.9
        lo = x0 + 0.9
        if hi < lo:
            continue  # a room too narrow for a door with its actuators: no door (a store)
        g0 = rng.uniform(lo, hi)
        gaps[side].append((g0, g0 + door_w))
        wall_y = width + WALL_HALF if side > 0 else -WALL_HALF
        hinge_west = rng.random() < 0.5
        into_room = width < 2.2 or rng.random() < 0.7
        swing_north = into_room == (side > 0)
        # Leaf along +x from a west hinge: counter-clockwise takes its latch north.
        ccw = swing_north if hinge_west else not swing_north
        door = f"door_{name[5:]}"
        hinge = (g0, wall_y) if hinge_west else (g0 + door_w, wall_y)
        b.door(door, hinge, "+x" if hinge_west else "-x", door_w, opens_ccw=ccw)
        plate = rng.random() < 0.25
        kind = "plate" if plate else "button"
        latch_x = g0 + door_w if hinge_west else g0
        if rng.random() < 0.8:  # the latch side, past the opening
            off = rng.uniform(0.3, 0.6)
            ax = latch_x + off if hinge_west else latch_x - off
        else:  # the hinge side, close to it
            off = rng.uniform(0.25, 0.4)
            ax = g0 - off if hinge_west else g0 + door_w + off
        ax = min(max(ax, x0 + 0.25), x1 - 0.25)
        corridor_face = wall_y - side * WALL_HALF
        room_face = wall_y + side * WALL_HALF
        b.actuator(f"{door}_{kind}_corridor", (ax, corridor_face), "-y" if side > 0 else "+y",
                   plate=plate)
        b.actuator(f"{door}_{kind}_room", (ax, room_face), "+y" if side > 0 else "-y",
                   plate=plate)
        doors.append((door, name, side, g0 + door_w / 2))

    # Walls: the corridor's, the rooms' backs, partitions, the west and east ends.
    b.wall_x("corridor_north", 0.0, length, width + WALL_HALF, gaps=gaps[+1])
    b.wall_x("corridor_south", 0.0, length, -WALL_HALF, gaps=gaps[-1])
    top = y_n + depth_n
    bottom = y_s - depth_s if south else -2 * WALL_HALF
    b.wall_x("north_back", -2 * WALL_HALF, length + 2 * WALL_HALF, top + WALL_HALF)
    if south:
        b.wall_x("south_back", -2 * WALL_HALF, length + 2 * WALL_HALF, bottom - WALL_HALF)
    for k in range(1, len(north)):
        xk = sum(north[:k])
        b.wall_y(f"partition_n{k}", y_n, top, xk)
    for k in range(1, len(south)):
        xk = sum(south[:k])
        b.wall_y(f"partition_s{k}", bottom, y_s, xk)
    b.wall_y("west", bottom - 2 * WALL_HALF, top + 2 * WALL_HALF, -WALL_HALF)
    exit_w = min(rng.choice([1.0, 1.1, 1.2]), width - 0.9)
    e0 = width / 2 - exit_w / 2 + rng.uniform(-0.1, 0.1)
    east_x = length + WALL_HALF
    b.wall_y("east", bottom - 2 * WALL_HALF, top + 2 * WALL_HALF, east_x, gaps=[(e0, e0 + exit_w)])
    # The exit opens outwards (east). Leaf along +y from its south jamb: counter-clockwise takes
    # its latch west, so clockwise.
    b.door("exit_door", (east_x, e0), "+y", exit_w, opens_ccw=False)
    if rng.random() < 0.5:  # on the end wall, beside the latch
        b.actuator("exit_button", (length, e0 + exit_w + 0.2), "-x")
    else:  # on a side wall, before the end
        side_y = width if rng.random() < 0.5 else 0.0
        b.actuator("exit_button", (length - rng.uniform(0.6, 1.0), side_y),
                   "-y" if side_y > 0 else "+y")

    places = {"corridor_west": (0.8, width / 2), "corridor_east": (length - 1.0, width / 2),
              "exit_outside": (length + 2.5, width / 2)}
    for name, side, x0, x1 in rooms:
        yc = y_n + depth_n / 2 if side > 0 else y_s - depth_s / 2
        places[name] = ((x0 + x1) / 2, yc)
    for name, (px, py) in places.items():
        b.frame(name, px, py)
    return b, rng, rooms, doors, places, (width, y_n, y_s, depth_n, depth_s)


def escort_scenario(b, rng, rooms, doors, places, dims, sdf_name):
    """One or two rooms evacuated through their doors and the exit; the robot in the first."""
    width, y_n, y_s, depth_n, depth_s = dims
    with_door = [d for d in doors]
    rng.shuffle(with_door)
    groups = with_door[:rng.choice([1, 2])] if len(with_door) > 1 else with_door[:1]
    gx, gy = b.xy(*places["exit_outside"])
    lines = []
    for k, (door, room, side, xc) in enumerate(groups):
        x0, x1 = next((r[2], r[3]) for r in rooms if r[0] == room)
        depth = depth_n if side > 0 else depth_s
        floor = y_n if side > 0 else y_s
        # The group's centre 2 m short of the room's back wall, beside the door: its front row
        # (a grid 1 m apart) about a metre and a half from the door's wall, clear of the
        # robot's start.
        cx = min(max(xc + rng.uniform(-1.0, 1.0), x0 + 1.5), x1 - 1.5)
        cy = floor + side * max(2.5, depth - 2.0)
        sx, sy = b.xy(cx, cy)
        count = rng.randint(6, 12)
        walkers = count - 2 * (count // 6) - (count // 5)
        lines.append(f"""  - name: {room}
    behavior: evacuate
    route: [{door}, exit_door]
    start: {{x: {sx:.3f}, y: {sy:.3f}}}
    goal: {{x: {gx:.3f}, y: {gy:.3f}}}
    count: {count}
    mobility: {{walker: {walkers}, cane: {count // 6}, frame: {count // 6}, wheelchair: {count // 5}}}
    trigger: {{at: {45.0 + 20.0 * k:.1f}}}""")
    door, room, side, xc = groups[0]
    # The robot inside the first room, 0.8 m from its door's wall and 1.5 m along it.
    x0, x1 = next((r[2], r[3]) for r in rooms if r[0] == room)
    floor = y_n if side > 0 else y_s
    rx = min(max(xc + rng.choice([-1.5, 1.5]), x0 + 0.6), x1 - 0.6)
    ry = floor + side * 0.8
    wx, wy = b.xy(rx, ry)
    yaw = math.degrees(b.turn) + (-90.0 if side > 0 else 90.0)  # facing its door
    people = "\n".join(lines)
    return f"""# Generated by worlds/tools/make_random_building.py: {len(groups)} group(s) evacuated through
# their room's door and the exit, the robot escorting from the first room.
name: random building escort
world: {sdf_name}
seed: 1
time_limit: 400
robot:
  start: {{x: {wx:.3f}, y: {wy:.3f}, yaw_deg: {yaw:.1f}}}
  goal: {{place: exit_outside}}
people:
{people}
mission:
  tree: {os.path.join(REPO, "behavior", "trees", "evacuation_escort.xml")}
  blackboard: {{max_yields: "30", clear_for: "5", wait_for: "20", keep_clear: "3.5"}}
"""


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    out_dir, seed = sys.argv[1], int(sys.argv[2])
    os.makedirs(out_dir, exist_ok=True)
    sdf = os.path.join(out_dir, f"building_{seed}.sdf")
    escort = os.path.join(out_dir, f"escort_{seed}.yaml")
    listing = os.path.join(out_dir, f"places_{seed}.txt")
    for path in (sdf, escort, listing):
        if os.path.exists(path):
            sys.exit(f"{path} exists: not overwritten")
    b, rng, rooms, doors, places, dims = random_building(seed)
    with open(sdf, "w") as f:
        f.write(b.sdf(f"egress random building, seed {seed}: a corridor with rooms off it and "
                      "an exit at its east end."))
    with open(escort, "w") as f:
        f.write(escort_scenario(b, rng, rooms, doors, places, dims, os.path.basename(sdf)))
    with open(listing, "w") as f:
        f.write("\n".join(places) + "\n")


if __name__ == "__main__":
    main()
