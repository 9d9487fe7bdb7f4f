"""Generates a large office building as an mjslam world (MJCF), and checks it.

    python3 sim/tools/generate_building.py --seed 1 --size 40x30 --out worlds/my_building.xml

The floor plan, in the building's own frame (inside faces of the outer walls
at x in [0, W], y in [0, H]; the whole building is then rotated by
--rotation-deg about its centre):

- `--corridors` corridors along x (--corridor-width wide) run the full width;
  `--cross-corridors` corridors along y join them and run the full height.
  Between them lie blocks of rooms.
- Each block holds one row of rooms per corridor it faces (two rows back to
  back in the middle bands). Rooms have random widths (--room-width) and
  random depths, so that their back walls, partitions and corners lie on many
  different lines, as in a real floor; the space behind a shallow room is a
  closed void (ducts, stores). Some runs of neighbouring rooms are merged into
  halls (--hall-probability).
- Every room has one door (--door-width, 0.8-0.9 m in real buildings) in its
  corridor wall, at a random place.
- Clutter: square columns at random yaw (--columns), round pillars
  (--pillars) and free-standing walls at random angles (--free-walls), placed
  in rooms and halls (halls first) clear of the tour and of the walls.
- The tour (sites tour_0, tour_1, ...) starts at the west end of the first
  corridor, drives the corridors in a serpentine, enters every room through
  its door (straight along the door's axis), drives to the room's middle,
  comes back out, and returns to the start.

Checks (a failed one is an error naming the element; nothing is written):
every door is passable by the robot (0.38 m wide, with 0.05 m a side) and its
middle is clear; the free space where the robot fits is connected: every tour
waypoint (hence every room) is reachable from the start; every waypoint and
every point of the tour's legs keeps >= 0.6 m from every obstacle, except the
legs through a door, which must pass through the door's middle; the robot's
body at the start pose is clear of every obstacle.

The world follows worlds/README.md. Python 3 standard library only; the same
arguments give the same file.
"""
import argparse
import math
import os
import random
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from world_xml import World  # noqa: E402

# The Pioneer 3-DX: 0.38 m wide; its body spans 0.47 m to 0.02 m behind the
# point h (worlds/README.md).
ROBOT_WIDTH_M = 0.38
ROBOT_BACK_M = 0.47
ROBOT_FRONT_M = 0.02
# Free space on each side of the robot that a door must leave, metres.
DOOR_SIDE_MARGIN_M = 0.05
# Clearance of every tour waypoint and leg, metres (worlds/README.md).
TOUR_CLEARANCE_M = 0.6
# Distance of the tour's door waypoints from the door's middle, along its axis.
DOOR_APPROACH_M = 0.7
# Clearance of the waypoint in a room's middle, where the robot turns, metres.
TURN_CLEARANCE_M = 1.0
# Cell of the connectivity grid, metres.
GRID_CELL_M = 0.1


class BuildingError(Exception):
    """A generated building that fails a check, or invalid arguments."""


class OptionError(BuildingError):
    """A bad option: reported as argparse reports its own (usage, exit 2)."""


class Obstacle:
    """An upright box (half extents hx, hy, yaw in degrees) or cylinder (r)."""

    def __init__(self, name, kind, cx, cy, hx=0.0, hy=0.0, yaw_deg=0.0, r=0.0):
        self.name, self.kind = name, kind
        self.cx, self.cy, self.hx, self.hy, self.yaw_deg, self.r = cx, cy, hx, hy, yaw_deg, r
        c, s = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))
        self.c, self.s = c, s
        if kind == "box":
            ex, ey = abs(c) * hx + abs(s) * hy, abs(s) * hx + abs(c) * hy
        else:
            ex = ey = r
        self.aabb = (cx - ex, cy - ey, cx + ex, cy + ey)

    def dist(self, px, py):
        """Distance from (px, py) to the footprint, 0 inside."""
        dx, dy = px - self.cx, py - self.cy
        if self.kind == "cyl":
            return max(0.0, math.hypot(dx, dy) - self.r)
        lx, ly = self.c * dx + self.s * dy, -self.s * dx + self.c * dy
        return math.hypot(max(0.0, abs(lx) - self.hx), max(0.0, abs(ly) - self.hy))


