#!/bin/sh
# Times the chip cell's default command for an 8-hour shift (the chosen feeder policy and
# the other two beside it), release build, and prints the figure of the chip cell's row in
# docs/benchmarks.md and of the README: the median wall time of RUNS runs (default 3), as
# each run's last line gives it, from the start of the command to its last line.
#
#   crates/cell-example/time-shift.sh [RUNS]
#
# Other work on the machine slows it down: time it on a quiet one.
set -eu
runs=${1:-3}
cd "$(dirname "$0")/../.."
cargo build --release --quiet --example chip_cell
walls=""
cores=""
i=0
while [ "$i" -lt "$runs" ]; do
    # The compilation is not timed: the line counts from the start of the example itself.
    line=$(cargo run --release --quiet --example chip_cell -- --hours 8 --no-progress | tail -n 1)
    echo "$line" >&2
    wall=$(echo "$line" | sed -n 's/.* in \([0-9.]*\) s of wall time on \([0-9]*\) cores\{0,1\} .*/\1/p')
    cores=$(echo "$line" | sed -n 's/.* s of wall time on \([0-9]*\) cores\{0,1\} .*/\1/p')
    if [ -z "$wall" ]; then
        echo "time-shift.sh: no wall time in the last line: $line" >&2
        exit 1
    fi
    walls="$walls $wall"
    i=$((i + 1))
done
median=$(printf '%s\n' $walls | sort -n | sed -n "$(((runs + 1) / 2))p")
[ "$cores" = 1 ] && unit=core || unit=cores
printf '%.1f s of wall time on %s %s (median of %s)\n' "$median" "$cores" "$unit" "$runs"
