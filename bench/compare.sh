#!/usr/bin/env bash
# applesim against LIGGGHTS on the same apple pile (issue 11), on this machine, in one go.
#
# usage: bench/compare.sh [1000|8000|all] [OUT_DIR] [--det-duration SECONDS]
#   1000 | 8000 | all   which pile (default all; the 8000 pile has 8036 apples)
#   OUT_DIR             where everything goes (default bench-out/ in the repository)
#   --det-duration S    simulated seconds of the thread determinism check (default 1.5; 5 runs
#                       the shipped 1000-apple scenario whole)
#
# For each pile: the reference run of LIGGGHTS (LIGGGHTS_BENCH/run.sh, default
# ../shared/bench/liggghts beside the repository; serial, one core) under /usr/bin/time -v, a
# check that the pile it generated is the committed assets/piles/liggghts_N.json, then
# `applesim bench` on scenarios/bench/liggghts_pile_N.json with --threads 1 and --threads 2.
# The runs go strictly one after the other (they are timed). Then the table (also written to
# OUT_DIR/table.txt) and the determinism check: `applesim run` of the 1000-apple pile with one
# thread and with two must write the same bytes (summary.json: all but wall_time_s).
set -euo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
bench_dir=${LIGGGHTS_BENCH:-$repo/../shared/bench/liggghts}
which=all
out=
det_duration=1.5
while [ $# -gt 0 ]; do
  case $1 in
    1000 | 8000 | all) which=$1 ;;
    --det-duration)
      [ $# -ge 2 ] || { echo "--det-duration needs a number of seconds" >&2; exit 2; }
      det_duration=$2; shift ;;
    -h | --help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "unknown option $1 (see --help)" >&2; exit 2 ;;
    [0-9]*) echo "pile $1: give 1000, 8000 or all" >&2; exit 2 ;;
    *)
      [ -z "$out" ] || { echo "two output folders given: $out and $1" >&2; exit 2; }
      out=$1 ;;
  esac
  shift
done
out=${out:-$repo/bench-out}
case $which in
  all) sizes="1000 8000" ;;
  *) sizes=$which ;;
esac
bench_dir=$(cd "$bench_dir" 2>/dev/null && pwd || echo "$bench_dir")
if [ ! -x "$bench_dir/run.sh" ]; then
  echo "no LIGGGHTS reference at $bench_dir/run.sh: set LIGGGHTS_BENCH to its folder" >&2
  exit 2
fi
if [ ! -x /usr/bin/time ]; then
  echo "/usr/bin/time is missing (Debian: apt-get install time)" >&2
  exit 2
fi
python3 -c "float('$det_duration')" 2>/dev/null || { echo "--det-duration: '$det_duration' is not a number" >&2; exit 2; }
mkdir -p "$out"
out=$(cd "$out" && pwd)

# Install LIGGGHTS before anything is timed (run.sh would otherwise do it inside the timed run).
if ! command -v liggghts >/dev/null; then
  echo "LIGGGHTS is missing: installing it from Debian's packages first (as run.sh would)" >&2
  (apt-get update -qq && apt-get install -y -qq liggghts) >/dev/null
fi

echo "building applesim (cargo build --release)" >&2
(cd "$repo" && cargo build --release --quiet)
applesim=$repo/target/release/applesim

apples_of() { if [ "$1" = 8000 ]; then echo 8036; else echo 1000; fi; }

for n in $sizes; do
  m=$(apples_of "$n")
  lig=$out/liggghts-$n
  rm -rf "$lig"
  echo "== $m apples: LIGGGHTS ($bench_dir/run.sh $n, one core)" >&2
  /usr/bin/time -v -o "$out/liggghts-$n.time" "$bench_dir/run.sh" "$n" "$lig" | tee "$out/liggghts-$n.out" >&2
  if cmp -s "$lig/pile.json" "$repo/assets/piles/liggghts_$m.json"; then
    echo "pile.json of LIGGGHTS's run is assets/piles/liggghts_$m.json, byte for byte" >&2
  else
    echo "WARNING: $lig/pile.json differs from assets/piles/liggghts_$m.json: the two codes do not run the same apples" | tee "$out/pile-$n.warning" >&2
  fi
  for t in 1 2; do
    echo "== $m apples: applesim bench --threads $t" >&2
    /usr/bin/time -v -o "$out/applesim-$n-t$t.time" \
      "$applesim" bench "$repo/scenarios/bench/liggghts_pile_$m.json" --threads "$t" --json \
      > "$out/applesim-$n-t$t.json"
  done
done

python3 - "$out" $sizes <<'EOF' | tee "$out/table.txt"
import json, os, re, sys

