#!/usr/bin/env python3
"""Prints the same-model comparison (issue 19) from DIR/liggghts.json and DIR/applesim.json.

usage: compare.py [DIR]     (default /work/lig-runs/models)

Each row: the LIGGGHTS figure, applesim's, applesim vs LIGGGHTS (relative difference) and the
acceptance bound of issue 19 where it sets one. A cell applesim could not produce (a scenario it
refuses, e.g. a field it does not parse yet) reads "pending" with its error below the table.
"""
import json
import os
import sys

out = sys.argv[1] if len(sys.argv) > 1 else "/work/lig-runs/models"
L = json.load(open(os.path.join(out, "liggghts.json")))
A = json.load(open(os.path.join(out, "applesim.json"))) if os.path.exists(os.path.join(out, "applesim.json")) else {}
errors = {}


def fmt(x, scale=1.0, digits=4):
    return "pending" if x is None else f"{x * scale:.{digits}f}"


def rel(a, l):
    if a is None or l is None or l == 0:
        return "-"
    return f"{100 * (a / l - 1):+.2f} %"


def verdict(a, l, bound):
    if bound is None or a is None or l is None:
        return ""
    return "ok" if abs(a / l - 1) <= bound else "NO"


rows = []


def row(what, l, a, unit="", scale=1.0, digits=4, bound=None):
    rows.append((what, fmt(l, scale, digits), fmt(a, scale, digits), unit, rel(a, l),
                 "" if bound is None else f"{100 * bound:g} %", verdict(a, l, bound)))


def get(d, k):
    return None if d is None or "error" in d else d.get(k)


# Drops: LIGGGHTS at dt 1e-6 (its own convergence is in the dt5e-07 / dt2e-06 cases).
adrop = {r["name"]: r for r in A.get("drop", [])}
for r in L.get("drop", []):
    if r.get("dt_s") != 1e-6 or "error" in r:
        continue
    a = adrop.get(r["name"])
    if a and "error" in a:
        errors[r["name"]] = a["error"]
    lab = r["name"].replace("drop_", "drop ")
    row(f"{lab}: peak force", r["peak_force_n"], get(a, "peak_force_n"), "N", 1, 3, 0.01)
    row(f"{lab}: contact time, F > 0", r["contact_time_force_s"], get(a, "contact_time_force_s"), "ms", 1e3, 4, 0.01)
    row(f"{lab}: contact time, overlap > 0", r["contact_time_overlap_s"], get(a, "contact_time_overlap_s"), "ms", 1e3, 4, None)
    row(f"{lab}: restitution at separation", r["restitution_separation"], get(a, "restitution_separation"), "", 1, 4, None)

# The pile at dt 1e-4.
lp = next((r for r in L.get("pile", []) if r["dt_s"] == 1e-4 and r["roll"] == "epsd2" and "error" not in r), None)
ap = (A.get("pile") or {}).get("epsd2")
if ap:
    if "error" in ap.get("bench", {}):
        errors["pile_epsd2_dt1e-4"] = ap["bench"]["error"]
    elif "run_error" in ap:
        errors["pile_epsd2_dt1e-4 (run)"] = ap["run_error"]
if lp:
    ab = ap.get("bench") if ap else None
    row("pile epsd2 dt 1e-4: height (max centre z)", lp["z_max_m"], get(ab, "pile_height_m"), "m", 1, 4, 0.01)
    row("pile epsd2 dt 1e-4: mean z of the 25 highest", lp["z_top25_mean_m"], get(ap, "z_top25_mean_m"), "m", 1, 4, None)
    aw = None
    if ab and "error" not in ab and ab.get("windows"):
        aw = ab["windows"][-1]["apple_apple_contacts_per_apple"]
    row("pile epsd2 dt 1e-4: apple-apple contacts/apple", lp["apple_apple_contacts_per_apple"], aw, "", 1, 4, 0.03)
    row("pile epsd2 dt 1e-4: contacts/apple from positions", lp["apple_apple_contacts_per_apple"],
        get(ap, "apple_apple_contacts_per_apple"), "", 1, 4, 0.03)
# The chaos scatter: four equally valid piles at dt 1e-4 (gen.py's start and three starts moved by
# up to 1 um); applesim's pile is another such pile, so its figures are also compared with their
# mean (and whether they fall inside their range).
ens = next((o for o in (L.get("pile_scatter_summary") or {}).get("ensembles", []) if o["dt_s"] == 1e-4), None)
if ens and lp:
    ab = ap.get("bench") if ap else None
    aw = ab["windows"][-1]["apple_apple_contacts_per_apple"] if ab and "error" not in ab and ab.get("windows") else None
    for k, lab, a, bound in (("z_max_m", "height (max centre z)", get(ab, "pile_height_m"), 0.01),
                             ("z_top25_mean_m", "mean z of the 25 highest", get(ap, "z_top25_mean_m"), None),
                             ("apple_apple_contacts_per_apple", "apple-apple contacts/apple", aw, 0.03)):
        e = ens[k]
        row(f"pile epsd2 dt 1e-4, {ens['starts']}-start mean: {lab}", e["mean"], a, "m" if "z" in k else "", 1, 4, bound)
        inside = "-" if a is None else ("inside" if e["min"] <= a <= e["max"] else "outside")
        rows.append((f"  LIGGGHTS range of the {ens['starts']} starts", f"[{e['min']:.4f}, {e['max']:.4f}]", inside,
                     "", f"spread {100 * e['spread_rel']:.2f} %", "", ""))
