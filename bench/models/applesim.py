#!/usr/bin/env python3
"""applesim side of the same-model comparison (issue 19, build items 4 and 5).

usage: applesim.py [drop|pile|roll|scatter|time|all]... [--out DIR] [--applesim PATH] [--threads N]
                   [--scenarios DIR]

Runs the scenarios of bench/models/scenarios/ (written by make_scenarios.py) one after the other
and writes DIR/applesim.json (compare.py reads it):

  drop  `applesim run` of drop_*.json: peak force, contact time (contacts.csv: touch to
        separation, i.e. overlap > 0; forces.csv: touch to the force's return to zero),
        restitution at separation.
  roll  `applesim run` of roll_{cdt,epsd2}.json and roll_{cdt,epsd2}_soft.json (a plate of the
        apple's E and nu): stopping time and distance from bodies.csv (the first sample with
        vx <= 0, interpolated), as for LIGGGHTS.
  pile  `applesim bench --json` of pile_epsd2_dt1e-4.json (wall time, settled height, apple-apple
        contacts per apple at 5 s) and `applesim run` of it (the final positions: the same
        height, top-25 mean and contact count as for LIGGGHTS, computed by the same function);
        the cdt pile by bench only.
  scatter  `applesim run` of pile_epsd2_dt1e-4.json from the three other starts of LIGGGHTS's
        ensemble (liggghts.py scatter: every apple moved sideways by up to 1 um, seeds 1-3; read
        from DIR/pile/pile_jitter{1,2,3}.data, written there if missing): with the gen.py start,
        applesim's own ensemble of four equally valid piles, to set beside LIGGGHTS's; the same
        for pile_cdt_dt1e-4.json (its gen.py start run too, for the positions).
  time  `applesim bench --json` of pile_epsd2_adaptive_{balanced,preview}.json (item 5; one
        run each: the timed, alternating rounds are time_to_answer.py's), and `applesim run` of
        them for the final positions (top-25 mean z, contacts counted from the positions).

A scenario applesim refuses (e.g. a field it does not parse yet) is recorded with its error and
shows as pending in the table. --threads (default 1: LIGGGHTS runs on one core) is passed to
both commands. --scenarios DIR reads the scenarios (same names) from DIR instead.
"""
import csv
import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import liggghts as lig  # noqa: E402  (the shared analysis: roll_figures, pile_geometry)

SC = os.path.join(HERE, "scenarios")  # --scenarios DIR replaces it


def call(cmd, log):
    t0 = time.monotonic()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall = time.monotonic() - t0
    with open(log, "w") as f:
        f.write(" ".join(cmd) + "\n--- stdout\n" + p.stdout + "\n--- stderr\n" + p.stderr)
    err = None
    if p.returncode != 0:
        lines = [l for l in p.stderr.splitlines() if l.strip()]
        err = (lines[0] if lines else f"exit code {p.returncode}")[:300]
    return p, wall, err


def run_folder(exe, scenario, folder, threads):
    """`applesim run SCENARIO --out FOLDER`; its command and output go to FOLDER.log, beside the
    folder: applesim replaces a result folder only when it holds nothing but a previous run's
    files."""
    stale = os.path.join(folder, "command.log")  # where earlier versions of this script wrote it
    if os.path.exists(stale):
        os.remove(stale)
    cmd = [exe, "run", scenario, "--out", folder]
    if threads:
        cmd += ["--threads", str(threads)]
    _, wall, err = call(cmd, folder + ".log")
    return folder, wall, err


def run(exe, name, out, threads):
    return run_folder(exe, os.path.join(SC, name + ".json"), os.path.join(out, "applesim_" + name), threads)


def bench(exe, name, out, threads):
    os.makedirs(out, exist_ok=True)
    cmd = [exe, "bench", os.path.join(SC, name + ".json"), "--json"]
    if threads:
        cmd += ["--threads", str(threads)]
    p, wall, err = call(cmd, os.path.join(out, f"bench_{name}.log"))
    if err:
        return {"error": err, "process_wall_s": wall}
    r = json.loads(p.stdout.strip().splitlines()[-1])
    r["process_wall_s"] = wall
    return r


