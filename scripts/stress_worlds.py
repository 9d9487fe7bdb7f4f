"""Writes the two worlds that measure how setup and evaluation cost grows
with the number of geoms (docs/results.md, "Cost with world size"):

- boxes_5000.xml: 5,000 boxes (0.2-0.8 m, random yaw, seed 1) scattered in a
  92 m square closed by four walls, the start clear in the middle;
- room_cut_5000.xml: the 8 x 6 m room of worlds/room.xml with each of its four
  walls cut into 1,250 touching pieces (5,000 geoms, the same true map).

Usage: python3 scripts/stress_worlds.py OUTPUT_DIR. Python 3 standard library.
"""
import math
import os
import random
import sys


def header(name, half):
    return [f'<mujoco model="{name}">', '  <worldbody>',
            f'    <geom name="floor" type="plane" size="{half + 2} {half + 2} 0.1"/>']


def footer(start_x, start_y):
    return [f'    <site name="start" group="4" pos="{start_x} {start_y} 0.01" size="0.1"/>',
            '  </worldbody>', '</mujoco>']


def boxes_5000():
    rng = random.Random(1)
    half = 46.0
    out = header("boxes_5000", half)
    t = 0.15
    for name, cx, cy, hx, hy in (("south", 0, -half - t / 2, half + t, t / 2),
                                 ("north", 0, half + t / 2, half + t, t / 2),
                                 ("west", -half - t / 2, 0, t / 2, half),
                                 ("east", half + t / 2, 0, t / 2, half)):
        out.append(f'    <geom name="wall_{name}" type="box" size="{hx} {hy} 0.5" '
                   f'pos="{cx} {cy} 0.5"/>')
    k = 0
    while k < 4996:
        cx, cy = rng.uniform(-half + 1, half - 1), rng.uniform(-half + 1, half - 1)
        if math.hypot(cx, cy) < 2.0:
            continue  # the start stays clear
        hx, hy = rng.uniform(0.1, 0.4), rng.uniform(0.1, 0.4)
        yaw = rng.uniform(0, 180)
        out.append(f'    <geom name="box_{k}" type="box" size="{hx:.3f} {hy:.3f} 0.5" '
                   f'pos="{cx:.3f} {cy:.3f} 0.5" euler="0 0 {yaw:.1f}"/>')
        k += 1
    return out + footer(0, 0)


def room_cut_5000():
    out = header("room_cut_5000", 5.0)
    t, pieces = 0.15, 1250
    # Inside 8 x 6 m; each wall's box from corner to corner (outer faces
    # included) cut into equal touching pieces.
    walls = [("south", -4 - t, -3 - t, 4 + t, -3), ("north", -4 - t, 3, 4 + t, 3 + t),
             ("west", -4 - t, -3, -4, 3), ("east", 4, -3, 4 + t, 3)]
    for name, x0, y0, x1, y1 in walls:
        along_x = (x1 - x0) > (y1 - y0)
        for k in range(pieces):
            if along_x:
                a, b = x0 + (x1 - x0) * k / pieces, x0 + (x1 - x0) * (k + 1) / pieces
                cx, cy, hx, hy = (a + b) / 2, (y0 + y1) / 2, (b - a) / 2, (y1 - y0) / 2
            else:
                a, b = y0 + (y1 - y0) * k / pieces, y0 + (y1 - y0) * (k + 1) / pieces
                cx, cy, hx, hy = (x0 + x1) / 2, (a + b) / 2, (x1 - x0) / 2, (b - a) / 2
            out.append(f'    <geom name="{name}_{k}" type="box" size="{hx:.6f} {hy:.6f} 0.5" '
                       f'pos="{cx:.6f} {cy:.6f} 0.5"/>')
    return out + footer(-2.8, -1.8)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: stress_worlds.py OUTPUT_DIR")
    for name, make in (("boxes_5000", boxes_5000), ("room_cut_5000", room_cut_5000)):
        path = os.path.join(sys.argv[1], name + ".xml")
        with open(path, "w") as f:
            f.write("\n".join(make()) + "\n")
        print(path, file=sys.stderr)