out, sizes = sys.argv[1], sys.argv[2:]
PHASES = [("falling", 0.0, 0.5, "falling 0-0.5 s"), ("impact", 0.5, 1.0, "impact 0.5-1 s"),
          ("settled", 3.0, 5.0, "settled 3-5 s")]


def max_rss_mib(path):
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", open(path).read())
    return int(m.group(1)) / 1024 if m else float("nan")


def liggghts(n):
    text = open(os.path.join(out, f"liggghts-{n}.out")).read()
    num = r"([\d.eE+-]+)"
    m = re.search(rf"falling 0-0.5 s {num}, impact 0.5-1 s {num}, settled 3-5 s {num}, "
                  rf"whole 0-5 s {num}; wall time 0-5 s {num} s", text)
    if not m:
        sys.exit(f"cannot find the phase figures in liggghts-{n}.out")
    rates = dict(zip(["falling", "impact", "settled", "whole"], map(float, m.groups()[:4])))
    # The last thermo row of log.lammps: step atoms ke c_rke c_cnavg c_zmax.
    header, last = None, None
    for line in open(os.path.join(out, f"liggghts-{n}", "log.lammps")):
        f = line.split()
        if "cnavg" in f and "zmax" in f:
            header = f
        elif header and len(f) == len(header):
            try:
                last = dict(zip(header, map(float, f)))
            except ValueError:
                header = None
    if last is None:
        sys.exit(f"no thermo row in liggghts-{n}/log.lammps")
    return {"rates": rates, "wall_s": float(m.group(5)),
            "apple_apple_per_apple": last["cnavg"] / 2, "pile_height_m": last["zmax"],
            "rss_mib": max_rss_mib(os.path.join(out, f"liggghts-{n}.time"))}


def applesim(n, t):
    r = json.load(open(os.path.join(out, f"applesim-{n}-t{t}.json")))
    win = {}
    for name, a, b, _ in PHASES:
        w = [w for w in r["windows"] if abs(w["from_s"] - a) < 1e-9 and abs(w["to_s"] - b) < 1e-9]
        win[name] = w[0] if w else None
    r["phase"] = win
    r["rss_time_mib"] = max_rss_mib(os.path.join(out, f"applesim-{n}-t{t}.time"))
    return r


def mib(x):
    return "n/a" if x is None else f"{x:.1f}"


def e(x):
    return "-" if x is None else f"{x:.3e}"


def ratio(a, b):
    return "-" if a is None or b is None or b == 0 else f"{a / b:.3f}"


def rel(a, b):
    return f"{100 * (a - b) / b:+.1f} %"


whole = {}
for n in sizes:
    L, A1, A2 = liggghts(n), applesim(n, 1), applesim(n, 2)
    apples = A1["apples"]
    print(f"\n== {apples} apples (pile {n}): apple-steps/s (apples x steps / wall s of the time loop)")
    print(f"{'phase':<18} {'LIGGGHTS':>10} {'applesim 1t':>12} {'applesim 2t':>12} "
          f"{'1t/LIGGGHTS':>12} {'2t/LIGGGHTS':>12}")
    for name, _, _, label in PHASES:
        l = L["rates"][name]
        a1 = A1["phase"][name] and A1["phase"][name]["apple_steps_per_s"]
        a2 = A2["phase"][name] and A2["phase"][name]["apple_steps_per_s"]
        print(f"{label:<18} {e(l):>10} {e(a1):>12} {e(a2):>12} {ratio(a1, l):>12} {ratio(a2, l):>12}")
    l = L["rates"]["whole"]
    a1, a2 = A1["apple_steps_per_s"], A2["apple_steps_per_s"]
    print(f"{'whole 0-5 s':<18} {e(l):>10} {e(a1):>12} {e(a2):>12} {ratio(a1, l):>12} {ratio(a2, l):>12}")
    awake = ", ".join(f"{label} {A1['phase'][name]['mean_awake_apples']:.1f}"
                      for name, _, _, label in PHASES if A1["phase"][name])
    print(f"applesim mean awake apples (the rest sleep; LIGGGHTS computes all): {awake}")
    print(f"whole-run wall time of the time loop: LIGGGHTS {L['wall_s']:.2f} s, applesim "
          f"1t {A1['wall_s']:.2f} s, 2t {A2['wall_s']:.2f} s; applesim / LIGGGHTS "
          f"{ratio(A1['wall_s'], L['wall_s'])} (1t), {ratio(A2['wall_s'], L['wall_s'])} (2t)")
    i1 = A1["phase"]["impact"] and A1["phase"]["impact"]["apple_steps_per_s"]
    i2 = A2["phase"]["impact"] and A2["phase"]["impact"]["apple_steps_per_s"]
    print(f"applesim impact phase, 2 threads / 1 thread: {ratio(i2, i1)} (speed-up)")
    print(f"peak resident memory (/usr/bin/time -v): LIGGGHTS {L['rss_mib']:.1f} MiB, applesim "
          f"1t {A1['rss_time_mib']:.1f} MiB, 2t {A2['rss_time_mib']:.1f} MiB "
          f"(applesim's own VmHWM: {mib(A1['peak_rss_mib'])} / {mib(A2['peak_rss_mib'])} MiB)")
    h = A1["pile_height_m"]
    same = "" if A1["pile_height_m"] == A2["pile_height_m"] else \
        f" (WARNING: 2 threads gave {A2['pile_height_m']:.4f} m)"
    print(f"settled pile height (largest apple-centre z at 5 s): LIGGGHTS "
          f"{L['pile_height_m']:.4f} m, applesim {h:.4f} m{same}; applesim vs LIGGGHTS "
          f"{rel(h, L['pile_height_m'])}")
    s1 = A1["phase"]["settled"]
    if s1:
        c = s1["apple_apple_contacts_per_apple"]
        print(f"apple-apple contacts per apple at 5 s (each pair once): LIGGGHTS "
              f"{L['apple_apple_per_apple']:.3f} (c_cnavg / 2), applesim {c:.3f}; applesim vs "
              f"LIGGGHTS {rel(c, L['apple_apple_per_apple'])}")
    if os.path.exists(os.path.join(out, f"pile-{n}.warning")):
        print("WARNING: LIGGGHTS's pile.json differs from the committed one (see above)")
    whole[n] = (apples, l, a1, a2)

