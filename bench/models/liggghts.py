#!/usr/bin/env python3
"""LIGGGHTS 3.8 side of the same-model comparison (issue 19, build items 4 and 5).

usage: liggghts.py [drop|pile|roll|scatter|timing|all]... [--out DIR] [--pile-dts 1e-4,2e-4,...] [--quick] [--reuse]

Runs the decks of this folder (drop.in, pile.in, roll.in) with /usr/bin/liggghts, serially, one
after the other, each in its own folder under DIR (default /work/lig-runs/models), reads the
records and writes DIR/liggghts.json (the figures; compare.py reads it) and prints them.

  drop  one apple (D 80 mm, 800 kg/m^3, E 2.6 MPa, nu 0.18) on a steel plate at 1 and 0.5 m/s,
        restitution 0.3 and 0.65, without and with gravity, dt 1e-6 (plus 5e-7 and 2e-6 for one
        case: LIGGGHTS's own convergence); peak force, contact time (force > 0 and overlap > 0),
        rebound speed.
  pile  the 1000-apple pile of shared/bench/liggghts (gen.py 5 5 40 0.1 1), epsd2, restitution
        0.3, friction 0.5, rolling friction 0.03, 5 s, at each dt of --pile-dts (default
        1e-4,2e-4,3e-4,5e-4,6e-4,7e-4,1e-3); settled height (largest centre z, mean z of the 25
        highest centres), apple-apple contacts per apple (contact/atom mean / 2, and counted from
        the final positions), wall time; then the largest dt within 1 % of dt = 1e-4 (one run per
        dt). Plus the cdt variant at 1e-4.
  roll  one apple launched rolling (v0 0.5 m/s, omega = v0/R) on a steel plate with gravity,
        rolling friction 0.05, cdt and epsd2, dt 1e-5 and 1e-6: stopping time and distance
        against the cdt closed form; and at dt 1e-5 on a soft plate (the apple's E and nu: the
        lever arm R - delta/2 then the same in both codes).
  scatter  the pile again from three starts with every apple moved sideways by up to 1 um
        (seeds 1-3) at dt 1e-4, 2e-4, 3e-4, 5e-4, 6e-4, 7e-4: with gen.py's start, an ensemble of
        four equally valid settled piles per dt (their scatter is chaos, not the step); the
        largest dt whose ensemble means stay within 1 % of dt 1e-4's. Also dt 1e-4 with
        neighbour skins 6, 10, 12 mm (only the summation order of the forces changes) and dt 5e-5;
        and the cdt pile from the same three starts at dt 1e-4.
  timing  the pile (gen.py's start) at dt 1e-4 and at the largest dt of the scatter, three times
        each, alternating: the wall times of item 5 (minimum and median).
--quick: the pile only 0.5 s at dt 1e-4 and 2e-4 (to check the scripts).
--reuse: read a case's folder instead of running it again when it holds a finished run of the
         same command (the same deck name and variables, from any checkout; its wall time is the
         one measured then).
"""
import json
import math
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
GEN = os.environ.get("LIGGGHTS_GEN", os.path.join(HERE, "..", "..", "..", "shared", "bench", "liggghts", "gen.py"))
LIGGGHTS = os.environ.get("LIGGGHTS", "liggghts")

R = 0.04
RHO = 800.0
MASS = RHO * 4.0 / 3.0 * math.pi * R ** 3
G = 9.81
E_APPLE, NU_APPLE, E_STEEL, NU_STEEL = 2.6e6, 0.18, 2.0e11, 0.30
Y_STAR_WALL = 1.0 / ((1 - NU_APPLE ** 2) / E_APPLE + (1 - NU_STEEL ** 2) / E_STEEL)


def static_overlap_wall(y_star=Y_STAR_WALL):
    """Overlap of an apple resting on the plate: (3 m g / (4 E* sqrt(R)))^(2/3)."""
    return (3.0 * MASS * G / (4.0 * y_star * math.sqrt(R))) ** (2.0 / 3.0)


