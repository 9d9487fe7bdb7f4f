#!/usr/bin/python3
"""Writes a maze world: an N x N grid of square cells (pitch P metres) cut by
a seeded depth-first search, with extra walls opened to make loops; walls
0.15 m thick, 1 m tall, so corridors are P - 0.15 m wide. Collinear wall
pieces are merged into one box. The start site is in the corner cell.

    scripts/make_maze.py OUT.xml [--cells 16] [--pitch 2.5] [--loops 0.1] [--seed 1]

The defaults give a 40 x 40 m maze with 2.35 m corridors.
Python 3 standard library only.
"""
import argparse
import random
import sys


def carve(n, loops, seed):
    """(horizontal, vertical) wall flags: h[i][j] the wall south of cell (i, j)
    for j in 0..n (row j), v[i][j] the wall west of cell (i, j) for i in 0..n."""
    rng = random.Random(seed)
    h = [[True] * (n + 1) for _ in range(n)]  # h[i][j]: wall at y = j between (i,j-1),(i,j)
    v = [[True] * n for _ in range(n + 1)]    # v[i][j]: wall at x = i between (i-1,j),(i,j)
    seen = [[False] * n for _ in range(n)]
    stack = [(0, 0)]
    seen[0][0] = True
    while stack:
        i, j = stack[-1]
        options = [(di, dj) for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1))
                   if 0 <= i + di < n and 0 <= j + dj < n and not seen[i + di][j + dj]]
        if not options:
            stack.pop()
            continue
        di, dj = rng.choice(options)
        if di == 1: v[i + 1][j] = False
        if di == -1: v[i][j] = False
        if dj == 1: h[i][j + 1] = False
        if dj == -1: h[i][j] = False
        seen[i + di][j + dj] = True
        stack.append((i + di, j + dj))
    inner = [("h", i, j) for i in range(n) for j in range(1, n) if h[i][j]] + \
            [("v", i, j) for i in range(1, n) for j in range(n) if v[i][j]]
    for kind, i, j in rng.sample(inner, int(loops * len(inner))):
        (h if kind == "h" else v)[i][j] = False
    return h, v


def runs(flags):
    """(start, end) of each run of consecutive true flags, end exclusive."""
    out = []
    start = None
    for i, flag in enumerate(list(flags) + [False]):
        if flag and start is None:
            start = i
        elif not flag and start is not None:
            out.append((start, i))
            start = None
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out")
    parser.add_argument("--cells", type=int, default=16)
    parser.add_argument("--pitch", type=float, default=2.5)
    parser.add_argument("--loops", type=float, default=0.1)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    n, p, t = args.cells, args.pitch, 0.15
    h, v = carve(n, args.loops, args.seed)
    boxes = []
    # Merge runs of wall pieces along each grid line; each box spans whole
    # cell edges plus half a thickness at both ends so that corners close.
    for j in range(n + 1):
        for a, b in runs([h[i][j] for i in range(n)]):
            boxes.append(((a + b) * p / 2, j * p, (b - a) * p / 2 + t / 2, t / 2))
    for i in range(n + 1):
        for a, b in runs(v[i]):
            boxes.append((i * p, (a + b) * p / 2, t / 2, (b - a) * p / 2 + t / 2))
    side = n * p
    lines = ['<mujoco model="maze">', "  <worldbody>",
             f'    <geom name="floor" type="plane" pos="{side / 2} {side / 2} 0" '
             f'size="{side / 2 + 1} {side / 2 + 1} 0.1"/>']
    for b, (x, y, sx, sy) in enumerate(boxes):
        lines.append(f'    <geom name="wall_{b}" type="box" size="{sx:.4f} {sy:.4f} 0.5" '
                     f'pos="{x:.4f} {y:.4f} 0.5" rgba="0.9 0.9 0.85 1"/>')
    lines.append(f'    <site name="start" pos="{p / 2} {p / 2} 0" euler="0 0 0"/>')
    lines += ["  </worldbody>", "</mujoco>", ""]
    with open(args.out, "w") as f:
        f.write("\n".join(lines))
    print(f"{args.out}: {len(boxes)} walls, {side:g} x {side:g} m", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
