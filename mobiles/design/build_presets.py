#!/usr/bin/env python3
"""Design of the two preset mobiles (mobiles/steel-fish.json, mobiles/southern-cross.json).

The presets are data; this script is how they were drawn, kept so that a change of design is a change
here and a re-run (`python3 mobiles/design/build_presets.py`), not hand-editing hundreds of numbers.
It needs only the Python standard library. World frame: metres, y up, the designed rest pose.

Construction rules, so that balance mode "mass" can make the drawn pose an equilibrium:
- a leaf (nothing hangs from it) hangs on a vertical thread, with its plate's centroid or its ball's
  centre exactly below the joint;
- an arm is a thread down from its joint to a pivot on a (slightly drooping) wire; children hang from
  the wire's ends, and an arm may carry its own plate welded at one end, on the side opposite its child;
- every joint is the end point of the parent's wire and the top of the child's thread.
"""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.dirname(HERE)


def r9(x):
    return round(x, 9)


def vec(v):
    return [r9(c) for c in v]


def add(a, b):
    return [a[i] + b[i] for i in range(3)]


def scale(a, k):
    return [c * k for c in a]


def centroid(points):
    """Area centroid of a simple polygon (either winding)."""
    a = cx = cy = 0.0
    n = len(points)
    for i in range(n):
        x0, y0 = points[i]
        x1, y1 = points[(i + 1) % n]
        cr = x0 * y1 - x1 * y0
        a += cr
        cx += (x0 + x1) * cr
        cy += (y0 + y1) * cr
    a *= 0.5
    return cx / (6 * a), cy / (6 * a)


def centred(points):
    cx, cy = centroid(points)
    return [[x - cx, y - cy] for x, y in points]


def heading(deg):
    t = math.radians(deg)
    return [math.cos(t), 0.0, math.sin(t)]


# Outlines in plate coordinates (u along the plate's horizontal direction, v up), metres.
def fish(length, height):
    """A stylised fish: lens-shaped body and a notched tail (concave)."""
    pts = []
    body = 0.72 * length
    for k in range(13):  # upper edge, nose to tail root
        s = k / 12
        pts.append([body * (0.5 - s), 0.5 * height * math.sin(math.pi * s) ** 0.8])
    tail = length - body
    pts += [[-body / 2 - tail, 0.42 * height], [-body / 2 - 0.55 * tail, 0.0], [-body / 2 - tail, -0.42 * height]]
    for k in range(1, 12):  # lower edge, tail root to nose
        s = 1 - k / 12
        pts.append([body * (0.5 - s), -0.42 * height * math.sin(math.pi * s) ** 0.8])
    return pts


def leaf(length, width, droop=0.0):
    """A pointed leaf hanging from its top; `droop` skews it (concave when large)."""
    pts = []
    for k in range(20):
        t = 2 * math.pi * k / 20
        y = 0.5 * length * math.cos(t)
        x = 0.5 * width * math.sin(t) * (abs(math.sin(t)) ** 0.3) + droop * (y / length) ** 2
        pts.append([x, y])
    return pts


def disc(radius, sides=28):
    return [[radius * math.cos(2 * math.pi * k / sides), radius * math.sin(2 * math.pi * k / sides)] for k in range(sides)]


def plate_shape(points, origin, direction, thickness):
    return {"plate": {"plane": {"origin": vec(origin), "u": vec(direction), "v": [0, 1, 0]},
                      "thickness": thickness, "points": [[r9(x), r9(y)] for x, y in points]}}


def wire(a, b, radius):
    return {"wire": {"from": vec(a), "to": vec(b), "radius": radius}}


