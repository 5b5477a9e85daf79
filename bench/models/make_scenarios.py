#!/usr/bin/env python3
"""Writes the applesim scenarios of the same-model comparison (issue 19, build item 4) into
bench/models/scenarios/: the twins of drop.in, pile.in and roll.in with the matching sub-models
(`"damping": "viscoelastic"` = LIGGGHTS `model hertz` with limitForce on, `"tangential":
"history"` = `tangential history`, `"rolling": "elastic-plastic"` = `rolling_friction epsd2`,
`"constant-torque"` = `cdt`). Run it again after changing a value here; the files are committed.

usage: make_scenarios.py
"""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "scenarios")

R = 0.04
MATERIALS = {
    "apple": {"youngs_modulus_pa": 2.6e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
    "steel": {"youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.3},
}
ROLLING = {"epsd2": "elastic-plastic", "cdt": "constant-torque"}


def contact(e, mu, mur, roll):
    # No ke / lambda_s_m: only the eq. 12 dampings need them. epsd2 has no rolling dashpot, so
    # "rolling_damping": 0 (applesim's default 1.0 is a critically damped dashpot, LIGGGHTS epsd).
    c = {"friction": mu, "damping": "viscoelastic", "restitution": e,
         "tangential": "history", "rolling": ROLLING[roll], "rolling_friction": mur}
    if roll == "epsd2":
        c["rolling_damping"] = 0.0
    return c


def plate_surface(material="steel"):
    return [{"name": "plate", "type": "plane", "material": material,
             "point_m": [0, 0, 0], "normal": [0, 0, 1]}]


def drop(v0, e, g):
    name = f"drop_v{v0:g}_e{e:g}_{'g' if g else 'nog'}"
    return name, {
        "description": (
            f"Issue 19, same model as LIGGGHTS (bench/models/drop.in, vars v0 {v0:g} e {e:g} g {g:g} "
            "dt 1e-6 tend 0.02 roll epsd2): one apple (D 80 mm, 800 kg/m^3, E 2.6 MPa, nu 0.18) "
            f"dropped on a steel plate (E 200 GPa, nu 0.3) at {v0:g} m/s "
            f"{'with' if g else 'without'} gravity; viscoelastic Hertz (LIGGGHTS model hertz, "
            f"limitForce on) with restitution {e:g}, tangential history (friction 0.5), epsd2 "
            "rolling friction 0.03. The centre starts 10 um above the plate. Compare the peak force "
            "and contact time of contacts.csv (and forces.csv: the time the force is > 0) with "
            "LIGGGHTS's (bench/models/compare.sh)."),
        "duration_s": 0.02,
        "time_step_s": 1e-6,
        "gravity_m_s2": [0, 0, -g],
        "output": {"sample_interval_s": 1e-5, "force_history": True,
                   "transitions": {"enabled": False}},
        "materials": MATERIALS,
        "contact": contact(e, 0.5, 0.03, "epsd2"),
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 2 * R,
                    "position_m": [0, 0, R + 1e-5], "velocity_m_s": [0, 0, -v0]}],
        "surfaces": plate_surface(),
    }


def static_overlap(soft=False):
    m = 800 * 4 / 3 * math.pi * R ** 3
    y = 1 / ((1 - 0.18 ** 2) / 2.6e6 + ((1 - 0.18 ** 2) / 2.6e6 if soft else (1 - 0.3 ** 2) / 2e11))
    return (3 * m * 9.81 / (4 * y * math.sqrt(R))) ** (2 / 3)


def roll(model, plate="steel"):
    v0, mur = 0.5, 0.05
    soft = plate == "soft"
    z0 = round(R - static_overlap(soft), 9)
    d = 7 * v0 ** 2 / (10 * mur * 9.81)
    t = 7 * v0 / (5 * mur * 9.81)
    plate_text = ("a soft plate (the apple's E 2.6 MPa and nu 0.18, so that the contact point "
                  "sits at R - u/2 as on LIGGGHTS's walls)" if soft else "a steel plate")
    return f"roll_{model}{'_soft' if soft else ''}", {
        "description": (
            f"Issue 19, same model as LIGGGHTS (bench/models/roll.in, vars roll {model} mur 0.05 "
            f"v0 0.5 z0 {z0} dt 1e-5 tend 2{' Ew 2.6e6 nuw 0.18' if soft else ''}): an apple "
            "(D 80 mm, 800 kg/m^3) launched rolling "
            f"without slip (vx 0.5 m/s, omega_y = v0 / R) on {plate_text}, gravity, resting "
            "overlap at the start; viscoelastic Hertz (restitution 0.3), tangential history "
            f"(friction 0.5), {model} rolling friction 0.05 ({ROLLING[model]}). Closed form (cdt): "
            f"stops after 7 v0^2 / (10 mu_r g) = {d:.4f} m at 7 v0 / (5 mu_r g) = {t:.4f} s."),
        "duration_s": 2.0,
        "time_step_s": 1e-5,
        "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 1e-4, "force_history": False,
                   "transitions": {"enabled": False}},
        "materials": dict(MATERIALS, soft={"youngs_modulus_pa": 2.6e6, "poisson_ratio": 0.18}) if soft else MATERIALS,
        "contact": contact(0.3, 0.5, mur, model),
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 2 * R,
                    "position_m": [0, 0, z0], "velocity_m_s": [v0, 0, 0],
                    "angular_velocity_rad_s": [0, v0 / R, 0]}],
        "surfaces": plate_surface("soft" if soft else "steel"),
    }