# applesim's own ensemble: the gen.py start and LIGGGHTS's three jittered starts (applesim.py
# scatter); its mean against LIGGGHTS's mean, and both ranges.
asc = [r for r in A.get("pile_scatter", []) if "error" not in r and r.get("roll", "epsd2") == "epsd2"]
for r in A.get("pile_scatter", []):
    if "error" in r:
        errors[r["name"]] = r["error"]
if ens and ap and "error" not in ap and "z_max_m" in ap and asc:
    arun = [ap] + asc
    for k, lab, bound in (("z_max_m", "height (max centre z)", 0.01),
                          ("z_top25_mean_m", "mean z of the 25 highest", None),
                          ("apple_apple_contacts_per_apple", "apple-apple contacts/apple", 0.03)):
        v = [r[k] for r in arun]
        m = sum(v) / len(v)
        e = ens[k]
        row(f"pile epsd2 dt 1e-4, {len(arun)}-start means (both codes): {lab}", e["mean"], m,
            "m" if "z" in k else "", 1, 4, bound)
        rows.append((f"  ranges of the {len(arun)} starts, each code", f"[{e['min']:.4f}, {e['max']:.4f}]",
                     f"[{min(v):.4f}, {max(v):.4f}]", "", f"spread {100 * (max(v) - min(v)) / m:.2f} %", "", ""))
lc = next((r for r in L.get("pile_cdt", []) if "error" not in r), None)
ac = (A.get("pile") or {}).get("cdt")
if lc:
    ab = ac.get("bench") if ac else None
    if ab and "error" in ab:
        errors["pile_cdt_dt1e-4"] = ab["error"]
    row("pile cdt dt 1e-4: height (max centre z)", lc["z_max_m"], get(ab, "pile_height_m"), "m", 1, 4, 0.01)
    aw = ab["windows"][-1]["apple_apple_contacts_per_apple"] if ab and "error" not in ab and ab.get("windows") else None
    row("pile cdt dt 1e-4: apple-apple contacts/apple", lc["apple_apple_contacts_per_apple"], aw, "", 1, 4, 0.03)
# The cdt pile's two ensembles (gen.py's start and the same three jittered starts in each code).
lce = (L.get("pile_scatter_summary") or {}).get("cdt_1e-4")
acs = [r for r in A.get("pile_scatter", []) if "error" not in r and r.get("roll") == "cdt"]
if lce and acs:
    for k, lab, bound in (("z_max_m", "height (max centre z)", 0.01),
                          ("z_top25_mean_m", "mean z of the 25 highest", None),
                          ("apple_apple_contacts_per_apple", "apple-apple contacts/apple", 0.03)):
        v = [r[k] for r in acs]
        m = sum(v) / len(v)
        e = lce[k]
        row(f"pile cdt dt 1e-4, {lce['starts']}/{len(acs)}-start means: {lab}", e["mean"], m,
            "m" if "z" in k else "", 1, 4, bound)
        rows.append((f"  ranges of the starts, each code", f"[{e['min']:.4f}, {e['max']:.4f}]",
                     f"[{min(v):.4f}, {max(v):.4f}]", "", f"spread {100 * (max(v) - min(v)) / m:.2f} %", "", ""))

# Rolling: LIGGGHTS at dt 1e-5 (the scenarios' step).
aroll = {(r["roll"], r.get("plate", "steel")): r for r in A.get("roll", [])}
for r in L.get("roll", []):
    if r.get("dt_s") != 1e-5 or "error" in r:
        continue
    plate = r.get("plate", "steel")
    a = aroll.get((r["roll"], plate))
    lab = r["roll"] + (" on the soft plate" if plate == "soft" else "")
    if a and "error" in a:
        errors[a["name"]] = a["error"]
    row(f"roll {lab}: stopping distance", r["stop_distance_m"], get(a, "stop_distance_m"), "m", 1, 5,
        0.02 if plate == "steel" else None)
    row(f"roll {lab}: stopping time", r["stop_time_s"], get(a, "stop_time_s"), "s", 1, 4, None)
    if r["roll"] == "cdt" and plate == "steel":
        rows.append((f"roll cdt: closed form 7 v0^2/(10 mu_r g)", fmt(r["closed_form_distance_m"], 1, 5), "", "m",
                     rel(r["stop_distance_m"], r["closed_form_distance_m"]) + " (LIGGGHTS)", "", ""))

w = [max(len(r[i]) for r in rows + [("quantity", "LIGGGHTS", "applesim", "unit", "applesim vs L", "bound", "")])
     for i in range(7)]