class ObstacleIndex:
    """Obstacles bucketed by their bounding boxes on a square grid, for
    distance queries up to a cap."""

    def __init__(self, obstacles, bucket_m=2.0):
        self.obstacles, self.bucket = obstacles, bucket_m
        self.cells = {}
        for k, o in enumerate(obstacles):
            x0, y0, x1, y1 = o.aabb
            for i in range(math.floor(x0 / bucket_m), math.floor(x1 / bucket_m) + 1):
                for j in range(math.floor(y0 / bucket_m), math.floor(y1 / bucket_m) + 1):
                    self.cells.setdefault((i, j), []).append(k)

    def nearest(self, px, py, cap):
        """(distance, obstacle name) of the nearest obstacle, or (cap, None)
        when none is closer than cap."""
        best, name, seen = cap, None, set()
        b = self.bucket
        for i in range(math.floor((px - cap) / b), math.floor((px + cap) / b) + 1):
            for j in range(math.floor((py - cap) / b), math.floor((py + cap) / b) + 1):
                for k in self.cells.get((i, j), ()):
                    if k in seen:
                        continue
                    seen.add(k)
                    d = self.obstacles[k].dist(px, py)
                    if d < best:
                        best, name = d, self.obstacles[k].name
        return best, name


class Room:
    """A room or hall: interior x in [x0, x1], y in [y0, y1]; its door's
    middle (dx, dy) with the unit axis (0, ay) pointing into the room."""

    def __init__(self, name, x0, x1, y0, y1, door_x, door_y, axis_y, hall):
        self.name, self.x0, self.x1, self.y0, self.y1 = name, x0, x1, y0, y1
        self.door_x, self.door_y, self.axis_y, self.hall = door_x, door_y, axis_y, hall


class Building:
    """A generated floor in its own frame: obstacles, rooms with their doors,
    the tour and the legs of the tour that pass doors."""

    def __init__(self, args):
        self.args = args
        self.obstacles = []
        self.rooms = []
        self.tour = []
        self.door_legs = {}   # tour index i (leg i -> i+1) -> room
        self.start = None     # (x, y, yaw_deg)

    def box(self, name, x0, y0, x1, y1):
        """An axis-aligned wall box from its faces."""
        lo_x, hi_x, lo_y, hi_y = min(x0, x1), max(x0, x1), min(y0, y1), max(y0, y1)
        self.obstacles.append(Obstacle(name, "box", (lo_x + hi_x) / 2, (lo_y + hi_y) / 2,
                                       (hi_x - lo_x) / 2, (hi_y - lo_y) / 2))


# The largest building side, metres (mjslam's default sim.max_world_extent_m;
# a 200 m building takes about 15 s to generate and check), and the most
# clutter of each kind.
MAX_SIZE_M = 500.0
MAX_CLUTTER = 10000


def parse_size(text):
    try:
        w, h = (float(v) for v in text.lower().split("x"))
    except ValueError:
        raise OptionError(f"--size: expected WIDTHxHEIGHT in metres, e.g. 40x30 (got '{text}')")
    if not (w >= 8 and h >= 8):
        raise OptionError(f"--size: each side must be at least 8 m (got '{text}')")
    if not (w <= MAX_SIZE_M and h <= MAX_SIZE_M):
        raise OptionError(f"--size: each side must be at most {MAX_SIZE_M:g} m (got '{text}')")
    return w, h


def parse_range(name, text):
    try:
        lo, hi = (float(v) for v in text.split(":"))
    except ValueError:
        raise OptionError(f"{name}: expected MIN:MAX in metres (got '{text}')")
    # A room narrower than a metre holds no robot (and tiny ones never end a row).
    if not (1 <= lo <= hi <= MAX_SIZE_M):
        raise OptionError(f"{name}: expected 1 <= MIN <= MAX <= {MAX_SIZE_M:g} (got '{text}')")
    return lo, hi


