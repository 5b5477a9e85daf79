#!/usr/bin/env bash
# The same contact model in LIGGGHTS 3.8 and applesim (issue 19, build items 4 and 5), in one go.
#
# usage: bench/models/compare.sh [OUT_DIR] [--quick] [--reuse] [--skip-liggghts] [--skip-applesim]
#   OUT_DIR          where the runs and liggghts.json / applesim.json go (default
#                    /work/lig-runs/models, with --quick /work/lig-runs/models-quick; not in
#                    the repository)
#   --quick          LIGGGHTS's pile only 0.5 s at dt 1e-4 and 2e-4, no scatter or timing runs
#                    (a check of the scripts, about 1 min; keep it out of a full run's OUT_DIR;
#                    applesim's runs are always whole)
#   --reuse          LIGGGHTS cases already run with the same command in OUT_DIR are read, not
#                    run again (their wall times are those measured then)
#   --skip-liggghts  only applesim (reads LIGGGHTS's figures from OUT_DIR/liggghts.json)
#   --skip-applesim  only LIGGGHTS
#
# First LIGGGHTS (bench/models/liggghts.py: drop.in, roll.in, pile.in; serial, one core, pinned
# to core 1 when taskset exists), then applesim (cargo build --release, then
# bench/models/applesim.py: `applesim run` / `applesim bench --threads 1` of
# bench/models/scenarios/), strictly one after the other (the pile runs are timed), then the
# table (bench/models/compare.py, also written to OUT_DIR/table.txt). The whole thing takes about
# 5 min of LIGGGHTS on an idle core plus applesim's runs.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
out=
quick=0
lig_args=(all)
app=1
lig=1
reuse=()
while [ $# -gt 0 ]; do
  case $1 in
    --quick) lig_args=(drop roll pile --quick); quick=1 ;;
    --reuse) reuse=(--reuse) ;;
    --skip-liggghts) lig=0 ;;
    --skip-applesim) app=0 ;;
    -h | --help) sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "unknown option $1 (see --help)" >&2; exit 2 ;;
    *) out=$1 ;;
  esac
  shift
done
if [ -z "$out" ]; then
  if [ $quick = 1 ]; then out=/work/lig-runs/models-quick; else out=/work/lig-runs/models; fi
fi
mkdir -p "$out"
out=$(cd "$out" && pwd)
pin=()
if command -v taskset >/dev/null; then pin=(taskset -c 1); fi

if [ $lig = 1 ]; then
  command -v liggghts >/dev/null || { echo "LIGGGHTS is missing (Debian: apt-get install liggghts)" >&2; exit 2; }
  echo "== LIGGGHTS (bench/models/liggghts.py ${lig_args[*]})" >&2
  "${pin[@]}" python3 "$here/liggghts.py" "${lig_args[@]}" "${reuse[@]}" --out "$out" | tee "$out/liggghts.out" >&2
fi
if [ $app = 1 ]; then
  echo "== applesim (cargo build --release; bench/models/applesim.py)" >&2
  (cd "$repo" && cargo build --release --quiet)
  exe=${CARGO_TARGET_DIR:-$repo/target}/release/applesim
  python3 "$here/applesim.py" all --out "$out" --applesim "$exe" --threads 1 | tee "$out/applesim.out" >&2
fi
python3 "$here/compare.py" "$out" | tee "$out/table.txt"