head = ("quantity", "LIGGGHTS", "applesim", "unit", "applesim vs L", "bound", "")
print("Same model in LIGGGHTS 3.8 and applesim (issue 19): viscoelastic Hertz (limitForce on), tangential history, epsd2/cdt")
for r in [head] + rows:
    print("  ".join(r[i].ljust(w[i]) if i == 0 else r[i].rjust(w[i]) for i in range(7)))

# Time to an answer (item 5).
print("\nTime to an answer, the same-model pile 0-5 s (LIGGGHTS serial on one core; applesim "
      f"--threads {A.get('threads', 1)}); single runs made at different times, not alternated: item 5's "
      "figures are time_to_answer.py's alternating rounds (below when run into this folder):")
lw = lp and lp["loop_s"]
timing = {r["dt_s"]: r for r in (L.get("pile_timing") or {}).get("runs", []) if r.get("median_s")}
if 1e-4 in timing:
    lw = timing[1e-4]["median_s"]
    print(f"  LIGGGHTS dt 1e-4, timed {len(timing[1e-4]['loop_s'])} times: time loop "
          f"{', '.join(f'{x:.2f}' for x in timing[1e-4]['loop_s'])} s (median {lw:.2f} s)")
chk = L.get("pile_dt_check") or {}
best = chk.get("largest_dt_all_smaller_within")
lb = next((r for r in L.get("pile", []) if r["dt_s"] == best and "error" not in r), None)
print(f"  LIGGGHTS dt 1e-4, the compared run: time loop {fmt(lp and lp['loop_s'], 1, 2)} s (process "
      f"{fmt(lp and lp['wall_s'], 1, 2)} s)")
if lb and best in timing:
    lb = dict(lb, loop_s=timing[best]["median_s"])
if lb:
    print(f"  LIGGGHTS largest dt whose settled height and contacts per apple stay within 1 % of dt 1e-4, "
          f"one run per dt (it and every smaller dt tried): {best:g} s, time loop {lb['loop_s']:.2f} s "
          f"(largest single dt within 1 %: {chk.get('largest_dt_within')})")
ebest = (L.get("pile_scatter_summary") or {}).get("largest_dt_ensemble_within_1pct")
le = next((r for r in L.get("pile", []) if r["dt_s"] == ebest and "error" not in r), None)
if le and ebest in timing:
    le = dict(le, loop_s=timing[ebest]["median_s"])
    print(f"  LIGGGHTS dt {ebest:g}, timed {len(timing[ebest]['loop_s'])} times: time loop "
          f"{', '.join(f'{x:.2f}' for x in timing[ebest]['loop_s'])} s (median {le['loop_s']:.2f} s)")
if le:
    print(f"  LIGGGHTS largest dt whose 4-start ensemble means stay within 1 % of those at dt 1e-4 (and every "
          f"smaller dt's): {ebest:g} s, time loop {le['loop_s']:.2f} s (gen.py's start)")
for acc in ("balanced", "preview"):
    t = (A.get("time") or {}).get(acc)
    b = t and t["bench"]
    if not b or "error" in b:
        if b:
            errors[f"pile_epsd2_adaptive_{acc}"] = b["error"]
        print(f"  applesim adaptive {acc}: pending")
        continue
    aw = b["windows"][-1]["apple_apple_contacts_per_apple"] if b.get("windows") else None
    awake = {w["label"]: w["mean_awake_apples"] for w in b.get("windows", [])}
    top = t.get("z_top25_mean_m")
    print(f"  applesim adaptive {acc}: time loop {b['wall_s']:.2f} s ({b['steps']} steps), height "
          f"{b['pile_height_m']:.4f} m ({rel(b['pile_height_m'], lp and lp['z_max_m'])} vs LIGGGHTS dt 1e-4), "
          + (f"top-25 mean {top:.4f} m ({rel(top, ens and ens['z_top25_mean_m']['mean'])} vs LIGGGHTS's 4-start mean), " if top else "")
          + f"mean awake apples {', '.join(f'{k} {v:.0f}' for k, v in awake.items())}, "
          f"contacts/apple {fmt(aw)} ({rel(aw, lp and lp['apple_apple_contacts_per_apple'])}); "
          f"LIGGGHTS dt 1e-4 / applesim {lw / b['wall_s']:.2f}"
          + (f", LIGGGHTS dt {best:g} / applesim {lb['loop_s'] / b['wall_s']:.2f}" if lb else "")
          + (f", LIGGGHTS dt {ebest:g} / applesim {le['loop_s'] / b['wall_s']:.2f}" if le and ebest != best else ""))
# The alternating timed rounds of time_to_answer.py, when they were run into this folder.
tta = os.path.join(out, "time_to_answer.json")
if os.path.exists(tta):
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import time_to_answer  # noqa: E402
    print("\nTime to an answer, alternating rounds (bench/models/time_to_answer.py, " + tta + "):")
    time_to_answer.print_summary(json.load(open(tta)))
if errors:
    print("\npending (applesim refused or failed):")
    for k, v in errors.items():
        print(f"  {k}: {v}")