def validate(args):
    """Argument checks that do not need the layout."""
    for key in ("corridor_width", "wall_thickness", "door_width"):
        v = getattr(args, key)
        if not (v > 0 and math.isfinite(v)):
            raise OptionError(f"--{key.replace('_', '-')}: expected a value > 0 (got {v})")
    if args.corridor_width < 2 * TOUR_CLEARANCE_M + 0.2:
        raise OptionError(f"--corridor-width: at least {2 * TOUR_CLEARANCE_M + 0.2:g} m for the "
                            f"tour's clearance (got {args.corridor_width:g})")
    for key in ("corridors", "cross_corridors", "columns", "pillars", "free_walls"):
        if not 0 <= getattr(args, key) <= MAX_CLUTTER:
            raise OptionError(f"--{key.replace('_', '-')}: expected a count in [0, {MAX_CLUTTER}] "
                              f"(got {getattr(args, key)})")
    if args.corridors < 1:
        raise OptionError(f"--corridors: expected at least 1 (got {args.corridors})")
    if not 0 <= args.hall_probability <= 1:
        raise OptionError(f"--hall-probability: expected a value in [0, 1] "
                          f"(got {args.hall_probability})")
    if not (math.isfinite(args.rotation_deg) and abs(args.rotation_deg) <= 360):
        raise OptionError(f"--rotation-deg: expected degrees in [-360, 360] "
                          f"(got {args.rotation_deg})")
    if args.wall_thickness > 10 or args.door_width > 100 or args.corridor_width > 100:
        raise OptionError("--wall-thickness, --door-width, --corridor-width: at most 10, 100 "
                          f"and 100 m (got {args.wall_thickness:g}, {args.door_width:g}, "
                          f"{args.corridor_width:g})")
    if args.name is not None and not re.fullmatch(r"[A-Za-z0-9_.-]{1,100}", args.name):
        raise OptionError(f"--name: expected letters, digits, '_', '.' or '-' (got {args.name!r})")


# ---------------------------------------------------------------------------
# Layout

def split_widths(rng, length, lo, hi):
    """Random widths in [lo, hi] (multiples of 0.05 m) summing to length."""
    widths, left = [], length
    while left > 2 * hi:
        w = round(rng.uniform(lo, hi) / 0.05) * 0.05
        widths.append(w)
        left -= w
    if left > hi:  # two last rooms share what is left
        a = round(rng.uniform(max(lo, left - hi), min(hi, left - lo)) / 0.05) * 0.05
        widths += [a, left - a]
    else:
        widths.append(left)
    return widths


def lay_out_row(b, rng, name, x0, x1, front, sign, depth_max, outer_back, ends):
    """One row of rooms along a corridor whose wall face is at y = front; the
    rooms extend in direction sign (+1 north, -1 south) up to depth_max
    (interior, metres). outer_back: the outer wall is at front + sign *
    (T + depth_max), so a room of full depth needs no back wall of its own.
    ends: (west, east) True where the row ends at a corridor (its own end wall),
    False at the outer wall. Returns the rooms."""
    a = b.args
    t, dw = a.wall_thickness, a.door_width
    lo, hi = a.room_width
    # Partition positions (wall middles) between x0 and x1 (the row's faces).
    inner0 = x0 + (t if ends[0] else 0.0)
    inner1 = x1 - (t if ends[1] else 0.0)
    widths = split_widths(rng, inner1 - inner0 - 0.0, lo + t, hi + t)
    cuts = [inner0]
    for w in widths[:-1]:
        cuts.append(cuts[-1] + w)
    cuts.append(inner1)
    # Halls: merge a run of 2-3 rooms.
    spans = []
    k = 0
    while k < len(cuts) - 1:
        n = 1
        if rng.random() < a.hall_probability and k + 2 < len(cuts):
            n = min(rng.choice((2, 3)), len(cuts) - 1 - k)
        spans.append((cuts[k], cuts[k + n], n > 1))
        k += n
    y_in = front + sign * t  # inner face of the corridor wall
    rooms = []
    depths = []
    for i, (c0, c1, hall) in enumerate(spans):
        d = rng.uniform(0.6, 1.0) * depth_max
        if outer_back and d > depth_max - t - 0.3:
            d = depth_max
        depths.append(round(d / 0.05) * 0.05 if d < depth_max else depth_max)
    for i, (c0, c1, hall) in enumerate(spans):
        rx0 = c0 + (t / 2 if i > 0 else 0.0)
        rx1 = c1 - (t / 2 if i + 1 < len(spans) else 0.0)
        d = depths[i]
        room_name = f"{name}_{'hall' if hall else 'room'}{i}"
        # Door: its middle anywhere leaving the tour's clearance to the partitions.
        margin = TOUR_CLEARANCE_M + 0.05
        door_x = round(rng.uniform(rx0 + margin, rx1 - margin) / 0.05) * 0.05
        rooms.append(Room(room_name, rx0, rx1, *sorted((y_in, y_in + sign * d)),
                          door_x, front + sign * t / 2, sign, hall))
        # Back wall (none where the outer wall is the back).
        if not (outer_back and d >= depth_max):
            yb = y_in + sign * d
            b.box(f"{room_name}_back", rx0 - t / 2 if i > 0 else rx0 - (t if ends[0] else 0),
                  yb, rx1 + t / 2 if i + 1 < len(spans) else rx1 + (t if ends[1] else 0),
                  yb + sign * t)
    # Partitions between rooms, as deep as the deeper neighbour.
    for i in range(1, len(spans)):
        c = spans[i][0]
        d = max(depths[i - 1], depths[i])
        far = y_in + sign * (d + (0.0 if outer_back and d >= depth_max else t))
        b.box(f"{name}_partition{i}", c - t / 2, y_in, c + t / 2, far)
    # End walls where the row meets a cross corridor.
    for side, (x, inward) in enumerate(((x0, +1), (x1, -1))):
        if not ends[side]:
            continue
        d = depths[0 if side == 0 else -1]
        far = y_in + sign * (d + (0.0 if outer_back and d >= depth_max else t))
        b.box(f"{name}_end{side}", x, front, x + inward * t, far)
    # Corridor wall with one door per room.
    xs = [x0]
    for r in rooms:
        xs += [r.door_x - dw / 2, r.door_x + dw / 2]
    xs.append(x1)
    for k in range(0, len(xs), 2):
        b.box(f"{name}_front{k // 2}", xs[k], front, xs[k + 1], front + sign * t)
    return rooms


