"""Regenerates the shipped worlds (worlds/*.xml) of mjslam.

The XML files are the artifacts; this script records how their walls were laid
out and checks that every tour waypoint, and every point of the closed tour
between them, is at least 0.6 m from every obstacle (the C++ test
tests/sim/worlds_test.cc checks the shipped files again, independently).

Usage: python3 sim/tools/generate_worlds.py worlds
Conventions of a world: worlds/README.md. Python 3 standard library only.
The two office buildings (building_40x30.xml, building_80x50.xml) come from
generate_building.py with the arguments in BUILDINGS below, and are checked
by it.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from generate_building import main as generate_building_main  # noqa: E402
from world_xml import T, World  # noqa: E402

def rect_walls(w, prefix, x0, y0, x1, y1):
    """Four walls on the centreline rectangle, corners joined."""
    w.wall(f"{prefix}_south", x0, y0, x1, y0)
    w.wall(f"{prefix}_east", x1, y0, x1, y1)
    w.wall(f"{prefix}_north", x1, y1, x0, y1)
    w.wall(f"{prefix}_west", x0, y1, x0, y0)

def poly_walls(w, prefix, pts):
    """Closed centreline polygon, every corner joined."""
    n = len(pts)
    for i in range(n):
        (ax, ay), (bx, by) = pts[i], pts[(i + 1) % n]
        w.wall(f"{prefix}_{i}", ax, ay, bx, by)

# ----------------------------------------------------------------------------
def room():
    w = World("room", """  mjslam world: a single rectangular room, 8 x 6 m inside (walls 0.15 m thick,
  1 m tall). The simplest map: four lines and four concave corners.
  Conventions (floor plane, static geoms in groups 0-4, sites start and
  tour_*): worlds/README.md.""")
    h = T / 2
    rect_walls(w, "wall", -4 - h, -3 - h, 4 + h, 3 + h)
    w.tour = [(-2.8, -1.8), (2.8, -1.8), (2.8, 1.8), (-2.8, 1.8)]
    w.start = (-2.8, -1.8, 0)
    w.extent = (-4.2, -3.2, 4.2, 3.2)
    return w

def corridor_loop():
    w = World("corridor_loop", """  mjslam world: a loop of 2 m wide corridors around a central block, about
  12 x 8 m inside, like the paper's consistency environment (walls and corners
  everywhere). Alcoves in the north and south walls, a jog in the east wall,
  a notch in the block's east face and a buttress on its west face give
  concave and convex corners. Walls 0.15 m thick, 1 m tall (centrelines below).
  Conventions: worlds/README.md.""")
    h = T / 2
    # Outer boundary (centreline, counter-clockwise), inner faces at
    # x in [-6, 6] (east of y = 0: 6.8), y in [-4, 4], plus alcoves.
    X0, X1, X1b, Y0, Y1 = -6 - h, 6 + h, 6.8 + h, -4 - h, 4 + h
    outer = [
        (X0, Y0),
        (1.5 - h, Y0), (1.5 - h, -5 - h), (3.0 + h, -5 - h), (3.0 + h, Y0),   # south alcove
        (X1, Y0), (X1, 0 - h), (X1b, 0 - h), (X1b, Y1),                        # east jog
        (1.0 + h, Y1), (1.0 + h, 5 + h), (-1.0 - h, 5 + h), (-1.0 - h, Y1),    # north alcove
        (X0, Y1),
    ]
    poly_walls(w, "outer", outer)
    # Central block, faces at x in [-4, 4], y in [-2, 2]; a notch 0.8 m deep
    # in the east face (y in [-0.75, 0.75]) and a buttress 0.5 m out of the
    # west face (y in [-0.5, 0.5]).
    B0, B1, BY0, BY1 = -4 + h, 4 - h, -2 + h, 2 - h
    block = [
        (B0, BY0), (B1, BY0),
        (B1, -0.75 - h), (3.2 - h, -0.75 - h), (3.2 - h, 0.75 + h), (B1, 0.75 + h),
        (B1, BY1), (B0, BY1),
        (B0, 0.5 - h), (-4.5 + h, 0.5 - h), (-4.5 + h, -0.5 + h), (B0, -0.5 + h),
    ]
    poly_walls(w, "block", block)
    w.tour = [(-5.0, -3.0), (-0.5, -3.0), (2.25, -3.1), (5.0, -3.0), (5.0, -1.0), (5.6, 1.0),
              (5.6, 3.0), (0.0, 3.1), (-5.0, 3.0), (-5.3, 0.0)]
    w.start = (-5.0, -3.0, 0)
    w.extent = (-6.2, -5.2, 7.0, 5.2)
    return w

def office():
    w = World("office", """  mjslam world: an office floor, 20 x 10 m, like the paper's laboratory: a
  2 m corridor along x (y 4..6) between four rooms to the south (5 m wide)
  and three to the north (7, 6 and 7 m wide), joined by 1.4 m doors.
  Walls 0.15 m thick, 1 m tall; coordinates below are wall centrelines.
  Conventions: worlds/README.md.""")
    D = 1.4  # door width
    rect_walls(w, "outer", 0, 0, 20, 10)
    # Corridor walls with doors (gaps) centred on the listed x.
    def wall_with_doors(name, y, doors, x0=0.0, x1=20.0):
        xs = [x0]
        for c in doors:
            xs += [c - D / 2, c + D / 2]
        xs.append(x1)
        for k in range(0, len(xs), 2):
            a, b = xs[k], xs[k + 1]
            w.wall(f"{name}_{k // 2}", a, y, b, y, ext0=(k == 0), ext1=(k + 2 == len(xs)))
    wall_with_doors("corridor_south", 4.0, [2.5, 7.5, 12.5, 17.5])
    wall_with_doors("corridor_north", 6.0, [3.5, 10.0, 16.5])
    # Room partitions (T-joined to the outer and corridor walls).
    for i, x in enumerate([5.0, 10.0, 15.0]):
        w.wall(f"south_partition_{i}", x, 0, x, 4)
    for i, x in enumerate([7.0, 13.0]):
        w.wall(f"north_partition_{i}", x, 6, x, 10)
    # Tour: along the corridor (y = 5), into rooms S1, N1, S3, N2, S4, N3 and back.
    def visit(xd, south):
        s = -1 if south else 1
        y_in = 5 + s * 2.2          # 1.2 m past the door line
        y_far = 5 + s * 3.6         # 1.1 m from the far wall's face
        return [(xd, 5.0), (xd, y_in), (xd + 1.2, y_far), (xd - 1.2, y_far), (xd, y_in), (xd, 5.0)]
    tour = [(1.2, 5.0)]
    tour += visit(2.5, True)
    tour += visit(3.5, False)
    tour += visit(12.5, True)
    tour += visit(10.0, False)
    tour += visit(17.5, True)
    tour += visit(16.5, False)
    tour += [(18.9, 5.0), (10.0, 5.2)]
    # Drop consecutive duplicates (door points shared by neighbouring visits).
    dedup = []
    for p in tour:
        if not dedup or math.hypot(p[0] - dedup[-1][0], p[1] - dedup[-1][1]) > 1e-9:
            dedup.append(p)
    w.tour = dedup
    w.start = (1.2, 5.0, 0)
    w.extent = (-0.2, -0.2, 20.2, 10.2)
    return w

def pillars():
    w = World("pillars", """  mjslam world: an irregular room (about 12 x 10 m) whose walls are not
  axis-aligned, with round pillars, a rotated square column and a rotated
  free-standing wall (convex corners seen from all sides), and a buttress
  sticking out of the south wall. Walls 0.15 m thick, 1 m tall (the free
  wall 0.12 m). The boundary's inner faces form the convex polygon
  (0, 0) (9, -1) (11.5, 3) (10, 8.5) (3, 9.5) (-1.5, 5), counter-clockwise;
  wall boxes lie outside it, extended so that their outer faces meet.
  Conventions: worlds/README.md.""")
    # Inner faces of the boundary, counter-clockwise (a convex polygon).
    poly = [(0.0, 0.0), (9.0, -1.0), (11.5, 3.0), (10.0, 8.5), (3.0, 9.5), (-1.5, 5.0)]
    n = len(poly)
    for i in range(n):
        (ax, ay), (bx, by) = poly[i], poly[(i + 1) % n]
        L = math.hypot(bx - ax, by - ay)
        ux, uy = (bx - ax) / L, (by - ay) / L
        nx, ny = uy, -ux  # outward normal (right of the edge for a CCW polygon)
        def interior_angle(p_prev, p, p_next):
            v1 = (p_prev[0] - p[0], p_prev[1] - p[1]); v2 = (p_next[0] - p[0], p_next[1] - p[1])
            return math.acos((v1[0]*v2[0] + v1[1]*v2[1]) / (math.hypot(*v1) * math.hypot(*v2)))
        phi0 = interior_angle(poly[i - 1], poly[i], poly[(i + 1) % n])
        phi1 = interior_angle(poly[i], poly[(i + 1) % n], poly[(i + 2) % n])
        e0, e1 = T / math.tan(phi0 / 2), T / math.tan(phi1 / 2)
        a, b = -e0, L + e1
        cx = ax + ux * (a + b) / 2 + nx * T / 2
        cy = ay + uy * (a + b) / 2 + ny * T / 2
        w.box(f"wall_{i}", cx, cy, (b - a) / 2, T / 2, math.degrees(math.atan2(uy, ux)))
    # Buttress out of the south wall (edge 0), aligned with it: 0.8 m wide,
    # 0.7 m into the room (its back sits 0.1 m inside the wall).
    (ax, ay), (bx, by) = poly[0], poly[1]
    L = math.hypot(bx - ax, by - ay); ux, uy = (bx - ax) / L, (by - ay) / L
    inx, iny = -uy, ux
    mx, my = ax + ux * 6.0, ay + uy * 6.0
    depth, back = 0.7, 0.1
    w.box("buttress", mx + inx * (depth - back) / 2, my + iny * (depth - back) / 2,
          0.4, (depth + back) / 2, math.degrees(math.atan2(uy, ux)))
    # Free-standing obstacles.
    w.cyl("pillar_0", 3.0, 3.0, 0.25)
    w.cyl("pillar_1", 7.2, 6.2, 0.25)
    w.cyl("pillar_2", 8.0, 2.2, 0.2)
    w.box("column", 4.2, 6.6, 0.4, 0.4, 25.0)
    w.box("free_wall", 5.6, 4.4, 1.1, 0.06, -35.0)
    w.tour = [(1.3, 1.2), (4.5, 1.0), (6.0, 1.6), (9.3, 0.9), (9.9, 3.3), (9.0, 6.2), (8.6, 7.6),
              (5.3, 8.2), (3.2, 8.4), (2.0, 7.3), (0.3, 5.0), (1.5, 4.3), (1.7, 3.0)]
    w.start = (1.3, 1.2, -10)
    w.extent = (-1.8, -1.3, 11.8, 9.8)
    return w

# The shipped buildings: file stem and generate_building.py arguments.
BUILDINGS = [
    ("building_40x30", ["--seed", "1", "--size", "40x30", "--corridors", "2",
                        "--cross-corridors", "2", "--door-width", "0.85", "--columns", "10",
                        "--pillars", "6", "--free-walls", "6"]),
    ("building_80x50", ["--seed", "2", "--size", "80x50", "--corridors", "4",
                        "--cross-corridors", "5", "--door-width", "0.85", "--columns", "30",
                        "--pillars", "15", "--free-walls", "15"]),
]

if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: generate_worlds.py OUTPUT_DIR")
    outdir = sys.argv[1]
    for make in (room, corridor_loop, office, pillars):
        w = make()
        w.check()
        open(f"{outdir}/{w.name}.xml", "w").write(w.xml())
    for stem, args in BUILDINGS:
        generate_building_main(args + ["--out", f"{outdir}/{stem}.xml"])