class Mobile:
    def __init__(self, name, total_mass, hook, hook_radius=0.012):
        self.doc = {"name": name, "aloft": 1, "balance": {"mode": "mass", "total_mass": total_mass},
                    "damping": {"linear": 0.02, "angular": 0.02},
                    "components": [{"name": "hook", "fixed": True, "color": "#3a3a3a",
                                    "shapes": [{"sphere": {"center": vec(hook), "radius": hook_radius}}]}]}

    def add(self, component):
        self.doc["components"].append(component)

    def arm(self, name, parent, joint, thread, left, right, deg, radius, color, droop=0.06,
            plate=None, plate_end="left", thread_radius=0.0008):
        """An arm: thread from `joint` down to the pivot, wire from the left end to the right end
        (each end drooping by `droop` of its length). Returns (left end, right end) world points."""
        d = heading(deg)
        pivot = add(joint, [0, -thread, 0])
        left_end = add(add(pivot, scale(d, -left)), [0, -droop * left, 0])
        right_end = add(add(pivot, scale(d, right)), [0, -droop * right, 0])
        shapes = [wire(joint, pivot, thread_radius), wire(left_end, pivot, radius), wire(pivot, right_end, radius)]
        if plate is not None:
            points, thickness = plate
            end = left_end if plate_end == "left" else right_end
            # The plate is welded by its edge point nearest the arm, hanging below the wire end.
            sign = -1 if plate_end == "left" else 1
            anchor = max(points, key=lambda p: p[1] - 0.3 * sign * p[0])
            pts = [[x - anchor[0], y - anchor[1]] for x, y in points]
            shapes.append(plate_shape(pts, end, d, thickness))
        self.add({"name": name, "parent": parent, "joint": vec(joint), "color": color, "shapes": shapes})
        return left_end, right_end

    def plate_leaf(self, name, parent, joint, thread, points, deg, thickness, color):
        d = heading(deg)
        pts = centred(points)
        top = max(y for _, y in pts)
        centre = add(joint, [0, -thread - top, 0])
        self.add({"name": name, "parent": parent, "joint": vec(joint), "color": color,
                  "shapes": [wire(joint, add(centre, [0, top, 0]), 0.0006), plate_shape(pts, centre, d, thickness)]})

    def ball_leaf(self, name, parent, joint, thread, radius, color, density=None):
        centre = add(joint, [0, -thread - radius, 0])
        ball = {"sphere": {"center": vec(centre), "radius": radius}}
        if density:
            ball["density"] = density
        self.add({"name": name, "parent": parent, "joint": vec(joint), "color": color,
                  "shapes": [wire(joint, add(centre, [0, radius, 0]), 0.0006), ball]})

    def write(self, filename):
        with open(os.path.join(OUT, filename), "w") as f:
            json.dump(self.doc, f, indent=1)
            f.write("\n")


def steel_fish():
    """Our reading of Calder's 'Steel Fish' (1934) as in the paper's figure 3: nine components O0..O8,
    eight spherical joints; wires, balls and sheet-steel plates. O0 is the hook."""
    black, red, white, yellow, blue = "#1b1b1b", "#b3261e", "#ece8dc", "#e0a21b", "#1f4e8c"
    m = Mobile("Steel Fish", 2.4, [0, 2.6, 0])
    # O1: the long top arm, the big steel fish welded to its left end.
    l1, r1 = m.arm("O1 top arm", "hook", [0, 2.59, 0], 0.06, 0.55, 0.75, 0, 0.003, black,
                   plate=(fish(0.42, 0.20), 0.0025), plate_end="left")
    # O2: the second arm, turned 35 degrees about the vertical.
    l2, r2 = m.arm("O2 arm", "O1 top arm", r1, 0.10, 0.30, 0.45, 35, 0.0025, black)
    # O3: a large white plate on the left of O2.
    m.plate_leaf("O3 white leaf", "O2 arm", l2, 0.08, leaf(0.30, 0.18, 0.03), 60, 0.002, white)
    # O6: the arm whose two ends carry O4 and O5 (the paper's example of mass ratios by lever arms).
    l6, r6 = m.arm("O6 arm", "O2 arm", r2, 0.12, 0.22, 0.30, -20, 0.002, black)
    m.ball_leaf("O4 red ball", "O6 arm", l6, 0.16, 0.045, red)
    # O5: a small arm with its own yellow plate at the right end, O7 hanging from its left end.
    l5, r5 = m.arm("O5 arm", "O6 arm", r6, 0.08, 0.16, 0.12, 70, 0.0018, black,
                   plate=(disc(0.06, 24), 0.002), plate_end="right")
    # O7: the lowest arm, a blue plate of its own at the right, O8 from its left end.
    l7, r7 = m.arm("O7 arm", "O5 arm", l5, 0.10, 0.14, 0.10, 120, 0.0015, black,
                   plate=(leaf(0.12, 0.08), 0.0015), plate_end="right")
    m.plate_leaf("O8 small fish", "O7 arm", l7, 0.07, fish(0.16, 0.07), 150, 0.0015, red)
    # Densities "as built" (kg/m^3): close to the ones balance mode "mass" derives, so that in mode
    # "none" the mobile hangs nearly balanced and swings gently; the ball (painted wood) and the small
    # fish are a little off, as a maker's first cut would be.
    densities = {"O1 top arm": 7850, "O2 arm": 3970, "O3 white leaf": 4880, "O6 arm": 1850,
                 "O4 red ball": 410, "O5 arm": 2230, "O7 arm": 2100, "O8 small fish": 1500}
    for c in m.doc["components"]:
        if c["name"] in densities:
            c["density"] = densities[c["name"]]
    m.write("steel-fish.json")