def lay_out(args):
    """The building's walls, rooms and tour (not yet checked or clutter-filled)."""
    b = Building(args)
    rng = random.Random(args.seed)
    W, H = args.size
    t, cw = args.wall_thickness, args.corridor_width
    k, m = args.corridors, args.cross_corridors
    share = (H - k * cw) / (2 * k)  # depth of one row of rooms, walls included
    block_w = (W - m * cw) / (m + 1)
    if share < 2 * t + 2.5:
        raise OptionError(f"--corridors: {k} corridors leave rows of {share:.2f} m in a "
                            f"{H:g} m deep building; at least {2 * t + 2.5:g} m are needed")
    if block_w < args.room_width[1] + 2 * t:
        raise OptionError(f"--cross-corridors: {m} cross corridors leave blocks "
                            f"{block_w:.2f} m long; at least {args.room_width[1] + 2 * t:g} m "
                            "(one room of the widest) are needed")
    # Outer walls (faces at 0, W and 0, H; corners joined).
    b.box("outer_south", -t, -t, W + t, 0)
    b.box("outer_north", -t, H, W + t, H + t)
    b.box("outer_west", -t, 0, 0, H)
    b.box("outer_east", W, 0, W + t, H)
    corridor_y = [share * (2 * i + 1) + cw * i for i in range(k)]  # south faces
    cross_x = [block_w * (j + 1) + cw * j for j in range(m)]        # west faces
    cols = [(0.0 if j == 0 else cross_x[j - 1] + cw, W if j == m else cross_x[j])
            for j in range(m + 1)]
    rooms_by_corridor = [[] for _ in range(k)]
    for ci, y in enumerate(corridor_y):
        for j, (x0, x1) in enumerate(cols):
            ends = (j > 0, j < m)
            # Row south of the corridor (rooms extend south), then north.
            # Rows at the outer wall have it as their back (one wall less).
            south = lay_out_row(b, rng, f"c{ci}s{j}", x0, x1, y, -1,
                                share - (t if ci == 0 else 2 * t), ci == 0, ends)
            north = lay_out_row(b, rng, f"c{ci}n{j}", x0, x1, y + cw, +1,
                                share - (t if ci == k - 1 else 2 * t), ci == k - 1, ends)
            rooms_by_corridor[ci] += south + north
    for ci in range(k):
        rooms_by_corridor[ci].sort(key=lambda r: r.door_x)
    b.rooms = [r for rs in rooms_by_corridor for r in rs]
    plan_tour(b, corridor_y, cross_x, rooms_by_corridor)
    place_clutter(b, rng)
    return b


