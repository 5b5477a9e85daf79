#!/usr/bin/env bash
# Checks that a change of code changes no output: every shipped scenario (scenarios/*.json,
# scenarios/paper/*.json, the paper's batch specs through `applesim batch`, and the 1000-apple
# bench pile shortened to 1.5 s) is run by two builds and their folders compared byte for byte,
# summary.json apart from wall_time_s (a measurement). Charts (--plots) are compared too.
#
#   tools/same_outputs.sh record BIN OUT_DIR       run everything with BIN into OUT_DIR
#   tools/same_outputs.sh compare DIR_A DIR_B      compare two recorded folders
#   tools/same_outputs.sh REV [OUT_DIR]            build REV (e.g. HEAD~3) in a temporary worktree
#                                                  and the working tree, record both, compare
#
# Exit status 0 only when every file is identical.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"

record() {
    local bin="$1" out="$2"
    rm -rf "$out"; mkdir -p "$out"
    local f name
    for f in "$ROOT"/scenarios/*.json "$ROOT"/scenarios/paper/*.json; do
        name="$(basename "$(dirname "$f")")_$(basename "$f" .json)"
        if python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); sys.exit(0 if ("base" in d or "parameters" in d) else 1)' "$f"; then
            "$bin" batch "$f" --out "$out/$name" --jobs 1 >/dev/null 2>"$out/$name.stderr" || echo "exit $?" >>"$out/$name.stderr"
            "$bin" merge "$out/$name" >/dev/null 2>>"$out/$name.stderr" || echo "merge exit $?" >>"$out/$name.stderr"
        else
            "$bin" run "$f" --out "$out/$name" --quiet --plots --threads 1 2>"$out/$name.stderr" || echo "exit $?" >>"$out/$name.stderr"
        fi
    done
    # The 1000-apple bench pile, shortened to 1.5 s (two threads: the parallel force pass too).
    local pile="$ROOT/scenarios/bench/liggghts_pile_1000.json"
    local short="$ROOT/scenarios/bench/.pile_1000_short.json"
    python3 - "$pile" "$short" <<'PY'
import json, sys
d = json.load(open(sys.argv[1])); d["duration_s"] = 1.5
json.dump(d, open(sys.argv[2], "w"), indent=1)
PY
    "$bin" run "$short" --out "$out/bench_pile_1000_1.5s" --quiet --threads 2 2>"$out/bench_pile.stderr" || echo "exit $?" >>"$out/bench_pile.stderr"
    rm -f "$short"
    # wall_time_s is a measurement; batch manifests record times and hosts.
    find "$out" -name summary.json -print0 | xargs -0 -r sed -i -E 's/"wall_time_s": *[-0-9.eE+]+/"wall_time_s": 0/'
    find "$out" \( -name 'manifest*.json' -o -name '*.log' \) -print0 | xargs -0 -r rm -f
    # scenario.json records the path of the spec only through its content: keep it.
    find "$out" -name '*.stderr' -empty -delete
}

compare() {
    if diff -r -q "$1" "$2"; then
        echo "identical: $(find "$1" -type f | wc -l) files"
    else
        echo "DIFFERENT (see above)"; return 1
    fi
}

case "${1:-}" in
    record) record "$2" "$3" ;;
    compare) compare "$2" "$3" ;;
    ""|-h|--help) sed -n 2,13p "$0"; exit 2 ;;
    *)
        rev="$1"; out="${2:-$ROOT/out/same_outputs}"
        wt="$(mktemp -d)"; trap 'git -C "$ROOT" worktree remove --force "$wt" >/dev/null 2>&1 || true' EXIT
        git -C "$ROOT" worktree add --detach "$wt" "$rev" >/dev/null
        (cd "$wt" && CARGO_TARGET_DIR="${BEFORE_TARGET_DIR:-$ROOT/target/same_outputs_before}" cargo build --release -q)
        (cd "$ROOT" && cargo build --release -q)
        record "${BEFORE_TARGET_DIR:-$ROOT/target/same_outputs_before}/release/applesim" "$out/before"
        record "$ROOT/target/release/applesim" "$out/after"
        compare "$out/before" "$out/after"
        ;;
esac
