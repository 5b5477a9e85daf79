#!/usr/bin/env python3
"""Copies the LIGGGHTS side of the same-model comparison into the repository, as small text
files that tests/liggghts_parity.rs reads (issue 28): tests/data/liggghts/.

usage: store_reference.py OUT [DEST]

OUT is a folder where `liggghts.py drop roll pile scatter --out OUT` has run (it reads
OUT/liggghts.json and the run folders); DEST defaults to tests/data/liggghts/ of this checkout.
Writes:

  results.json        every figure of OUT/liggghts.json (drops, rolls, piles at each dt, the
                      scatter ensembles, the cdt piles), with each run's command line
  drops/NAME.txt      the per-step record of drop.in (t z vz fwall wy, as LIGGGHTS printed it),
                      kept over the contact only (from 20 steps before the touch to 20 after the
                      overlap closes) and thinned to every 10th step, keeping every row the
                      figures are read from (the touch, the peak, the force's end, the separation)
  rolls/NAME.txt      the record of roll.in (t x vx wy z fwall, every 0.1 ms as printed), thinned
                      to every 10 ms plus the 20 rows around the stop
  piles/start_jitter{1,2,3}.data   the three jittered starts (gen.py's start moved by up to 1 um)
  piles/NAME.dump     the final apples (write_dump: id type radius x y z vx vy vz c_cn) of the
                      piles compared with applesim: epsd2 and cdt at dt 1e-4 from gen.py's start
                      and from the three jittered starts
  logs/NAME.log       LIGGGHTS's log of each stored run (its version line, the thermo rows); in
                      the logs and the command lines the deck folder reads bench/models/ and
                      the run folder OUT/

gen.py's start itself is assets/piles/liggghts_1000.json (the same apples; the test checks it
against piles/start.data, which is gen.py's data file as LIGGGHTS read it).
"""
import json
import os
import shutil
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import liggghts as lig  # noqa: E402

R = lig.R


def rows_with_text(path):
    head, rows = None, []
    with open(path) as f:
        for line in f:
            if line[:1].isdigit() or line[:1] == "-":
                rows.append((line, [float(x) for x in line.split()]))
            elif head is None:
                head = line
    return head, rows


def thin_drop(src, dst):
    head, rows = rows_with_text(src)
    v = [r for _, r in rows]
    k_touch = next(i for i in range(1, len(v)) if v[i][1] < R)
    f0 = next(i for i in range(len(v)) if v[i][3] > 0)
    f1 = f0
    while f1 + 1 < len(v) and v[f1 + 1][3] > 0:
        f1 += 1
    peak = max(range(f0, f1 + 1), key=lambda i: v[i][3])
    kmin = min(range(len(v)), key=lambda i: v[i][1])
    k_sep = next((i for i in range(kmin, len(v)) if v[i][1] >= R), len(v) - 1)
    first, last = max(0, min(k_touch, f0) - 20), min(len(v) - 1, max(k_sep, f1) + 20)
    keep = {k_touch - 1, k_touch, f0 - 1, f0, peak - 1, peak, peak + 1, f1 - 1, f1, f1 + 1, k_sep - 1, k_sep,
            first, last}
    with open(dst, "w") as f:
        f.write(head)
        for i in range(first, last + 1):
            if (i - first) % 10 == 0 or i in keep:
                f.write(rows[i][0])


def thin_roll(src, dst):
    head, rows = rows_with_text(src)
    v = [r for _, r in rows]
    k = next((i for i in range(1, len(v)) if v[i][2] <= 0), None)
    near = set(range(k - 10, k + 10)) if k else set()
    with open(dst, "w") as f:
        f.write(head)
        for i, (text, r) in enumerate(rows):
            if i % 100 == 0 or i in near or i == len(rows) - 1:
                f.write(text)


def main(argv):
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__)
        return 0 if argv else 2
    out = os.path.abspath(argv[0])
    dest = os.path.abspath(argv[1]) if len(argv) > 1 else os.path.join(HERE, "..", "..", "tests", "data", "liggghts")
    res = json.load(open(os.path.join(out, "liggghts.json")))
    for sub in ("drops", "rolls", "piles", "logs"):
        os.makedirs(os.path.join(dest, sub), exist_ok=True)

    def command(name):
        """The run's command line, with this checkout's deck folder as bench/models/ and the
        run folder as OUT/."""
        line = open(os.path.join(out, name, "command.txt")).read().strip()
        return line.replace(HERE + os.sep, "bench/models/").replace(out + os.sep, "OUT/")

    def log(name):
        text = open(os.path.join(out, name, "log.lammps")).read()
        with open(os.path.join(dest, "logs", name + ".log"), "w") as f:
            f.write(text.replace(HERE + os.sep, "bench/models/").replace(out + os.sep, "OUT/"))

    for r in res.get("drop", []):
        if "error" in r:
            continue
        r["command"] = command(r["name"])
        if r["dt_s"] == 1e-6:
            thin_drop(os.path.join(out, r["name"], "rec.txt"), os.path.join(dest, "drops", r["name"] + ".txt"))
            log(r["name"])
    for r in res.get("roll", []):
        if "error" in r:
            continue
        r["command"] = command(r["name"])
        thin_roll(os.path.join(out, r["name"], "rec.txt"), os.path.join(dest, "rolls", r["name"] + ".txt"))
        log(r["name"])
    stored = {f"pile_{m}_dt0.0001{j}" for m in ("epsd2", "cdt") for j in ("", "_jitter1", "_jitter2", "_jitter3")}
    for key in ("pile", "pile_cdt", "pile_scatter"):
        for r in res.get(key, []):
            if "error" in r:
                continue
            r["command"] = command(r["name"])
            if r["name"] in stored:
                shutil.copyfile(os.path.join(out, r["name"], "final.dump"),
                                os.path.join(dest, "piles", r["name"] + ".dump"))
                log(r["name"])
    if "pile" in res:
        shutil.copyfile(os.path.join(out, "pile", "pile.data"), os.path.join(dest, "piles", "start.data"))
    if "pile_scatter" in res:
        for seed in (1, 2, 3):
            shutil.copyfile(os.path.join(out, "pile", f"pile_jitter{seed}.data"),
                            os.path.join(dest, "piles", f"start_jitter{seed}.data"))
    res.pop("machine", None)
    with open(os.path.join(dest, "results.json"), "w") as f:
        json.dump(res, f, indent=1)
        f.write("\n")
    total = 0
    for root, _, files in os.walk(dest):
        for name in files:
            size = os.path.getsize(os.path.join(root, name))
            total += size
            if size > 500_000:
                print(f"warning: {os.path.join(root, name)} is {size} bytes")
    print(f"stored {dest}: {total} bytes")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