# The soft plate of the rolling variant: the apple's own modulus and Poisson ratio, so that
# applesim's contact point (R - u c1/(c1 + c2), compliance share) sits at R - u/2 as LIGGGHTS's
# does on every wall (R - delta/2): the lever arm difference of the steel plate removed.
Y_STAR_SOFT = 1.0 / (2 * (1 - NU_APPLE ** 2) / E_APPLE)


REUSE = False


def same_command(a, b):
    """Whether two recorded command lines are the same run: the same deck (by name: the folder
    of this checkout may differ) with the same variables."""
    norm = lambda l: re.sub(r"-in \S*/([^/\s]+\.in)", r"-in \1", l.strip())
    return norm(a) == norm(b)


def run_deck(deck, folder, variables):
    """Runs one deck; returns (wall seconds of the process, summed 'Loop time' of its runs,
    the error if it failed). With --reuse a folder that already holds a finished run of the
    same command is read instead of run again."""
    os.makedirs(folder, exist_ok=True)
    cmd = [LIGGGHTS, "-in", os.path.join(HERE, deck), "-log", "log.lammps"]
    for k, v in variables.items():
        cmd += ["-var", k, str(v)]
    line = "OMP_NUM_THREADS=1 " + " ".join(cmd) + "\n"
    cmd_file, wall_file = os.path.join(folder, "command.txt"), os.path.join(folder, "wall_s.txt")
    if (REUSE and os.path.exists(wall_file) and os.path.exists(cmd_file)
            and same_command(open(cmd_file).read(), line)):
        wall = float(open(wall_file).read())
        print(f"(reusing {folder})")
    else:
        with open(cmd_file, "w") as f:
            f.write(line)
        if os.path.exists(wall_file):
            os.remove(wall_file)
        env = dict(os.environ, OMP_NUM_THREADS="1")
        t0 = time.monotonic()
        with open(os.path.join(folder, "stdout.txt"), "w") as out:
            rc = subprocess.call(cmd, cwd=folder, stdout=out, stderr=subprocess.STDOUT, env=env)
        wall = time.monotonic() - t0
        with open(wall_file, "w") as f:
            f.write(f"{wall}\n")
        with open(os.path.join(folder, "rc.txt"), "w") as f:
            f.write(f"{rc}\n")
    rc = int(open(os.path.join(folder, "rc.txt")).read()) if os.path.exists(os.path.join(folder, "rc.txt")) else 0
    log = open(os.path.join(folder, "log.lammps")).read() if os.path.exists(os.path.join(folder, "log.lammps")) else ""
    loops = [float(m.group(1)) for m in re.finditer(r"Loop time of ([\d.eE+-]+) on", log)]
    err = None
    if rc != 0 or "ERROR" in log:
        m = re.search(r"ERROR[^\n]*", log) or re.search(r"ERROR[^\n]*", open(os.path.join(folder, "stdout.txt")).read())
        err = m.group(0) if m else f"exit code {rc}"
    return wall, sum(loops), err


def read_rec(path):
    rows = []
    with open(path) as f:
        for line in f:
            if line[:1].isdigit() or line[:1] == "-":
                rows.append([float(x) for x in line.split()])
    return rows


# ---------------------------------------------------------------------------------------- drop

