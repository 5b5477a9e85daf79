#!/usr/bin/env python3
"""Awake apples in 3-5 s at `preview` and `balanced` over several starts of the same-model pile
(issue 19, item 5: preview must let the pile sleep no less than balanced).

usage: awake_starts.py [--seeds N] [--applesim PATH] [--out DIR]

The pile is chaotic: which apples end up twisting about a contact normal (nothing stops that
spin in LIGGGHTS's model, so they never sleep) changes from start to start, and so does the
count. Start 0 is gen.py's pile (assets/piles/liggghts_1000.json); start k >= 1 is that pile
with every apple moved sideways by up to 1 um (liggghts.py's jittered_data, seed k; 1-3 are the
starts of `applesim.py scatter`). For each start, `applesim bench SCENARIO --json --threads 1
--window 3:5` of pile_epsd2_adaptive_{preview,balanced}.json; prints the mean awake apples over
the window's steps, the top apple's height and the wall time, then the means.
"""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import liggghts as lig  # noqa: E402

ROOT = os.path.join(HERE, "..", "..")
REF = os.path.abspath(os.path.join(ROOT, "assets", "piles", "liggghts_1000.json"))


def start_pile(out, seed):
    """The roster file of start `seed` (0: gen.py's pile itself)."""
    if seed == 0:
        return REF
    ref = json.load(open(REF))
    lines = open(lig.jittered_data(out, seed)).read().splitlines()
    k = lines.index("Atoms")
    pile = []
    for line in lines[k + 1:]:
        p = line.split()
        if len(p) != 7:
            continue
        a = ref[int(p[0]) - 1]
        pile.append({"name": a["name"], "diameter_m": a["diameter_m"],
                     "position_m": [float(p[4]), float(p[5]), float(p[6])]})
    path = os.path.join(out, "pile", f"applesim_pile_jitter{seed}.json")
    json.dump(pile, open(path, "w"))
    return path


def main(argv):
    seeds, exe, out = 9, os.path.join(ROOT, "target", "release", "applesim"), "/tmp/awake_starts"
    i = 0
    while i < len(argv):
        if argv[i] == "--seeds":
            seeds = int(argv[i + 1])
        elif argv[i] == "--applesim":
            exe = argv[i + 1]
        elif argv[i] == "--out":
            out = argv[i + 1]
        else:
            sys.exit(__doc__)
        i += 2
    os.makedirs(os.path.join(out, "pile"), exist_ok=True)
    means = {"preview": [], "balanced": []}
    print("| start | preview: awake 3-5 s (height m, wall s) | balanced: awake 3-5 s (height m, wall s) |")
    print("|---|---|---|")
    for seed in range(seeds):
        pile = start_pile(out, seed)
        cells = []
        for acc in ("preview", "balanced"):
            sc = json.load(open(os.path.join(HERE, "scenarios", f"pile_epsd2_adaptive_{acc}.json")))
            sc["generators"][0]["file"] = pile
            path = os.path.join(out, f"pile_{acc}_{seed}.json")
            json.dump(sc, open(path, "w"), indent=1)
            r = subprocess.run([exe, "bench", path, "--json", "--threads", "1", "--window", "3:5"],
                               capture_output=True, text=True, check=True)
            b = json.loads(r.stdout)
            awake = b["windows"][0]["mean_awake_apples"]
            means[acc].append(awake)
            cells.append(f"{awake:.2f} ({b['pile_height_m']:.4f}, {b['wall_s']:.2f})")
        print(f"| {seed} | {cells[0]} | {cells[1]} |", flush=True)
    fewer = sum(p <= b for p, b in zip(means["preview"], means["balanced"]))
    print(f"| mean | {sum(means['preview']) / seeds:.2f} | {sum(means['balanced']) / seeds:.2f} |")
    print(f"preview no more than balanced on {fewer} of {seeds} starts")


if __name__ == "__main__":
    main(sys.argv[1:])
