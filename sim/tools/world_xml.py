"""The MJCF writer of mjslam's generated worlds: a World holds walls (boxes),
pillars (cylinders), a start and a closed tour, checks the tour's clearance and
writes the file. Used by generate_worlds.py (the shipped worlds) and
generate_building.py (office buildings). Conventions: worlds/README.md.
Python 3 standard library only.
"""
import math
import sys

T = 0.15      # wall thickness
H = 1.0       # wall height

def fmt(v): 
    s = f"{v:.4f}".rstrip('0').rstrip('.')
    return "0" if s in ("-0", "") else s

class World:
    def __init__(self, name, comment):
        self.name, self.comment = name, comment
        self.boxes = []     # (name, cx, cy, hx, hy, yaw_deg)
        self.cyls = []      # (name, cx, cy, r)
        self.tour = []
        self.start = None
        self.extent = None
        self.thickness = T  # wall thickness named in the file's comment
    def box(self, name, cx, cy, hx, hy, yaw_deg=0.0):
        self.boxes.append((name, cx, cy, hx, hy, yaw_deg))
    def wall(self, name, x0, y0, x1, y1, ext0=True, ext1=True, t=T):
        """A wall on the centreline (x0,y0)-(x1,y1); ends extended by t/2 where they join other walls."""
        L = math.hypot(x1 - x0, y1 - y0)
        ux, uy = (x1 - x0) / L, (y1 - y0) / L
        a = -t / 2 if ext0 else 0.0
        b = L + (t / 2 if ext1 else 0.0)
        cx = x0 + ux * (a + b) / 2; cy = y0 + uy * (a + b) / 2
        self.box(name, cx, cy, (b - a) / 2, t / 2, math.degrees(math.atan2(uy, ux)))
    def cyl(self, name, cx, cy, r):
        self.cyls.append((name, cx, cy, r))

    # --- geometry checks -----------------------------------------------------
    def dist(self, px, py):
        d = 1e9
        for (_, cx, cy, hx, hy, yaw) in self.boxes:
            c, s = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))
            dx, dy = px - cx, py - cy
            lx, ly = c * dx + s * dy, -s * dx + c * dy
            ex, ey = max(0, abs(lx) - hx), max(0, abs(ly) - hy)
            d = min(d, math.hypot(ex, ey))
        for (_, cx, cy, r) in self.cyls:
            d = min(d, max(0, math.hypot(px - cx, py - cy) - r))
        return d
    def check(self):
        n = len(self.tour)
        worst_pt = min(self.dist(x, y) for x, y in self.tour)
        worst_seg = 1e9
        for i in range(n):
            (x0, y0), (x1, y1) = self.tour[i], self.tour[(i + 1) % n]
            for k in range(101):
                f = k / 100
                worst_seg = min(worst_seg, self.dist(x0 + f * (x1 - x0), y0 + f * (y1 - y0)))
        length = sum(math.hypot(self.tour[(i+1)%n][0]-self.tour[i][0], self.tour[(i+1)%n][1]-self.tour[i][1]) for i in range(n))
        sx, sy, _ = self.start
        print(f"{self.name}: {n} waypoints, tour {length:.1f} m, min clearance waypoints {worst_pt:.3f} m, segments {worst_seg:.3f} m, start {self.dist(sx, sy):.3f} m", file=sys.stderr)
        assert worst_pt >= 0.6 and worst_seg >= 0.6, self.name

    def xml(self):
        (x0, y0, x1, y1) = self.extent
        fx, fy = (x0 + x1) / 2, (y0 + y1) / 2
        hx, hy = (x1 - x0) / 2 + 1, (y1 - y0) / 2 + 1
        out = []
        out.append(f'<!--\n{self.comment}\n-->')
        out.append(f'<mujoco model="{self.name}">')
        out.append('  <asset>')
        out.append('    <texture name="floor_grid" type="2d" builtin="checker" rgb1="0.82 0.82 0.80"')
        out.append('             rgb2="0.74 0.74 0.72" width="256" height="256"/>')
        out.append('    <material name="floor_mat" texture="floor_grid" texrepeat="1 1" texuniform="true"/>')
        out.append('    <material name="wall_mat" rgba="0.93 0.90 0.84 1"/>')
        out.append('    <material name="pillar_mat" rgba="0.60 0.66 0.74 1"/>')
        out.append('  </asset>')
        out.append('  <worldbody>')
        out.append(f'    <light name="sun" directional="true" pos="{fmt(fx)} {fmt(fy)} 8" dir="0 0 -1" diffuse="0.7 0.7 0.7"/>')
        out.append(f'    <geom name="floor" type="plane" pos="{fmt(fx)} {fmt(fy)} 0" size="{fmt(hx)} {fmt(hy)} 0.1" material="floor_mat"/>')
        out.append('')
        out.append(f'    <!-- Walls: boxes {fmt(self.thickness)} m thick, {fmt(H)} m tall (yaw in degrees). -->')
        for (name, cx, cy, hx_, hy_, yaw) in self.boxes:
            e = f' euler="0 0 {fmt(yaw)}"' if abs(yaw) > 1e-9 else ''
            out.append(f'    <geom name="{name}" type="box" material="wall_mat" size="{fmt(hx_)} {fmt(hy_)} {fmt(H/2)}" pos="{fmt(cx)} {fmt(cy)} {fmt(H/2)}"{e}/>')
        if self.cyls:
            out.append('')
            out.append('    <!-- Pillars. -->')
            for (name, cx, cy, r) in self.cyls:
                out.append(f'    <geom name="{name}" type="cylinder" material="pillar_mat" size="{fmt(r)} {fmt(H/2)}" pos="{fmt(cx)} {fmt(cy)} {fmt(H/2)}"/>')
        out.append('')
        sx, sy, syaw = self.start
        out.append('    <!-- Default start pose of the robot frame R (the point h): x, y, yaw. -->')
        out.append(f'    <site name="start" group="4" pos="{fmt(sx)} {fmt(sy)} 0.01" euler="0 0 {fmt(syaw)}" size="0.1" rgba="0.1 0.8 0.1 1"/>')
        out.append('    <!-- Closed tour for the point h, >= 0.6 m from every wall. -->')
        for i, (x, y) in enumerate(self.tour):
            out.append(f'    <site name="tour_{i}" group="4" pos="{fmt(x)} {fmt(y)} 0.01" size="0.06" rgba="0.9 0.5 0.1 1"/>')
        out.append('  </worldbody>')
        out.append('</mujoco>')
        return "\n".join(out) + "\n"