def drop_figures(rows, dt, g):
    """Peak force and contact times of the first impact from the per-step record
    (t, z, vz, F_wall, omega_y)."""
    # Touch: z crosses R going down (interpolated); the approach speed there.
    k0 = next(i for i in range(1, len(rows)) if rows[i][1] < R)
    (ta, za, va), (tb, zb, vb) = rows[k0 - 1][:3], rows[k0][:3]
    s = (za - R) / (za - zb)
    t_touch = ta + s * (tb - ta)
    v_touch = -(va + s * (vb - va))
    # The force pulse: consecutive steps with F > 0 from the first one.
    f0 = next(i for i in range(len(rows)) if rows[i][3] > 0)
    f1 = f0
    while f1 + 1 < len(rows) and rows[f1 + 1][3] > 0:
        f1 += 1
    peak = max(rows[i][3] for i in range(f0, f1 + 1))
    t_peak = next(rows[i][0] for i in range(f0, f1 + 1) if rows[i][3] == peak)
    # Force contact time: the force acts from the step it first appears (the force at the end of
    # a step is the one of the positions reached in it) over (f1 - f0 + 1) steps; the touch is
    # inside the step before f0, so the force-time is counted from the interpolated touch to
    # the interpolated zero crossing of F after f1 (linear in the last two samples).
    fa, fb = rows[f1 - 1][3], rows[f1][3]
    t_zero = rows[f1][0] + (fb / (fa - fb)) * dt if fa > fb else rows[f1][0]
    t_force = t_zero - t_touch
    v_force_end = rows[min(f1 + 1, len(rows) - 1)][2]
    # Overlap contact time: z back above R (interpolated), searched from the deepest point.
    kmin = min(range(len(rows)), key=lambda i: rows[i][1])
    k1 = next((i for i in range(kmin, len(rows)) if rows[i][1] >= R), None)
    if k1 is None:
        t_overlap, v_sep = None, None
    else:
        (ta, za, va), (tb, zb, vb) = rows[k1 - 1][:3], rows[k1][:3]
        s = (R - za) / (zb - za)
        t_sep = ta + s * (tb - ta)
        t_overlap = t_sep - t_touch
        v_sep = va + s * (vb - va)
    return {
        "touch_time_s": t_touch,
        "approach_speed_m_s": v_touch,
        "peak_force_n": peak,
        "t_peak_after_touch_s": t_peak - t_touch,
        "contact_time_force_s": t_force,
        "contact_time_overlap_s": t_overlap,
        "speed_at_force_end_m_s": v_force_end,
        "restitution_force_end": v_force_end / v_touch,
        "separation_speed_m_s": v_sep,
        "restitution_separation": (v_sep / v_touch) if v_sep is not None else None,
        "max_overlap_m": R - min(r[1] for r in rows),
    }


def drop_cases():
    for g in (0.0, G):
        for e in (0.3, 0.65):
            for v0 in (1.0, 0.5):
                yield {"v0": v0, "e": e, "g": g}


def case_name(c):
    return f"drop_v{c['v0']:g}_e{c['e']:g}_{'g' if c['g'] else 'nog'}"


def run_drop(out):
    res = []
    todo = [(c, 1e-6) for c in drop_cases()]
    todo += [({"v0": 1.0, "e": 0.3, "g": 0.0}, dt) for dt in (5e-7, 2e-6)]
    for c, dt in todo:
        name = case_name(c) + ("" if dt == 1e-6 else f"_dt{dt:g}")
        folder = os.path.join(out, name)
        tend = 0.02
        wall, loop, err = run_deck("drop.in", folder, {
            "v0": c["v0"], "e": c["e"], "g": c["g"], "dt": dt, "tend": tend,
            "roll": "epsd2", "out": "rec.txt"})
        if err:
            res.append(dict(c, name=name, dt_s=dt, error=err))
            print(f"{name}: LIGGGHTS failed: {err}")
            continue
        fig = drop_figures(read_rec(os.path.join(folder, "rec.txt")), dt, c["g"])
        res.append(dict(c, name=name, dt_s=dt, wall_s=wall, loop_s=loop, **fig))
        print(f"{name:28s} dt {dt:.0e}: v_touch {fig['approach_speed_m_s']:.4f} m/s, peak {fig['peak_force_n']:.3f} N "
              f"at {fig['t_peak_after_touch_s']*1e3:.3f} ms, contact {fig['contact_time_force_s']*1e3:.4f} ms (F > 0), "
              f"{(fig['contact_time_overlap_s'] or float('nan'))*1e3:.4f} ms (overlap > 0), e {fig['restitution_force_end']:.4f} "
              f"(at F = 0) / {(fig['restitution_separation'] or float('nan')):.4f} (at separation); wall {wall:.2f} s")
    return res


