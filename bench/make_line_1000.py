#!/usr/bin/env python3
"""Writes scenarios/bench/line_1000.json, issue 30's benchmark line, from line_1000_belts.json
(the infeed and transfer belts, the chute and the bin) by adding a roller singulator between the
transfer belt and the chute, and a catch floor under the line.

usage: python3 bench/make_line_1000.py [DURATION_S]   (default 60)

The singulator is a looped bed: 35 steel rollers (R 30 mm, 0.9 m long: the eight lanes) at a
pitch of 80 mm, carried round a closed path at V = 0.32 m/s (a top run of 1.2 m from x 8.98 m,
roller centres at z 0.80 m, down 0.2 m at its end, back under it, up at its start), each
turning at 10 rad/s about its axis (docs/lines.md section 4). At 0.32 m/s a valley passes every
0.25 s: with one apple per lane and valley the bed carries the eight lanes' 32 apples per second.
Each roller's path is given as translation keyframes at its corners (the layer moves a keyframed
surface linearly between them); the keyframes run to one second past the run's end.

The chute starts under the bed's last valley, 0.75 m high, so that an apple leaving the bed lands
on it; the bin stays placed at the chute's bottom. The catch floor (a plastic plane at z = -0.5 m,
under the bin's floor) holds any apple that falls off the line instead of letting it fall for ever.
"""
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SCEN = os.path.join(HERE, "..", "scenarios", "bench")

V, R, PITCH, LENGTH = 0.32, 0.03, 0.08, 0.9
X0, L, ZT, DROP, SPIN = 8.98, 1.2, 0.80, 0.2, 10.0
X1 = X0 + L
PERIMETER = 2 * L + 2 * DROP


def path(s):
    """(x, z) of the point at arc length s along the loop (from the top run's start)."""
    s %= PERIMETER
    if s < L:
        return X0 + s, ZT
    s -= L
    if s < DROP:
        return X1, ZT - s
    s -= DROP
    if s < L:
        return X1 - s, ZT - DROP
    s -= L
    return X0, ZT - DROP + s


def rollers(duration):
    n = int(round(PERIMETER / PITCH))
    pitch = PERIMETER / n
    corners = [0.0, L, L + DROP, 2 * L + DROP]
    end = duration + 1.0
    loops = int(end * V / PERIMETER) + 2
    out = []
    for k in range(n):
        s0 = k * pitch
        x0, z0 = path(s0)
        times = sorted(((c - s0) % PERIMETER + m * PERIMETER) / V
                       for m in range(loops) for c in corners)
        keys = [[0.0, [0.0, 0.0, 0.0]]]
        for t in times:
            if 1e-6 < t < end - 1e-6:
                x, z = path(s0 + V * t)
                keys.append([round(t, 9), [round(x - x0, 12), 0.0, round(z - z0, 12)]])
        x, z = path(s0 + V * end)
        keys.append([end, [round(x - x0, 12), 0.0, round(z - z0, 12)]])
        out.append({"name": f"singulator-{k + 1}", "type": "roller", "material": "steel",
                    "radius_m": R, "length_m": LENGTH, "position_m": [round(x0, 12), 0, round(z0, 12)],
                    "axis": [0, 1, 0], "angular_velocity_rad_s": SPIN,
                    "motion": {"translation": {"keyframes": keys}}})
    return out


def main(argv):
    duration = float(argv[1]) if len(argv) > 1 else 60.0
    base = json.load(open(os.path.join(SCEN, "line_1000_belts.json")))
    surfaces = []
    for s in base["surfaces"]:
        if s["name"] == "chute":
            s = dict(s)
            # Its top edge under the bed's last valley (the flat chute's position is its centre:
            # 0.47 m along x and 0.171 m up from its centre to its top edge at 20 degrees).
            s["position_m"] = [round(X1 - 0.06 + 0.47, 12), 0, round(0.75 - 0.171, 12)]
        surfaces.append(s)
        if s["name"] == "transfer":
            surfaces.extend(rollers(duration))
    surfaces.append({"name": "catch-floor", "type": "plane", "material": "plastic",
                     "point_m": [0, 0, -0.5], "normal": [0, 0, 1]})
    d = dict(base)
    d["duration_s"] = duration
    d["surfaces"] = surfaces
    d["description"] = (
        "Issue 30 item 3 (benchmark line, not a shipped result): eight lanes fed at 4 apples per "
        "second each (32 per second, D 75 +- 5 mm) onto a 10 m rubber belt at 0.4 m/s, a drop of "
        "0.1 m onto a 4 m belt at 0.6 m/s, a roller singulator (a looped bed of 35 steel rollers, "
        "R 30 mm, pitch 80 mm, carried at 0.32 m/s over a 1.2 m top run and each turning at "
        "10 rad/s), a 20 degree steel chute under the bed's end and a 2 x 2 m plastic bin placed "
        "below the chute's end; a catch floor under the line; about 1000 apples in the line at "
        "once; 60 s. Written by bench/make_line_1000.py from line_1000_belts.json (the same line "
        "without the singulator). Run with: applesim bench scenarios/bench/line_1000.json "
        "--window 0:20 --window 20:40 --window 40:60")
    with open(os.path.join(SCEN, "line_1000.json"), "w") as f:
        json.dump(d, f, indent=1)
        f.write("\n")
    print(f"{len(rollers(duration))} rollers; wrote scenarios/bench/line_1000.json")


if __name__ == "__main__":
    main(sys.argv)