def plan_tour(b, corridor_y, cross_x, rooms_by_corridor):
    """The serpentine tour: corridor c west to east (c even) or east to west,
    every room on the way, the cross corridor nearest the end to the next."""
    a = b.args
    W, cw = a.size[0], a.corridor_width
    mid = [y + cw / 2 for y in corridor_y]
    cross_mid = [x + cw / 2 for x in cross_x]
    end_x = (cw / 2, W - cw / 2)
    tour = [(end_x[0], mid[0])]
    b.start = (end_x[0], mid[0], 0.0)
    for ci in range(len(mid)):
        east = ci % 2 == 0
        rooms = rooms_by_corridor[ci] if east else rooms_by_corridor[ci][::-1]
        if not east:
            tour.append((end_x[1], mid[ci]))  # drive to the east end first
        for r in rooms:
            # On the door's axis: across the corridor (a run-up to align with
            # the door), just before and just after the door, and deep in the
            # room; then the room's middle, and back the same way.
            face = r.door_y - r.axis_y * a.wall_thickness / 2
            c = (r.door_x, face - r.axis_y * (cw - TOUR_CLEARANCE_M - 0.05))
            out = (r.door_x, r.door_y - r.axis_y * DOOR_APPROACH_M)
            inside = (r.door_x, r.door_y + r.axis_y * DOOR_APPROACH_M)
            depth = r.y1 - r.y0
            deep = (r.door_x, face + r.axis_y * (a.wall_thickness +
                                                 min(depth - TURN_CLEARANCE_M, 2.4)))
            middle = room_middle(r)
            visit = [deep]
            if math.hypot(middle[0] - deep[0], middle[1] - deep[1]) > 0.5:
                visit += [middle, deep]
            tour += [c, out]
            b.door_legs[len(tour) - 1] = r
            tour += [inside] + visit + [inside]
            b.door_legs[len(tour) - 1] = r
            tour += [out, c]
        tour.append((end_x[1] if east else end_x[0], mid[ci]))
        if ci + 1 < len(mid):
            if not cross_mid:
                raise BuildingError("--cross-corridors: at least 1 is needed to join "
                                    f"{len(mid)} corridors")
            x = cross_mid[-1] if east else cross_mid[0]
            tour += [(x, mid[ci]), (x, mid[ci + 1])]
    # Back to the start along the cross corridors used on the way.
    for ci in range(len(mid) - 1, 0, -1):
        x = cross_mid[-1] if (ci - 1) % 2 == 0 else cross_mid[0]
        tour += [(x, mid[ci]), (x, mid[ci - 1])]
    # Drop repeated points (a waypoint equal to the one before it).
    dedup, legs = [], {}
    for i, p in enumerate(tour):
        if dedup and math.hypot(p[0] - dedup[-1][0], p[1] - dedup[-1][1]) < 1e-9:
            if i in b.door_legs:
                legs[len(dedup) - 1] = b.door_legs[i]
            continue
        if i in b.door_legs:
            legs[len(dedup)] = b.door_legs[i]
        dedup.append(p)
    if math.hypot(dedup[-1][0] - dedup[0][0], dedup[-1][1] - dedup[0][1]) < 1e-9:
        dedup.pop()
    b.tour, b.door_legs = dedup, legs


def room_middle(r):
    """The tour's turning point in a room: its middle, at least
    TURN_CLEARANCE_M from the walls."""
    x = min(max((r.x0 + r.x1) / 2, r.x0 + TURN_CLEARANCE_M), r.x1 - TURN_CLEARANCE_M)
    y = min(max((r.y0 + r.y1) / 2, r.y0 + TURN_CLEARANCE_M), r.y1 - TURN_CLEARANCE_M)
    return (x, y)