# ---------------------------------------------------------------------------------------- pile

def read_dump(path):
    atoms = []
    with open(path) as f:
        lines = f.read().splitlines()
    k = next(i for i, l in enumerate(lines) if l.startswith("ITEM: ATOMS"))
    cols = lines[k].split()[2:]
    for l in lines[k + 1:]:
        if l.strip():
            atoms.append(dict(zip(cols, map(float, l.split()))))
    return atoms


def pile_geometry(apples, top=25):
    """Figures of a settled pile from (x, y, z, r) tuples: largest centre z, mean z of the `top`
    highest centres, unique apple-apple contacts (centres closer than r_i + r_j) per apple."""
    zs = sorted((a[2] for a in apples), reverse=True)
    n = len(apples)
    cells = {}
    h = 0.09
    for i, (x, y, z, r) in enumerate(apples):
        cells.setdefault((int(math.floor(x / h)), int(math.floor(y / h)), int(math.floor(z / h))), []).append(i)
    contacts = 0
    for i, (x, y, z, r) in enumerate(apples):
        cx, cy, cz = int(math.floor(x / h)), int(math.floor(y / h)), int(math.floor(z / h))
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for dz in (-1, 0, 1):
                    for j in cells.get((cx + dx, cy + dy, cz + dz), ()):
                        if j <= i:
                            continue
                        xj, yj, zj, rj = apples[j]
                        if (x - xj) ** 2 + (y - yj) ** 2 + (z - zj) ** 2 < (r + rj) ** 2:
                            contacts += 1
    return {
        "z_max_m": zs[0],
        f"z_top{top}_mean_m": sum(zs[:top]) / top,
        "apple_apple_contacts_per_apple": contacts / n,
    }


def thermo_rows(log):
    rows = []
    head = None
    for line in log.splitlines():
        p = line.split()
        if p[:2] == ["Step", "Time"]:
            head = p
            continue
        if head and len(p) == len(head):
            try:
                rows.append(dict(zip(head, map(float, p))))
            except ValueError:
                head = None
    return rows


def pile_data(out):
    folder0 = os.path.join(out, "pile")
    os.makedirs(folder0, exist_ok=True)
    data = os.path.join(folder0, "pile.data")
    if not os.path.exists(data):
        subprocess.check_call([sys.executable, GEN, "5", "5", "40", "0.1", "1", "pile"], cwd=folder0,
                              stdout=subprocess.DEVNULL)
    return data


def jittered_data(out, seed, amp=1e-6):
    """gen.py's pile with every apple moved sideways by up to +-amp (1 um): another, equally
    valid start of the same pile."""
    import random
    rng = random.Random(seed)
    src = pile_data(out)
    dst = os.path.join(out, "pile", f"pile_jitter{seed}.data")
    lines = open(src).read().splitlines()
    k = lines.index("Atoms")
    for i in range(k + 1, len(lines)):
        p = lines[i].split()
        if len(p) == 7:
            p[4] = f"{float(p[4]) + rng.uniform(-amp, amp):.9f}"
            p[5] = f"{float(p[5]) + rng.uniform(-amp, amp):.9f}"
            lines[i] = " ".join(p)
    with open(dst, "w") as f:
        f.write("\n".join(lines) + "\n")
    return dst