def rows_of(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def drop_figures(folder):
    c = [r for r in rows_of(os.path.join(folder, "contacts.csv")) if "plate" in (r["a"], r["b"])][0]
    t0 = float(c["t_start_s"])
    fig = {
        "touch_time_s": t0,
        "approach_speed_m_s": float(c["approach_speed_m_s"]),
        "peak_force_n": float(c["peak_force_n"]),
        "t_peak_after_touch_s": float(c["t_peak_s"]) - t0,
        "contact_time_overlap_s": float(c["duration_s"]) if c["duration_s"] else None,
        "restitution_separation": float(c["restitution"]) if c["restitution"] else None,
        "max_overlap_m": float(c["max_overlap_m"]),
    }
    fpath = os.path.join(folder, "forces.csv")
    if os.path.exists(fpath):
        h = [(float(r["time_s"]), float(r["force_n"])) for r in rows_of(fpath) if r["contact"] == "0"]
        pos = [i for i, (_, f) in enumerate(h) if f > 0]
        if pos:
            # The force's first return to zero after the peak: extrapolated linearly from the last
            # two samples with F > 0, as liggghts.py does (the force is clamped at 0, so the line
            # to the first zero sample would put the zero at that sample: up to one sample late;
            # forces.csv keeps every 4th step of this 9000-step contact).
            k = max(range(len(h)), key=lambda i: h[i][1])
            while k + 1 < len(h) and h[k + 1][1] > 0:
                k += 1
            (ta, fa), (tb, fb) = h[k - 1], h[k]
            t_zero = tb + fb / (fa - fb) * (tb - ta) if fa > fb else tb
            if k + 1 < len(h):
                t_zero = min(t_zero, h[k + 1][0])
            fig["contact_time_force_s"] = t_zero - t0
            fig["force_samples"] = len(h)
    return fig


def body_rows(folder, apple="a1"):
    rows = []
    for r in rows_of(os.path.join(folder, "bodies.csv")):
        if r["apple"] == apple:
            rows.append([float(r["time_s"]), float(r["x_m"]), float(r["vx_m_s"]), float(r["wy_rad_s"]),
                         float(r["z_m"]), float(r["fz_n"])])
    return rows


def final_positions(folder, radii):
    last = {}
    tmax = None
    for r in rows_of(os.path.join(folder, "bodies.csv")):
        t = float(r["time_s"])
        if tmax is None or t > tmax + 1e-12:
            tmax, last = t, {}
        if abs(t - tmax) <= 1e-12:
            last[r["apple"]] = (float(r["x_m"]), float(r["y_m"]), float(r["z_m"]))
    apples = [(x, y, z, radii[name]) for name, (x, y, z) in last.items()]
    return tmax, apples


def pile_radii():
    pile = json.load(open(os.path.join(HERE, "..", "..", "assets", "piles", "liggghts_1000.json")))
    # A file generator `p` names apple `p17` of the file `p-p17`.
    return {"p-" + a["name"]: a["diameter_m"] / 2 for a in pile}


def jittered_scenario(out, seed, model="epsd2"):
    """pile_{model}_dt1e-4.json with the start of LIGGGHTS's jittered data file `seed` (the same
    apples, names and diameters, each moved sideways by up to 1 um): (scenario path, pile path)."""
    data = lig.jittered_data(out, seed)
    lines = open(data).read().splitlines()
    k = lines.index("Atoms")
    ref = json.load(open(os.path.join(HERE, "..", "..", "assets", "piles", "liggghts_1000.json")))
    pile = []
    for l in lines[k + 1:]:
        p = l.split()
        if len(p) != 7:
            continue
        i = int(p[0])
        a = ref[i - 1]
        assert a["name"] == f"p{i}" and abs(a["diameter_m"] - float(p[2])) < 1e-9, (a, l)
        pile.append({"name": a["name"], "diameter_m": a["diameter_m"],
                     "position_m": [float(p[4]), float(p[5]), float(p[6])]})
    folder = os.path.join(out, "pile")
    pile_path = os.path.join(folder, f"applesim_pile_jitter{seed}.json")
    with open(pile_path, "w") as f:
        json.dump(pile, f)
    sc = json.load(open(os.path.join(SC, f"pile_{model}_dt1e-4.json")))
    sc["generators"][0]["file"] = pile_path
    sc["description"] += f" Start: LIGGGHTS's jittered start {seed} (bench/models/applesim.py scatter)."
    sc_path = os.path.join(folder, f"pile_{model}_dt1e-4_jitter{seed}.json")
    with open(sc_path, "w") as f:
        json.dump(sc, f, indent=1)
    return sc_path


def main(argv):
    what, out, exe, threads = [], "/work/lig-runs/models", None, 1
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("drop", "pile", "roll", "scatter", "time", "all"):
            what.append(a)
        elif a == "--out":
            out = argv[i + 1]; i += 1
        elif a == "--applesim":
            exe = argv[i + 1]; i += 1
        elif a == "--threads":
            threads = int(argv[i + 1]); i += 1
        elif a == "--scenarios":
            global SC
            SC = os.path.abspath(argv[i + 1]); i += 1
        elif a in ("-h", "--help"):
            print(__doc__); return 0
        else:
            print(f"unknown argument {a} (see --help)", file=sys.stderr); return 2
        i += 1
    if not what or "all" in what:
        what = ["drop", "roll", "pile", "scatter", "time"]
    exe = exe or os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(HERE, "..", "..", "target")),
                              "release", "applesim")
    out = os.path.abspath(out)
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, "applesim.json")
    res = json.load(open(path)) if os.path.exists(path) else {}
    res["applesim"] = exe
    res["threads"] = threads
    if "drop" in what:
        res["drop"] = []
        for name, _ in (x for x in lig_drop_names()):
            folder, wall, err = run(exe, name, out, threads)
            r = {"name": name, "wall_s": wall}
            if err:
                r["error"] = err
                print(f"{name}: applesim refused or failed: {err}")
            else:
                r.update(drop_figures(folder))
                print(f"{name:22s}: peak {r['peak_force_n']:.3f} N, contact {1e3*(r.get('contact_time_force_s') or float('nan')):.4f} ms (F > 0), "
                      f"{1e3*(r['contact_time_overlap_s'] or float('nan')):.4f} ms (overlap > 0), e {r['restitution_separation']}; wall {wall:.1f} s")
            res["drop"].append(r)
    if "roll" in what:
        res["roll"] = []
        for model, plate in (("cdt", "steel"), ("epsd2", "steel"), ("cdt", "soft"), ("epsd2", "soft")):
            name = f"roll_{model}{'_soft' if plate == 'soft' else ''}"
            folder, wall, err = run(exe, name, out, threads)
            r = {"name": name, "roll": model, "plate": plate, "wall_s": wall}
            if err:
                r["error"] = err
                print(f"{name}: applesim refused or failed: {err}")
            else:
                r.update(lig.roll_figures(body_rows(folder), 0.5, 0.05))
                print(f"{name}: stops after {r['stop_distance_m']} m at {r['stop_time_s']} s; wall {wall:.1f} s")
            res["roll"].append(r)
    if "pile" in what:
        res["pile"] = {}
        for model in ("epsd2", "cdt"):
            name = f"pile_{model}_dt1e-4"
            b = bench(exe, name, out, threads)
            r = {"name": name, "bench": b}
            if model == "epsd2" and "error" not in b:
                folder, wall, err = run(exe, name, out, threads)
                r["run_wall_s"] = wall
                if err:
                    r["run_error"] = err
                else:
                    t, apples = final_positions(folder, pile_radii())
                    r["final_time_s"] = t
                    r.update(lig.pile_geometry(apples))
            res["pile"][model] = r
            print(f"{name}: {json.dumps({k: v for k, v in r.items() if k != 'bench'})}; bench "
                  f"{b.get('error') or (b['wall_s'], b['pile_height_m'])}")
    if "scatter" in what:
        res["pile_scatter"] = []
        radii = pile_radii()
        for model, seed in [("epsd2", s) for s in (1, 2, 3)] + [("cdt", s) for s in (0, 1, 2, 3)]:
            if seed == 0:  # the cdt pile from gen.py's start: its positions (the pile target only benches it)
                sc_path = os.path.join(SC, "pile_cdt_dt1e-4.json")
            else:
                sc_path = jittered_scenario(out, seed, model)
            name = f"pile_{model}_dt1e-4" + (f"_jitter{seed}" if seed else "")
            folder = os.path.join(out, "applesim_" + name)
            _, wall, err = run_folder(exe, sc_path, folder, threads)
            r = {"name": name, "roll": model, "jitter_seed": seed, "run_wall_s": wall}
            if err:
                r["error"] = err
            else:
                t, apples = final_positions(folder, radii)
                r["final_time_s"] = t
                r.update(lig.pile_geometry(apples))
            res["pile_scatter"].append(r)
            print(f"{r['name']}: {json.dumps(r)}")
    if "time" in what:
        res["time"] = {}
        for acc in ("balanced", "preview"):
            name = f"pile_epsd2_adaptive_{acc}"
            b = bench(exe, name, out, threads)
            r = {"name": name, "bench": b}
            if "error" not in b:
                # The final positions too: the top-25 mean and the contacts, as for LIGGGHTS.
                folder, wall, err = run(exe, name, out, threads)
                r["run_wall_s"] = wall
                if err:
                    r["run_error"] = err
                else:
                    r.update(lig.pile_geometry(final_positions(folder, pile_radii())[1]))
            res["time"][acc] = r
            print(f"{name}: {b.get('error') or (b['wall_s'], b['pile_height_m'], b['steps'])}; "
                  f"{json.dumps({k: v for k, v in r.items() if k not in ('bench', 'name')})}")
    with open(path, "w") as f:
        json.dump(res, f, indent=1)
    print(f"figures: {path}")
    return 0


def lig_drop_names():
    for c in lig.drop_cases():
        yield lig.case_name(c), c


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