def pile(model, step, accuracy=None):
    label = {1e-4: "1e-4", 5e-4: "5e-4"}.get(step)
    tag = f"dt{label}" if step != "adaptive" else f"adaptive_{accuracy}"
    sc = {
        "description": (
            f"Issue 19, same model as LIGGGHTS (bench/models/pile.in, vars roll {model} e 0.3 mu 0.5 "
            f"mur 0.03 dt {label or '1e-4'}): the 1000-apple reference pile of shared/bench/liggghts (gen.py 5 5 "
            "40 0.1 1, read from assets/piles/liggghts_1000.json) in the open steel box of "
            "half-width 0.25 m, 5 s; viscoelastic Hertz (restitution 0.3), tangential history "
            f"(friction 0.5), {model} rolling friction 0.03 ({ROLLING[model]}), apple-apple and "
            "apple-steel. "
            + (f"Fixed step {label} s as LIGGGHTS. " if step != "adaptive" else
               f"Adaptive step at accuracy '{accuracy}' (issue 19 item 5, time to an answer). ")
            + "Settled height, contacts per apple and wall time: applesim bench SCENARIO --json; "
            "positions: applesim run."),
        "duration_s": 5.0,
        "time_step_s": step,
        "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 0.5, "force_history": False,
                   "transitions": {"enabled": False}},
        "materials": MATERIALS,
        "contact": contact(0.3, 0.5, 0.03, model),
        "generators": [{"type": "file", "name": "p", "material": "apple",
                        "file": "../../../assets/piles/liggghts_1000.json"}],
        "surfaces": [
            {"name": "floor", "type": "plane", "material": "steel", "point_m": [0, 0, 0], "normal": [0, 0, 1]},
            {"name": "x_min", "type": "plane", "material": "steel", "point_m": [-0.25, 0, 0], "normal": [1, 0, 0]},
            {"name": "x_max", "type": "plane", "material": "steel", "point_m": [0.25, 0, 0], "normal": [-1, 0, 0]},
            {"name": "y_min", "type": "plane", "material": "steel", "point_m": [0, -0.25, 0], "normal": [0, 1, 0]},
            {"name": "y_max", "type": "plane", "material": "steel", "point_m": [0, 0.25, 0], "normal": [0, -1, 0]},
        ],
    }
    if accuracy:
        # After time_step_s, as in the README's example.
        sc = dict(list(sc.items())[:3] + [("accuracy", accuracy)] + list(sc.items())[3:])
    return f"pile_{model}_{tag}", sc


def all_scenarios():
    for g in (0.0, 9.81):
        for e in (0.3, 0.65):
            for v0 in (1.0, 0.5):
                yield drop(v0, e, g)
    for m in ("cdt", "epsd2"):
        yield roll(m)
        yield roll(m, "soft")
    yield pile("epsd2", 1e-4)
    yield pile("cdt", 1e-4)
    yield pile("epsd2", 5e-4)  # LIGGGHTS's largest dt within 1 %, for the timing (item 5)
    yield pile("epsd2", "adaptive", "balanced")
    yield pile("epsd2", "adaptive", "preview")
    yield from diagnosis()


def variant(name, sc, what, **contact):
    """A pile scenario changed for the diagnosis of the awake pile (time_to_answer.py --diagnose)."""
    sc = json.loads(json.dumps(sc))
    sc["description"] = ("Diagnosis of the pile that stays awake at accuracy preview (issue 19 item 5, "
                         "docs/liggghts_models.md): " + what + " Otherwise as this: " + sc["description"])
    sc["contact"].update(contact)
    return name, sc


def diagnosis():
    _, fixed = pile("epsd2", 1e-4)
    _, prev = pile("epsd2", "adaptive", "preview")
    _, bal = pile("epsd2", "adaptive", "balanced")
    fixed6 = dict(fixed, time_step_s=6e-4)
    yield variant("diag_pile_epsd2_dt6e-4", fixed6,
                  "fixed step 6e-4 s, LIGGGHTS's first step that no longer settles.")
    for n in (16, 24):
        sc = dict(bal, accuracy=n)
        yield variant(f"diag_pile_epsd2_adaptive_{n}", sc,
                      f"accuracy {n} steps per contact: resting contacts get t/{max(n / 4, 4):g} "
                      "(src/layer/adaptive.rs contact_step_limit).")
    yield variant("diag_pile_epsd2_mindlin_adaptive_preview", prev,
                  "tangential mindlin (applesim's own dashpot, bounded by the velocity-kill rate) "
                  "instead of history.", tangential="mindlin")
    yield variant("diag_pile_epsd2_e0.65_adaptive_preview", prev,
                  "restitution 0.65 (the history damping ratio 0.23 instead of 0.61).", restitution=0.65)


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    for name, sc in all_scenarios():
        with open(os.path.join(OUT, name + ".json"), "w") as f:
            json.dump(sc, f, indent=2)
            f.write("\n")
        print(os.path.join("bench/models/scenarios", name + ".json"))