def run_pile(out, dts, roll="epsd2", duration=5.0, tag="", skin=0.008, data=None):
    data = data or pile_data(out)
    res = []
    for dt in dts:
        name = f"pile_{roll}_dt{dt:g}{tag}"
        folder = os.path.join(out, name)
        nwin = 10
        wsteps = int(round(duration / nwin / dt))
        thermo = max(1, int(round(0.1 / dt)))
        wall, loop, err = run_deck("pile.in", folder, {
            "data": data, "W": 0.25, "skin": skin, "dt": dt, "nwin": nwin, "wsteps": wsteps,
            "thermo": thermo, "e": 0.3, "mu": 0.5, "mur": 0.03, "roll": roll, "dump": "final.dump"})
        if err:
            res.append({"name": name, "roll": roll, "dt_s": dt, "skin_m": skin, "error": err, "wall_s": wall})
            print(f"{name}: LIGGGHTS failed after {wall:.1f} s: {err}")
            continue
        log = open(os.path.join(folder, "log.lammps")).read()
        th = thermo_rows(log)
        last = th[-1]
        atoms = read_dump(os.path.join(folder, "final.dump"))
        geo = pile_geometry([(a["x"], a["y"], a["z"], a["radius"]) for a in atoms])
        # Settling: the last thermo row where the largest centre z still moved by > 1 mm in 0.1 s.
        settle = None
        for a, b in zip(th, th[1:]):
            if abs(b["zmax"] - a["zmax"]) > 1e-3:
                settle = b["Time"]
        r = {"name": name, "roll": roll, "dt_s": dt, "skin_m": skin, "wall_s": wall, "loop_s": loop,
             "simulated_s": last["Time"], "apples": int(last["Atoms"]),
             "cnavg_half": last["cnavg"] / 2, "zmax_thermo_m": last["zmax"],
             "ke_j": last["KinEng"], "rke_j": last["rke"], "zmax_last_moving_s": settle, **geo}
        res.append(r)
        print(f"{name:24s}: z_max {geo['z_max_m']:.4f} m, top-25 mean z {geo['z_top25_mean_m']:.4f} m, "
              f"contacts/apple {geo['apple_apple_contacts_per_apple']:.4f} (contact/atom / 2: {r['cnavg_half']:.4f}), "
              f"KE {last['KinEng']:.2e} J, z_max still moving at {settle} s; loop {loop:.1f} s, wall {wall:.1f} s")
    return res


def within_1pct(res):
    ref = next((r for r in res if r["dt_s"] == 1e-4 and "error" not in r), None)
    if not ref:
        return None
    out = []
    for r in res:
        if "error" in r:
            out.append({"dt_s": r["dt_s"], "ok": False, "why": r["error"]})
            continue
        d = {k: r[k] / ref[k] - 1 for k in ("z_max_m", "z_top25_mean_m", "apple_apple_contacts_per_apple")}
        ok = abs(d["z_max_m"]) <= 0.01 and abs(d["apple_apple_contacts_per_apple"]) <= 0.01
        out.append({"dt_s": r["dt_s"], "ok": ok, "rel": d, "wall_s": r["wall_s"], "loop_s": r["loop_s"]})
    good = [o["dt_s"] for o in out if o["ok"]]
    # The largest dt such that it and every smaller dt tried are within 1 %.
    largest = None
    for o in sorted(out, key=lambda o: o["dt_s"]):
        if not o["ok"]:
            break
        largest = o["dt_s"]
    return {"per_dt": out, "largest_dt_all_smaller_within": largest, "largest_dt_within": max(good) if good else None}


# ---------------------------------------------------------------------------------------- roll

