#!/usr/bin/env bash
# Times what a newcomer waits for on a fresh clone of this repository's HEAD, in a folder of
# its own with an empty target directory: the README's first command (`first-run`, the
# default), or a whole CI run (`ci`, `.ci/run`). Crates already in the local cargo registry
# are not downloaded again. Prints one line, for docs/benchmarks.md.
# Usage: benches/fresh-clone.sh [first-run|ci]
set -euo pipefail
what="${1:-first-run}"
root="$(cd "$(dirname "$0")/.." && pwd)"
clone="$(mktemp -d)"
log="$(mktemp)"
trap 'rm -rf "$clone" "$log"' EXIT
git clone --quiet "$root" "$clone"
cd "$clone"
commit="$(git rev-parse --short HEAD)"
case "$what" in
    first-run) command=(cargo run --release --example chip_cell) ;;
    ci) command=(.ci/run) ;;
    *) echo "usage: $0 [first-run|ci]" >&2; exit 2 ;;
esac
start="$(date +%s)"
"${command[@]}" >"$log" 2>&1 || { tail -40 "$log" >&2; exit 1; }
seconds=$(( $(date +%s) - start ))
crates="$(grep -c '^ *Compiling ' "$log" || true)"
printf '%s: `%s` on a fresh clone of %s, %d cores: %dm %02ds, %s crates compiled\n' \
    "$(date -u +%Y-%m-%d)" "${command[*]}" "$commit" "$(nproc)" \
    $((seconds / 60)) $((seconds % 60)) "$crates"