def place_clutter(b, rng):
    """Columns, pillars and free-standing walls in rooms (halls first), each
    >= 1.0 m from the room's walls and other clutter and >= 0.75 m from the
    tour, so that the robot passes around it."""
    a = b.args
    halls = [r for r in b.rooms if r.hall]
    rooms = [r for r in b.rooms if not r.hall]
    legs = [(b.tour[i], b.tour[(i + 1) % len(b.tour)]) for i in range(len(b.tour))]
    placed = []
    kinds = ["column"] * a.columns + ["pillar"] * a.pillars + ["free_wall"] * a.free_walls
    rng.shuffle(kinds)
    count = {"column": 0, "pillar": 0, "free_wall": 0}
    for kind in kinds:
        for _ in range(60):
            r = rng.choice(halls) if halls and rng.random() < 0.7 else rng.choice(rooms or halls)
            if kind == "column":
                h = rng.uniform(0.2, 0.35)
                o = Obstacle("", "box", 0, 0, h, h, rng.uniform(0, 90))
            elif kind == "pillar":
                o = Obstacle("", "cyl", 0, 0, r=rng.uniform(0.15, 0.3))
            else:
                o = Obstacle("", "box", 0, 0, rng.uniform(0.6, 1.2), 0.06, rng.uniform(0, 180))
            reach = max(o.aabb[2], o.aabb[3])
            if r.x1 - r.x0 < 2 * (reach + 1.0) or r.y1 - r.y0 < 2 * (reach + 1.0):
                continue
            cx = rng.uniform(r.x0 + reach + 1.0, r.x1 - reach - 1.0)
            cy = rng.uniform(r.y0 + reach + 1.0, r.y1 - reach - 1.0)
            o = Obstacle(f"{r.name}_{kind}{count[kind]}", o.kind, round(cx, 2), round(cy, 2),
                         o.hx, o.hy, round(o.yaw_deg, 1), round(o.r, 2))
            if any(math.hypot(o.cx - p.cx, o.cy - p.cy) < reach + 1.0 + 1.2 for p in placed):
                continue
            if any(segment_distance(o, p, q) < 0.75 + 0.05 for p, q in legs):
                continue
            placed.append(o)
            count[kind] += 1
            break
    b.obstacles += placed
    b.clutter = count


def segment_distance(o, p, q, step=0.05):
    """Smallest distance from obstacle o to points of segment p-q (sampled)."""
    x0, y0, x1, y1 = o.aabb
    if min(p[0], q[0]) > x1 + 2 or max(p[0], q[0]) < x0 - 2 or \
       min(p[1], q[1]) > y1 + 2 or max(p[1], q[1]) < y0 - 2:
        return 2.0
    n = max(1, int(math.hypot(q[0] - p[0], q[1] - p[1]) / step))
    return min(o.dist(p[0] + (q[0] - p[0]) * i / n, p[1] + (q[1] - p[1]) * i / n)
               for i in range(n + 1))


# ---------------------------------------------------------------------------
# Checks

def check(b):
    """Raises BuildingError naming the first failed check."""
    index = ObstacleIndex(b.obstacles)
    check_doors(b, index)
    check_start(b, index)
    check_tour(b, index)
    check_connected(b)


def check_doors(b, index):
    need = ROBOT_WIDTH_M + 2 * DOOR_SIDE_MARGIN_M
    for r in b.rooms:
        width = door_width(r, index)
        if width < need:
            raise BuildingError(f"door of {r.name} at ({r.door_x:.2f}, {r.door_y:.2f}) is "
                                f"{width:.2f} m wide: the robot ({ROBOT_WIDTH_M} m) needs at "
                                f"least {need:.2f} m")
        d, name = index.nearest(r.door_x, r.door_y, 1.0)
        if d < need / 2:
            raise BuildingError(f"door of {r.name} at ({r.door_x:.2f}, {r.door_y:.2f}) is "
                                f"blocked: {name} is {d:.2f} m from its middle")


def door_width(r, index):
    """Free width of a room's door along its wall, to 5 mm: from its middle to
    the nearest obstacle on the door's line, both ways."""
    width = 0.0
    for direction in (-1, 1):
        s = 0.0
        while s < 5.0 and index.nearest(r.door_x + direction * s, r.door_y, 0.01)[0] > 1e-9:
            s += 0.005
        width += s
    return width


def check_start(b, index):
    """The robot's body (a rectangle behind h) at the start pose is clear."""
    x, y, yaw = b.start
    c, s = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))
    half = ROBOT_WIDTH_M / 2
    for i in range(21):
        for j in range(9):
            bx = -ROBOT_FRONT_M - (ROBOT_BACK_M - ROBOT_FRONT_M) * i / 20
            by = -half + 2 * half * j / 8
            d, name = index.nearest(x + c * bx - s * by, y + s * bx + c * by, 0.05)
            if d < 0.05:
                raise BuildingError(f"start ({x:.2f}, {y:.2f}): the robot's body is "
                                    f"{d:.2f} m from {name} (needs >= 0.05 m)")


