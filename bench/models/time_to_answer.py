#!/usr/bin/env python3
"""Time to an answer (issue 19, build item 5): the same-model 1000-apple pile, 0-5 s, in LIGGGHTS
and applesim, timed in alternating rounds.

usage: time_to_answer.py [--out DIR] [--rounds N] [--applesim PATH] [--threads N] [--no-fixed]
       time_to_answer.py --diagnose [--out DIR] [--applesim PATH] [--threads N]

Each round runs, strictly one after the other (never two at once):
  LIGGGHTS dt 1e-4 (the reference step), applesim adaptive `balanced`, LIGGGHTS dt 5e-4 (its
  largest dt within 1 %, by the four-start ensembles of liggghts.py scatter), applesim adaptive
  `preview`, and (unless --no-fixed) applesim at LIGGGHTS's two fixed steps, 1e-4 and 5e-4 s.
The codes alternate so that a change of the machine's load hits both alike; the load average is
recorded before every run. LIGGGHTS: `liggghts -in pile.in` (serial, OMP_NUM_THREADS=1), its
"Loop time" (the stepping, without reading the data file) and the process wall time. applesim:
`applesim bench SCENARIO --json --threads 1`, its `wall_s` (the stepping, without loading the
scenario) and the process wall time. Neither is pinned to a core. Also each run's settled height,
apple-apple contacts per apple, and for applesim the mean awake apples per window (3-5 s:
"settled").

Writes DIR/time_to_answer.json (default DIR /work/lig-runs/models; LIGGGHTS's runs go to
DIR/pile_epsd2_dt*_tta{round}) and prints the medians and the ratios LIGGGHTS / applesim.

--diagnose: instead, `applesim bench` once each of the scenarios diag_*.json (make_scenarios.py:
why the pile stays awake at preview: a fixed 6e-4 s step, accuracy 16 and 24, tangential
mindlin, restitution 0.65) and of the two adaptive piles; the awake apples per window, the
steps, the height and contacts; DIR/diagnose.json.
"""
import json
import os
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import applesim as app  # noqa: E402
import liggghts as lig  # noqa: E402


def lig_run(out, dt, k):
    load = os.getloadavg()[0]
    r = lig.run_pile(out, [dt], tag=f"_tta{k}")[0]
    return {"code": "LIGGGHTS", "case": f"dt {dt:g}", "round": k, "load_before": load,
            "loop_s": r.get("loop_s"), "process_s": r.get("wall_s"), "error": r.get("error"),
            "height_m": r.get("z_max_m"), "top25_m": r.get("z_top25_mean_m"),
            "contacts_per_apple": r.get("apple_apple_contacts_per_apple"), "ke_j": r.get("ke_j")}


def app_run(exe, out, name, case, k, threads):
    load = os.getloadavg()[0]
    b = app.bench(exe, name, out, threads)
    r = {"code": "applesim", "case": case, "round": k, "load_before": load,
         "loop_s": b.get("wall_s"), "process_s": b.get("process_wall_s"), "error": b.get("error")}
    if "error" not in b:
        w = b.get("windows") or []
        r.update(height_m=b["pile_height_m"], steps=b["steps"],
                 contacts_per_apple=w[-1]["apple_apple_contacts_per_apple"] if w else None,
                 awake={x["label"]: x["mean_awake_apples"] for x in w},
                 window_wall_s={x["label"]: x["wall_s"] for x in w},
                 window_steps={x["label"]: x["steps"] for x in w})
    return r