def roll_figures(rows, v0, mur):
    """Stop: the first record with vx <= 0 (interpolated); rows are (t, x, vx, wy, z, F)."""
    k = next((i for i in range(1, len(rows)) if rows[i][2] <= 0), None)
    closed_d = 7 * v0 ** 2 / (10 * mur * G)
    closed_t = 7 * v0 / (5 * mur * G)
    fig = {"closed_form_distance_m": closed_d, "closed_form_time_s": closed_t}
    if k is None:
        fig.update(stop_time_s=None, stop_distance_m=None)
        return fig
    (ta, xa, va), (tb, xb, vb) = rows[k - 1][:3], rows[k][:3]
    s = va / (va - vb)
    t_stop = ta + s * (tb - ta)
    x_stop = xa + s * (xb - xa)
    after = [r for r in rows if r[0] >= t_stop]
    xs = [r[1] for r in after]
    # Deceleration while rolling: a straight-line fit of vx over 10-90 % of the stop time.
    sel = [r for r in rows if 0.1 * t_stop <= r[0] <= 0.9 * t_stop]
    n = len(sel)
    mt = sum(r[0] for r in sel) / n
    mv = sum(r[2] for r in sel) / n
    slope = sum((r[0] - mt) * (r[2] - mv) for r in sel) / sum((r[0] - mt) ** 2 for r in sel)
    fig.update(
        stop_time_s=t_stop, stop_distance_m=x_stop,
        rel_distance=x_stop / closed_d - 1, rel_time=t_stop / closed_t - 1,
        deceleration_m_s2=-slope, closed_form_deceleration_m_s2=5 / 7 * mur * G,
        x_final_m=rows[-1][1], x_after_stop_min_m=min(xs), x_after_stop_max_m=max(xs),
        vx_final_m_s=rows[-1][2], t_final_s=rows[-1][0])
    return fig


def run_roll(out):
    res = []
    v0, mur = 0.5, 0.05
    cases = [(roll, dt, "steel") for roll in ("cdt", "epsd2") for dt in (1e-5, 1e-6)]
    cases += [("cdt", 1e-5, "soft"), ("epsd2", 1e-5, "soft")]
    for roll, dt, plate in cases:
            soft = plate == "soft"
            z0 = R - static_overlap_wall(Y_STAR_SOFT if soft else Y_STAR_WALL)
            name = f"roll_{roll}{'_soft' if soft else ''}_dt{dt:g}"
            folder = os.path.join(out, name)
            every = int(round(1e-4 / dt))
            var = {"roll": roll, "mur": mur, "v0": v0, "z0": f"{z0:.9f}", "dt": dt, "tend": 2.0,
                   "every": every, "out": "rec.txt"}
            if soft:
                var.update(Ew=E_APPLE, nuw=NU_APPLE)
            wall, loop, err = run_deck("roll.in", folder, var)
            if err:
                res.append({"name": name, "roll": roll, "plate": plate, "dt_s": dt, "error": err})
                print(f"{name}: LIGGGHTS failed: {err}")
                continue
            fig = roll_figures(read_rec(os.path.join(folder, "rec.txt")), v0, mur)
            res.append({"name": name, "roll": roll, "plate": plate, "dt_s": dt, "v0": v0, "mur": mur,
                        "z0_m": z0, "wall_s": wall, "loop_s": loop, **fig})
            print(f"{name:18s}: stops after {fig['stop_distance_m']:.5f} m ({100*fig['rel_distance']:+.2f} % of "
                  f"{fig['closed_form_distance_m']:.5f}) at {fig['stop_time_s']:.4f} s ({100*fig['rel_time']:+.2f} % of "
                  f"{fig['closed_form_time_s']:.4f}); deceleration {fig['deceleration_m_s2']:.5f} m/s^2 (closed "
                  f"{fig['closed_form_deceleration_m_s2']:.5f}); after the stop x in [{fig['x_after_stop_min_m']:.5f}, "
                  f"{fig['x_after_stop_max_m']:.5f}] m; wall {wall:.1f} s")
    return res


SCATTER_DTS = (1e-4, 2e-4, 3e-4, 5e-4, 6e-4, 7e-4)
KEYS = ("z_max_m", "z_top25_mean_m", "apple_apple_contacts_per_apple")