def check_tour(b, index):
    n = len(b.tour)
    for i, (x, y) in enumerate(b.tour):
        d, name = index.nearest(x, y, TOUR_CLEARANCE_M)
        if d < TOUR_CLEARANCE_M:
            raise BuildingError(f"tour_{i} at ({x:.2f}, {y:.2f}) is {d:.2f} m from {name} "
                                f"(needs >= {TOUR_CLEARANCE_M} m)")
    for i in range(n):
        (x0, y0), (x1, y1) = b.tour[i], b.tour[(i + 1) % n]
        door = b.door_legs.get(i)
        if door is not None:
            # Through the door's middle, along its axis.
            if abs(x0 - door.door_x) > 0.05 or abs(x1 - door.door_x) > 0.05:
                raise BuildingError(f"tour_{i} -> tour_{(i + 1) % n}: the leg through the door "
                                    f"of {door.name} is not on the door's axis")
            need = b.args.door_width / 2 - 0.06
        else:
            need = TOUR_CLEARANCE_M
        steps = max(1, int(math.hypot(x1 - x0, y1 - y0) / 0.05))
        for k in range(steps + 1):
            f = k / steps
            px, py = x0 + f * (x1 - x0), y0 + f * (y1 - y0)
            d, name = index.nearest(px, py, need)
            if d < need:
                raise BuildingError(f"tour_{i} -> tour_{(i + 1) % n}: the leg passes "
                                    f"{d:.2f} m from {name} at ({px:.2f}, {py:.2f}) "
                                    f"(needs >= {need:.2f} m)")


def check_connected(b):
    """Every waypoint is reachable from the start through cells where the
    robot fits (clearance >= half its width + 0.02 m)."""
    W, H = b.args.size
    t = b.args.wall_thickness
    cell, need = GRID_CELL_M, ROBOT_WIDTH_M / 2 + 0.02
    x_lo, y_lo = -t - cell, -t - cell
    nx = int(math.ceil((W + 2 * t + 2 * cell) / cell))
    ny = int(math.ceil((H + 2 * t + 2 * cell) / cell))
    blocked = bytearray(nx * ny)
    for o in b.obstacles:
        x0, y0, x1, y1 = o.aabb
        for i in range(max(0, int((x0 - need - x_lo) / cell)),
                       min(nx, int((x1 + need - x_lo) / cell) + 2)):
            px = x_lo + (i + 0.5) * cell
            for j in range(max(0, int((y0 - need - y_lo) / cell)),
                           min(ny, int((y1 + need - y_lo) / cell) + 2)):
                if not blocked[j * nx + i] and o.dist(px, y_lo + (j + 0.5) * cell) < need:
                    blocked[j * nx + i] = 1

    def cell_of(x, y):
        return int((y - y_lo) / cell) * nx + int((x - x_lo) / cell)

    start = cell_of(b.start[0], b.start[1])
    reached = bytearray(nx * ny)
    reached[start] = 1
    todo = [start]
    while todo:
        c = todo.pop()
        i, j = c % nx, c // nx
        for nb, ok in ((c - 1, i > 0), (c + 1, i + 1 < nx), (c - nx, j > 0),
                       (c + nx, j + 1 < ny)):
            if ok and not reached[nb] and not blocked[nb]:
                reached[nb] = 1
                todo.append(nb)
    for i, (x, y) in enumerate(b.tour):
        if not reached[cell_of(x, y)]:
            room = next((r for r in b.rooms if r.x0 <= x <= r.x1 and r.y0 <= y <= r.y1), None)
            where = f" in {room.name}" if room else ""
            raise BuildingError(f"tour_{i} at ({x:.2f}, {y:.2f}){where} is not connected to the "
                                "start: no path where the robot fits")


# ---------------------------------------------------------------------------
# Output

def to_world(b, name):
    """The checked building as a World in the world frame (rotated)."""
    a = b.args
    W, H = a.size
    rot = math.radians(a.rotation_deg)
    c, s = math.cos(rot), math.sin(rot)
    mx, my = W / 2, H / 2

    def tf(x, y):
        dx, dy = x - mx, y - my
        return (round(mx + c * dx - s * dy, 4), round(my + s * dx + c * dy, 4))

    clutter = ", ".join(f"{v} {k.replace('_', '-')}s" for k, v in b.clutter.items())
    w = World(name, f"""  mjslam world: an office building {W:g} x {H:g} m generated by
  sim/tools/generate_building.py ({command_line(a)}).
  {len(b.rooms)} rooms and halls off {a.corridors} corridors and {a.cross_corridors} cross corridors,
  {a.door_width:g} m doors, walls {a.wall_thickness:g} m thick, clutter: {clutter};
  rotated {a.rotation_deg:g} deg about the middle. Regenerate rather than edit.
  Conventions: worlds/README.md.""")
    w.thickness = a.wall_thickness
    for o in b.obstacles:
        x, y = tf(o.cx, o.cy)
        if o.kind == "cyl":
            w.cyl(o.name, x, y, o.r)
        else:
            w.box(o.name, x, y, o.hx, o.hy, o.yaw_deg + a.rotation_deg)
    w.tour = [tf(x, y) for x, y in b.tour]
    sx, sy = tf(b.start[0], b.start[1])
    w.start = (sx, sy, b.start[2] + a.rotation_deg)
    corners = [tf(x, y) for x, y in ((-1, -1), (W + 1, -1), (W + 1, H + 1), (-1, H + 1))]
    w.extent = (min(p[0] for p in corners), min(p[1] for p in corners),
                max(p[0] for p in corners), max(p[1] for p in corners))
    return w


