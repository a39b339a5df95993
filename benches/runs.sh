#!/usr/bin/env bash
# Runs every benchmark N times (default 5), keeps each run's ratio table, and prints each
# row's median and spread over the runs. One run on a shared machine says little.
#
#   benches/runs.sh [N]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
out=target/bench-runs
rm -rf "$out"
mkdir -p "$out"
for run in $(seq 1 "$runs"); do
  echo "run $run of $runs" >&2
  cargo bench -p imrs-benches >"$out/bench-$run.log" 2>&1
  cargo run --release -q -p imrs-benches --bin ratio_table >"$out/table-$run.txt"
  cp target/criterion/ratios.tsv "$out/run-$run.tsv"
done
cargo run --release -q -p imrs-benches --bin ratio_table -- --runs "$out"