def southern_cross():
    """After Calder's 'Southern Cross' (1963): a standing stabile base carries a long balanced arm
    from which a chain of arms with black and red discs hangs, the discs growing smaller down the chain."""
    black, red = "#141414", "#c1121f"
    m = Mobile("Southern Cross", 3.0, [0, 2.2, 0], hook_radius=0.02)
    base = m.doc["components"][0]
    base["name"] = "stabile"
    base["shapes"] += [
        wire([0, 2.2, 0], [-0.45, 0.0, -0.3], 0.012),
        wire([0, 2.2, 0], [0.45, 0.0, -0.3], 0.012),
        wire([0, 2.2, 0], [0.0, 0.0, 0.5], 0.012),
        {"box": {"center": [0, 0.01, 0], "size": [1.1, 0.02, 1.1]}},
    ]
    # The long arm pivots on the stabile's tip; a big black disc on its left, the chain on its right.
    l1, r1 = m.arm("A1 long arm", "stabile", [0, 2.19, 0], 0.05, 0.7, 1.0, 0, 0.004, black, droop=0.04,
                   plate=(disc(0.16), 0.003), plate_end="left")
    # A chain of arms; each carries a disc at its right end and the next arm at its left.
    joint = r1
    sizes = [(0.32, 0.26, 0.11, 15), (0.26, 0.22, 0.09, 60), (0.22, 0.18, 0.075, 105),
             (0.18, 0.15, 0.06, 150), (0.15, 0.12, 0.05, 195)]
    for k, (left, right, radius, deg) in enumerate(sizes):
        colour = red if k % 2 == 0 else black
        l, r = m.arm(f"A{k + 2} arm", m.doc["components"][-1]["name"], joint, 0.10, left, right, deg,
                     0.003 - 0.0003 * k, black, plate=(disc(radius), 0.0025), plate_end="right")
        joint = l
    # The chain ends in a pair of small discs on a last arm.
    l, r = m.arm("A7 arm", m.doc["components"][-1]["name"], joint, 0.08, 0.09, 0.11, 240, 0.0015, black)
    m.plate_leaf("D1 red disc", "A7 arm", l, 0.05, disc(0.04), 200, 0.002, red)
    m.plate_leaf("D2 black disc", "A7 arm", r, 0.06, disc(0.035), 280, 0.002, black)
    # Densities as built (kg/m^3): the discs are thinner (lighter) down the chain, close to what balance
    # mode "mass" derives; in mode "none" the red disc at the end is a little heavy, so it swings.
    densities = {"A1 long arm": 7850, "A2 arm": 6635, "A3 arm": 4137, "A4 arm": 2641, "A5 arm": 1762,
                 "A6 arm": 1127, "A7 arm": 980, "D1 red disc": 1060, "D2 black disc": 1003}
    for c in m.doc["components"]:
        if c["name"] in densities:
            c["density"] = densities[c["name"]]
    m.write("southern-cross.json")


if __name__ == "__main__":
    steel_fish()
    southern_cross()