def run_scatter(out):
    """Chaos, not the step: the same pile settles into another packing when its start moves by a
    micrometre. At each dt of SCATTER_DTS, three starts with every apple moved sideways by up to
    1 um (seeds 1-3); at dt 1e-4 also three other neighbour skins (6, 10, 12 mm: only the order
    in which the forces are summed changes) and one run at dt 5e-5."""
    res = []
    for skin in (0.006, 0.010, 0.012):
        res += run_pile(out, [1e-4], tag=f"_skin{skin:g}", skin=skin)
    res += run_pile(out, [5e-5])
    for seed in (1, 2, 3):
        for dt in SCATTER_DTS:
            for r in run_pile(out, [dt], tag=f"_jitter{seed}", data=jittered_data(out, seed)):
                r["jitter_seed"] = seed
                res.append(r)
    # The cdt pile from the same three starts (dt 1e-4 only): its own ensemble.
    for seed in (1, 2, 3):
        for r in run_pile(out, [1e-4], roll="cdt", tag=f"_jitter{seed}", data=jittered_data(out, seed)):
            r["jitter_seed"] = seed
            res.append(r)
    return res


def stats(rs):
    row = {"runs": len(rs), "loop_s_mean": sum(r["loop_s"] for r in rs) / len(rs)}
    for k in KEYS:
        v = [r[k] for r in rs]
        m = sum(v) / len(v)
        row[k] = {"mean": m, "min": min(v), "max": max(v), "spread_rel": (max(v) - min(v)) / m}
    return row


def scatter_summary(pile, scatter, pile_cdt=()):
    """Per dt: the ensemble of the gen.py start and the jittered starts (mean, min, max); at
    1e-4 also the skin runs on their own; each ensemble mean against the one at dt 1e-4."""
    ok = [r for r in pile + scatter if "error" not in r and r["roll"] == "epsd2"]
    out = {"ensembles": [], "skins_1e-4": None}
    for dt in sorted({r["dt_s"] for r in ok}):
        rs = [r for r in ok if r["dt_s"] == dt and r.get("skin_m", 0.008) == 0.008]
        out["ensembles"].append(dict(stats(rs), dt_s=dt, starts=len(rs)))
    skins = [r for r in ok if r["dt_s"] == 1e-4 and "jitter_seed" not in r]
    if skins:
        out["skins_1e-4"] = stats(skins)
    cdt = [r for r in pile_cdt + scatter if "error" not in r and r["roll"] == "cdt" and r["dt_s"] == 1e-4]
    if cdt:
        out["cdt_1e-4"] = dict(stats(cdt), dt_s=1e-4, starts=len(cdt))
    ref = next((o for o in out["ensembles"] if o["dt_s"] == 1e-4), None)
    largest = None
    if ref:
        for o in out["ensembles"]:
            o["rel_to_1e-4"] = {k: o[k]["mean"] / ref[k]["mean"] - 1 for k in KEYS}
            o["ok"] = (abs(o["rel_to_1e-4"]["z_max_m"]) <= 0.01
                       and abs(o["rel_to_1e-4"]["apple_apple_contacts_per_apple"]) <= 0.01)
        for o in out["ensembles"]:
            if o["dt_s"] < 1e-4:
                continue
            if not o["ok"]:
                break
            largest = o["dt_s"]
    out["largest_dt_ensemble_within_1pct"] = largest
    return out