def main(argv):
    out, rounds, exe, threads, fixed, diagnose = "/work/lig-runs/models", 3, None, 1, True, False
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--out":
            out = argv[i + 1]; i += 1
        elif a == "--rounds":
            rounds = int(argv[i + 1]); i += 1
        elif a == "--applesim":
            exe = argv[i + 1]; i += 1
        elif a == "--threads":
            threads = int(argv[i + 1]); i += 1
        elif a == "--no-fixed":
            fixed = False
        elif a == "--diagnose":
            diagnose = True
        elif a in ("-h", "--help"):
            print(__doc__); return 0
        else:
            print(f"unknown argument {a} (see --help)", file=sys.stderr); return 2
        i += 1
    exe = exe or os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(HERE, "..", "..", "target")),
                              "release", "applesim")
    out = os.path.abspath(out)
    os.makedirs(out, exist_ok=True)
    if diagnose:
        return run_diagnosis(exe, out, threads)
    lig.REUSE = False
    runs = []
    t0 = time.time()
    for k in range(1, rounds + 1):
        seq = [lambda: lig_run(out, 1e-4, k),
               lambda: app_run(exe, out, "pile_epsd2_adaptive_balanced", "adaptive balanced", k, threads),
               lambda: lig_run(out, 5e-4, k),
               lambda: app_run(exe, out, "pile_epsd2_adaptive_preview", "adaptive preview", k, threads)]
        if fixed:
            seq += [lambda: app_run(exe, out, "pile_epsd2_dt1e-4", f"dt {1e-4:g}", k, threads),
                    lambda: app_run(exe, out, "pile_epsd2_dt5e-4", f"dt {5e-4:g}", k, threads)]
        for f in seq:
            r = f()
            runs.append(r)
            print(f"round {k}: {r['code']:8s} {r['case']:18s} loop {r['loop_s'] or float('nan'):7.2f} s, "
                  f"process {r['process_s'] or float('nan'):7.2f} s, load {r['load_before']:.2f}; "
                  + (f"error {r['error']}" if r.get("error") else
                     f"height {r['height_m']:.4f} m, contacts/apple {r['contacts_per_apple']:.3f}"
                     + (f", awake {', '.join(f'{a}: {v:.0f}' for a, v in r['awake'].items())}" if "awake" in r else "")),
                  flush=True)
    summary = {}
    for r in runs:
        if r.get("error"):
            continue
        s = summary.setdefault(f"{r['code']} {r['case']}", {"loop_s": [], "process_s": [], "height_m": [],
                                                             "contacts_per_apple": [], "awake_settled": []})
        s["loop_s"].append(r["loop_s"])
        s["process_s"].append(r["process_s"])
        s["height_m"].append(r["height_m"])
        s["contacts_per_apple"].append(r["contacts_per_apple"])
        if "awake" in r:
            s["awake_settled"].append(r["awake"].get("settled"))
    for s in summary.values():
        s["median_loop_s"] = statistics.median(s["loop_s"])
        s["median_process_s"] = statistics.median(s["process_s"])
    res = {"rounds": rounds, "threads": threads, "applesim": exe, "cpus": os.cpu_count(),
           "load_average_at_end": os.getloadavg(), "elapsed_s": time.time() - t0,
           "runs": runs, "summary": summary}
    with open(os.path.join(out, "time_to_answer.json"), "w") as f:
        json.dump(res, f, indent=1)
    print_summary(res)
    return 0


def run_diagnosis(exe, out, threads):
    names = ["pile_epsd2_adaptive_balanced", "pile_epsd2_adaptive_preview"] + sorted(
        f[:-5] for f in os.listdir(app.SC) if f.startswith("diag_") and f.endswith(".json"))
    res = []
    for name in names:
        r = app_run(exe, out, name, name, 1, threads)
        res.append(r)
        if r.get("error"):
            print(f"{name:42s} error {r['error']}")
            continue
        print(f"{name:42s} loop {r['loop_s']:5.2f} s (load {r['load_before']:.1f}), {r['steps']:5d} steps "
              f"({', '.join(f'{k} {v}' for k, v in r['window_steps'].items())}), height {r['height_m']:.4f} m, "
              f"contacts/apple {r['contacts_per_apple']:.3f}, mean awake {', '.join(f'{k} {v:.0f}' for k, v in r['awake'].items())}",
              flush=True)
    with open(os.path.join(out, "diagnose.json"), "w") as f:
        json.dump(res, f, indent=1)
    return 0


def print_summary(res):
    sm = res["summary"]
    print(f"\nmedians of {res['rounds']} alternating rounds (LIGGGHTS serial; applesim --threads {res['threads']}):")
    for k, s in sm.items():
        print(f"  {k:28s} loop {s['median_loop_s']:6.2f} s ({', '.join(f'{x:.2f}' for x in s['loop_s'])}), "
              f"process {s['median_process_s']:6.2f} s; height {', '.join(f'{x:.4f}' for x in s['height_m'])} m, "
              f"contacts/apple {', '.join(f'{x:.3f}' for x in s['contacts_per_apple'])}"
              + (f", awake 3-5 s {', '.join(f'{x:.0f}' for x in s['awake_settled'])}" if s["awake_settled"] else ""))
    for lk in ("LIGGGHTS dt 0.0001", "LIGGGHTS dt 0.0005"):
        for ak in ("applesim adaptive balanced", "applesim adaptive preview", "applesim dt 0.0001", "applesim dt 0.0005"):
            if lk in sm and ak in sm:
                print(f"  {lk} / {ak}: {sm[lk]['median_loop_s'] / sm[ak]['median_loop_s']:.2f} (loops), "
                      f"{sm[lk]['median_process_s'] / sm[ak]['median_process_s']:.2f} (processes)")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
