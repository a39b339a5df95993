#!/usr/bin/env bash
# Runs every benchmark and the idle-module count N times (default 5), keeps each run's rows,
# and prints the ratio table: each row's median and spread over the runs, as Markdown. One
# run on a shared machine says little. With --write, the table also replaces the one in
# docs/benchmarks.md (between its ratio-table markers).
#
#   benches/runs.sh [N] [--write]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=5
write=()
for arg in "$@"; do
  case "$arg" in
    --write) write=(--write docs/benchmarks.md) ;;
    *[!0-9]* | "")
      echo "usage: benches/runs.sh [N] [--write]" >&2
      exit 2
      ;;
    *) runs=$arg ;;
  esac
done
# Where cargo builds, and so where criterion and the programs below leave their figures.
target=${CARGO_TARGET_DIR:-target}
out=$target/bench-runs
rm -rf "$out"
mkdir -p "$out"
cargo build --release -q -p imrs-benches --bins
for run in $(seq 1 "$runs"); do
  echo "run $run of $runs" >&2
  cargo bench -p imrs-benches >"$out/bench-$run.log" 2>&1
  "$target/release/idle_modules" >"$out/idle-$run.txt"
  "$target/release/ratio_table" >"$out/table-$run.txt"
  cp "$target/criterion/ratios.tsv" "$out/run-$run.tsv"
done
"$target/release/ratio_table" --runs "$out" "${write[@]}"