def run_timing(out, dts=(1e-4, 5e-4), repeats=3):
    """Wall time of the pile (gen.py's start) at each dt, `repeats` times, alternating the dts so
    that a change of the machine's load hits both alike; the minimum and the median."""
    runs = {dt: [] for dt in dts}
    for k in range(repeats):
        for dt in dts:
            for r in run_pile(out, [dt], tag=f"_time{k + 1}"):
                if "error" not in r:
                    runs[dt].append(r["loop_s"])
    res = []
    for dt, v in runs.items():
        v = sorted(v)
        res.append({"dt_s": dt, "loop_s": v, "min_s": v[0] if v else None,
                    "median_s": v[len(v) // 2] if v else None})
        print(f"pile dt {dt:g}: time loop {', '.join(f'{x:.2f}' for x in v)} s")
    return res


def main(argv):
    global REUSE
    what, out, dts, quick = [], "/work/lig-runs/models", None, False
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("drop", "pile", "roll", "scatter", "timing", "all"):
            what.append(a)
        elif a == "--out":
            out = argv[i + 1]; i += 1
        elif a == "--pile-dts":
            dts = [float(x) for x in argv[i + 1].split(",")]; i += 1
        elif a == "--quick":
            quick = True
        elif a == "--reuse":
            REUSE = True
        elif a in ("-h", "--help"):
            print(__doc__); return 0
        else:
            print(f"unknown argument {a} (see --help)", file=sys.stderr); return 2
        i += 1
    if not what or "all" in what:
        what = ["drop", "roll", "pile", "scatter", "timing"]
    out = os.path.abspath(out)
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, "liggghts.json")
    res = json.load(open(path)) if os.path.exists(path) else {}
    res["machine"] = {"load_average_at_start": os.getloadavg(), "cpus": os.cpu_count()}
    if "drop" in what:
        res["drop"] = run_drop(out)
    if "roll" in what:
        res["roll"] = run_roll(out)
    if "pile" in what:
        if quick:
            res["pile"] = run_pile(out, [1e-4, 2e-4], duration=0.5, tag="_quick")
        else:
            res["pile"] = run_pile(out, dts or [1e-4, 2e-4, 3e-4, 5e-4, 6e-4, 7e-4, 1e-3])
            res["pile_cdt"] = run_pile(out, [1e-4], roll="cdt")
        res["pile_dt_check"] = within_1pct(res["pile"])
        print(json.dumps(res["pile_dt_check"], indent=1))
    if "scatter" in what:
        res["pile_scatter"] = run_scatter(out)
    if "timing" in what:
        best = (res.get("pile_scatter_summary") or {}).get("largest_dt_ensemble_within_1pct") or 5e-4
        res["pile_timing"] = {"load_average_before": os.getloadavg(),
                              "runs": run_timing(out, dts=(1e-4, best)),
                              "load_average_after": os.getloadavg()}
    if "pile_scatter" in res and "pile" in res:
        res["pile_scatter_summary"] = sm = scatter_summary(res["pile"], res["pile_scatter"], res.get("pile_cdt", []))
        res.pop("pile_dt_check_ensemble", None)
        for o in sm["ensembles"]:
            print(f"dt {o['dt_s']:g}, {o['starts']} start(s): " + ", ".join(
                f"{k} {o[k]['mean']:.4f} [{o[k]['min']:.4f}, {o[k]['max']:.4f}]" for k in KEYS)
                + f"; vs dt 1e-4 " + ", ".join(f"{100 * v:+.2f} %" for v in o.get("rel_to_1e-4", {}).values())
                + f"; mean loop {o['loop_s_mean']:.1f} s")
        if sm.get("cdt_1e-4"):
            o = sm["cdt_1e-4"]
            print(f"cdt, dt 1e-4, {o['starts']} starts: " + ", ".join(
                f"{k} {o[k]['mean']:.4f} [{o[k]['min']:.4f}, {o[k]['max']:.4f}]" for k in KEYS))
        if sm["skins_1e-4"]:
            o = sm["skins_1e-4"]
            print(f"dt 1e-4, skins 6/8/10/12 mm: " + ", ".join(
                f"{k} [{o[k]['min']:.4f}, {o[k]['max']:.4f}]" for k in KEYS))
        print(f"largest dt whose ensemble (height, contacts per apple) stays within 1 % of dt 1e-4's, "
              f"with every smaller dt: {sm['largest_dt_ensemble_within_1pct']}")
    with open(path, "w") as f:
        json.dump(res, f, indent=1)
    print(f"figures: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