if "1000" in whole and "8000" in whole:
    (n1, l1, a1, b1), (n8, l8, a8, b8) = whole["1000"], whole["8000"]
    print(f"\ncost per apple-step, {n8} apples / {n1} apples (whole run; 1 = scales linearly): "
          f"LIGGGHTS {l1 / l8:.3f}, applesim 1t {a1 / a8:.3f}, 2t {b1 / b8:.3f}")
EOF

# Determinism: one thread and two give the same bytes.
det=$out/determinism
rm -rf "$det"
mkdir -p "$det"
if python3 -c "import sys; sys.exit(0 if float('$det_duration') >= 5 else 1)"; then
  det_scenario=$repo/scenarios/bench/liggghts_pile_1000.json
  det_what="the shipped scenario, 5 s"
else
  det_scenario=$det/liggghts_pile_1000_${det_duration}s.json
  python3 - "$repo" "$det_scenario" "$det_duration" <<'EOF'
import json, os, sys
repo, dest, dur = sys.argv[1], sys.argv[2], float(sys.argv[3])
sc = json.load(open(os.path.join(repo, "scenarios/bench/liggghts_pile_1000.json")))
sc["duration_s"] = dur
sc["description"] = f"determinism check of bench/compare.sh: scenarios/bench/liggghts_pile_1000.json shortened to {dur} s"
sc["generators"][0]["file"] = os.path.join(repo, "assets/piles/liggghts_1000.json")
json.dump(sc, open(dest, "w"), indent=2)
EOF
  det_what="a copy shortened to $det_duration s: $det_scenario"
fi
echo "== determinism: applesim run of the 1000-apple pile ($det_what), --threads 1 and --threads 2" >&2
"$applesim" run "$det_scenario" --threads 1 --out "$det/det1" --quiet
"$applesim" run "$det_scenario" --threads 2 --out "$det/det2" --quiet
python3 - "$det/det1" "$det/det2" "$det_what" <<'EOF' | tee -a "$out/table.txt"
import json, os, sys
a, b, what = sys.argv[1:4]


def files(d):
    return sorted(os.path.relpath(os.path.join(r, f), d) for r, _, fs in os.walk(d) for f in fs)


fa, fb = files(a), files(b)
bad = [f"only in one run: {f}" for f in sorted(set(fa) ^ set(fb))]
for f in sorted(set(fa) & set(fb)):
    x, y = open(os.path.join(a, f), "rb").read(), open(os.path.join(b, f), "rb").read()
    if f == "summary.json":
        x, y = json.loads(x), json.loads(y)
        x.pop("wall_time_s", None)
        y.pop("wall_time_s", None)
    if x != y:
        bad.append(f"differs: {f}")
print(f"\ndeterminism, 1000-apple pile ({what}): --threads 1 and --threads 2 wrote "
      f"{len(fa)} files; " + ("all identical byte for byte (summary.json but wall_time_s)"
                              if not bad else "NOT identical: " + "; ".join(bad)))
sys.exit(1 if bad else 0)
EOF
echo "everything is in $out (table: $out/table.txt)" >&2
