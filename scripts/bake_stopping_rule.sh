#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Does the stopping rule save work? Bakes one sample luminaire with --target-error E (budget 10 M) and with
# fixed particle counts, each graded once on held-out particles the same way (one pass of N particles), and
# prints particles, seconds and the finest level's error at d (upper bound) for each.
# Usage: scripts/bake_stopping_rule.sh [LUMINAIRE] [E] [D] [FIXED COUNTS...]
#   defaults: the troffer sample, 0.05, 1, and 1000000 2000000 4000000
set -euo pipefail
cd "$(dirname "$0")/.."
dir=$(bash scripts/build.sh | tail -n 1)
lumx="$dir/converters/lumx"
work=out/stopping_rule
mkdir -p "$work"
lum=${1:-}
if [ -z "$lum" ]; then
  "$dir/samples/sample_luminaires" "$work/luminaires" > /dev/null
  lum="$work/luminaires/troffer.glb"
fi
target=${2:-0.05}
distance=${3:-1}
shift $(( $# > 3 ? 3 : $# )) || true
counts=("$@")
[ ${#counts[@]} -eq 0 ] && counts=(1000000 2000000 4000000)

row() {  # label, then the bake's output on stdin
  awk -v label="$1" '
    /^trace:/ { particles = $2 }
    /pass [0-9]+:/ { seconds = $5; error = $8 }
    END { printf "%-28s %12s %10s %10s\n", label, particles, seconds, error }'
}
printf "%-28s %12s %10s %10s\n" "bake" "particles" "seconds" "error %"
"$lumx" bake "$lum" "$work/rule.lumx" --particles 10000000 --target-error "$target" --target-distance "$distance" \
  | tee "$work/rule.txt" | row "target $target at d=$distance"
for n in "${counts[@]}"; do
  "$lumx" bake "$lum" "$work/fixed_$n.lumx" --particles "$n" --pass-particles "$n" --target-error 1e-9 \
    --target-distance "$distance" | tee "$work/fixed_$n.txt" | row "fixed $n"
done
