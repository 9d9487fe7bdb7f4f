"""Tests of sim/tools/generate_building.py: a generated building passes its
checks, and each kind of broken building fails with the error that names
what is wrong (a too-narrow door, a room with no way in, a tour too close to
a wall, a start in a wall). Run by ctest (sim_generate_building_test, label
unit); Python 3 standard library only."""
import contextlib
import io
import math
import os
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "sim", "tools"))
import generate_building as gb  # noqa: E402

SMALL = ["--seed", "3", "--size", "24x18", "--corridors", "1", "--cross-corridors", "1",
         "--columns", "3", "--pillars", "2", "--free-walls", "2"]


def layout(argv):
    """The unchecked building of argv (as build() makes it)."""
    args = gb.parser().parse_args(argv + ["--out", "unused.xml"])
    args.size = gb.parse_size(args.size)
    args.room_width = gb.parse_range("--room-width", args.room_width)
    gb.validate(args)
    return gb.lay_out(args)


class GenerateBuildingTest(unittest.TestCase):
    def test_a_generated_building_passes_and_is_written(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "b.xml")
            self.assertEqual(gb.main(SMALL + ["--out", out]), 0)
            text = open(out).read()
        self.assertIn('<site name="start"', text)
        self.assertIn('<site name="tour_0"', text)
        self.assertIn('type="plane"', text)
        # Same arguments, same file.
        with tempfile.TemporaryDirectory() as tmp:
            again = os.path.join(tmp, "b.xml")
            gb.main(SMALL + ["--out", again])
            self.assertEqual(open(again).read(), text)

    def test_every_room_has_a_door_of_the_given_width_and_the_tour_enters_it(self):
        b = layout(SMALL + ["--door-width", "0.8"])
        gb.check(b)
        index = gb.ObstacleIndex(b.obstacles)
        self.assertGreaterEqual(len(b.rooms), 8)
        for r in b.rooms:
            self.assertAlmostEqual(gb.door_width(r, index), 0.8, delta=0.011)
        entered = {r.name for r in b.door_legs.values()}
        self.assertEqual(entered, {r.name for r in b.rooms})

    def test_rotation_keeps_the_tour_and_start_with_the_walls(self):
        _, b, w = gb.build(SMALL + ["--rotation-deg", "30", "--out", "x.xml"])
        _, b0, w0 = gb.build(SMALL + ["--out", "x.xml"])
        self.assertEqual(len(w.boxes), len(w0.boxes))
        # The start's distance to the first wall is the same in both.
        def d(world):
            (sx, sy, _), (_, cx, cy, *_rest) = world.start, world.boxes[0]
            return math.hypot(sx - cx, sy - cy)
        self.assertAlmostEqual(d(w), d(w0), places=3)
        self.assertAlmostEqual(w.start[2], 30.0)

    def test_a_too_narrow_door_is_an_error_naming_the_door(self):
        with self.assertRaisesRegex(gb.BuildingError,
                                    r"door of c0\w+ at .* is 0\.4\d m wide: the robot "
                                    r"\(0\.38 m\) needs at least 0\.48 m"):
            gb.build(SMALL + ["--door-width", "0.45", "--out", "x.xml"])

    def test_a_room_with_its_door_walled_up_is_not_connected(self):
        b = layout(SMALL)
        room = b.rooms[3]
        # Wall the door up: a box over the gap in the corridor wall.
        half = b.args.door_width / 2 + 0.01
        b.obstacles.append(gb.Obstacle("bricks", "box", room.door_x, room.door_y, half, 0.075))
        # The connectivity check on its own, then all checks (the door's
        # width check comes first).
        with self.assertRaisesRegex(gb.BuildingError,
                                    rf"tour_\d+ at .* in {room.name} is not connected to "
                                    r"the start"):
            gb.check_connected(b)
        with self.assertRaisesRegex(gb.BuildingError, rf"door of {room.name} .* is 0\.00 m wide"):
            gb.check(b)

    def test_a_tour_too_close_to_a_wall_is_an_error_naming_waypoint_and_wall(self):
        b = layout(SMALL)
        # Move a corridor waypoint 0.3 m from the outer wall's face.
        i = len(b.tour) - 1
        b.tour[i] = (b.args.size[0] - 0.3, b.tour[i][1])
        with self.assertRaisesRegex(gb.BuildingError,
                                    rf"tour_{i} at .* is 0\.30 m from outer_east "
                                    r"\(needs >= 0\.6 m\)"):
            gb.check(b)

    def test_a_leg_through_a_door_off_its_middle_is_an_error(self):
        b = layout(SMALL)
        i, room = next(iter(b.door_legs.items()))
        for k in (i, i + 1):  # both ends 0.2 m to the side
            b.tour[k] = (b.tour[k][0] + 0.2, b.tour[k][1])
        with self.assertRaisesRegex(gb.BuildingError,
                                    rf"tour_{i} -> tour_{i + 1}: the leg through the door of "
                                    rf"{room.name} is not on the door's axis"):
            gb.check_tour(b, gb.ObstacleIndex(b.obstacles))

    def test_a_start_in_a_wall_is_an_error(self):
        b = layout(SMALL)
        x, y, yaw = b.start
        b.start = (0.2, y, yaw)  # the body reaches into the west wall
        with self.assertRaisesRegex(gb.BuildingError, r"start \(0\.20, .*\): the robot's body"):
            gb.check_start(b, gb.ObstacleIndex(b.obstacles))

    def test_bad_arguments_are_errors_naming_the_option(self):
        for argv, message in ((["--size", "40"], "--size: expected WIDTHxHEIGHT"),
                              (["--size", "5x5"], "--size: each side must be at least 8 m"),
                              (["--room-width", "3"], "--room-width: expected MIN:MAX"),
                              (["--door-width", "-1"], "--door-width: expected a value > 0"),
                              (["--corridor-width", "1.0"], "--corridor-width: at least"),
                              (["--corridors", "9"], "--corridors: 9 corridors leave rows")):
            with self.assertRaisesRegex(gb.BuildingError, message):
                gb.build(SMALL + argv + ["--out", "x.xml"])

    def test_hostile_options_are_usage_errors_in_bounded_time(self):
        # docs/reliability.md: before, --size infxinf and --room-width 0.01:0.02
        # looped forever, nan and 'x"y' wrote a broken world with exit 0.
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "b.xml")
            for argv, message in ((["--size", "infxinf"], "--size: each side must be at most"),
                                  (["--room-width", "0.01:0.02"], "--room-width: expected 1 <="),
                                  (["--rotation-deg", "nan"], "--rotation-deg: expected degrees"),
                                  (["--name", 'x"y'], "--name: expected letters"),
                                  (["--columns", "1000000000"], "--columns: expected a count")):
                with self.assertRaisesRegex(gb.OptionError, message):
                    gb.build(SMALL + argv + ["--out", out])
                with self.assertRaises(SystemExit) as exit_status:
                    with contextlib.redirect_stderr(io.StringIO()):
                        gb.main(SMALL + argv + ["--out", out])
                self.assertEqual(exit_status.exception.code, 2, argv)
            self.assertEqual(os.listdir(tmp), [])
            # An --out that cannot be written: a one-line error, exit 1.
            with contextlib.redirect_stderr(io.StringIO()) as err:
                self.assertEqual(gb.main(SMALL + ["--out", os.path.join(tmp, "no", "b.xml")]), 1)
            self.assertIn("--out", err.getvalue())

    def test_a_failed_check_writes_nothing(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "b.xml")
            self.assertEqual(gb.main(SMALL + ["--door-width", "0.4", "--out", out]), 1)
            self.assertEqual(os.listdir(tmp), [])


if __name__ == "__main__":
    unittest.main()