def command_line(a):
    return (f"--seed {a.seed} --size {a.size[0]:g}x{a.size[1]:g} --corridors {a.corridors} "
            f"--cross-corridors {a.cross_corridors} --corridor-width {a.corridor_width:g} "
            f"--room-width {a.room_width[0]:g}:{a.room_width[1]:g} "
            f"--hall-probability {a.hall_probability:g} --door-width {a.door_width:g} "
            f"--wall-thickness {a.wall_thickness:g} --columns {a.columns} --pillars {a.pillars} "
            f"--free-walls {a.free_walls} --rotation-deg {a.rotation_deg:g}")


def tour_length(tour):
    n = len(tour)
    return sum(math.hypot(tour[(i + 1) % n][0] - tour[i][0], tour[(i + 1) % n][1] - tour[i][1])
               for i in range(n))


def parser():
    p = argparse.ArgumentParser(
        prog="generate_building.py",
        description="Generates and checks an office building world (MJCF) for mjslam.")
    p.add_argument("--out", required=True, help="the world file to write (.xml)")
    p.add_argument("--name", help="the model's name (default: the file's stem)")
    p.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
    p.add_argument("--size", default="40x30", help="inside size WxH, metres (default 40x30)")
    p.add_argument("--corridors", type=int, default=2,
                   help="corridors along x (default 2)")
    p.add_argument("--cross-corridors", type=int, default=2,
                   help="corridors along y that join them (default 2)")
    p.add_argument("--corridor-width", type=float, default=2.2, help="metres (default 2.2)")
    p.add_argument("--room-width", default="2.8:4.8",
                   help="MIN:MAX width of a room, metres (default 2.8:4.8)")
    p.add_argument("--hall-probability", type=float, default=0.15,
                   help="chance that a room starts a hall of 2-3 rooms (default 0.15)")
    p.add_argument("--door-width", type=float, default=0.85, help="metres (default 0.85)")
    p.add_argument("--wall-thickness", type=float, default=0.15, help="metres (default 0.15)")
    p.add_argument("--columns", type=int, default=10,
                   help="square columns at random yaw (default 10)")
    p.add_argument("--pillars", type=int, default=6, help="round pillars (default 6)")
    p.add_argument("--free-walls", type=int, default=6,
                   help="free-standing walls at random angles (default 6)")
    p.add_argument("--rotation-deg", type=float, default=0.0,
                   help="rotation of the whole building about its middle (default 0)")
    return p


def build(argv):
    """Parses argv, generates and checks the building: (args, World)."""
    args = parser().parse_args(argv)
    args.size = parse_size(args.size)
    args.room_width = parse_range("--room-width", args.room_width)
    validate(args)
    b = lay_out(args)
    check(b)
    name = args.name or os.path.splitext(os.path.basename(args.out))[0]
    return args, b, to_world(b, name)


def main(argv):
    try:
        args, b, w = build(argv)
    except OptionError as e:
        parser().error(str(e))  # usage and the message on stderr, exit 2
    except BuildingError as e:
        print(f"generate_building.py: error: {e}", file=sys.stderr)
        return 1
    text = w.xml()
    tmp = args.out + ".tmp"
    try:
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, args.out)
    except OSError as e:
        if os.path.exists(tmp):
            os.remove(tmp)
        print(f"generate_building.py: error: --out {args.out}: {e.strerror}", file=sys.stderr)
        return 1
    print(f"{args.out}: {len(b.rooms)} rooms and halls, {len(b.obstacles)} geoms, "
          f"{len(b.tour)} waypoints, tour {tour_length(b.tour):.0f} m, clutter "
          f"{b.clutter}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
