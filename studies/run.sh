#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Runs the study programs of a build and writes one CSV per study; builds nothing.
#
#   studies/run.sh [--quick] [--out OUT_DIR] BUILD_DIR [STUDY...]
#
# BUILD_DIR is a configured and built lumx build (its studies/lumx_study_* programs). OUT_DIR defaults to
# out/studies under the repository. STUDY is PROGRAM (every study of lumx_study_PROGRAM) or PROGRAM/NAME,
# e.g. spot or spot/more-rays; without one, every study runs. --quick passes --quick to each study (its
# smaller variant: the program's --help says what each leaves out). Each study writes
# OUT_DIR/PROGRAM-NAME.csv, replaced only when the study succeeds; the script exits non-zero if any
# study failed, after running the rest. studies/tables.py OUT_DIR turns the files into markdown tables.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
quick=()
out="$here/../out/studies"
usage() { sed -n '4,13p' "$0" | sed 's/^# \{0,1\}//'; }
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=(--quick); shift ;;
    --out) [ $# -ge 2 ] || { usage >&2; exit 2; }; out=$2; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    -*) echo "run.sh: unknown option $1" >&2; usage >&2; exit 2 ;;
    *) break ;;
  esac
done
[ $# -ge 1 ] || { usage >&2; exit 2; }
build=$1
shift
programs=(pinhole_box far_field spot kernel_density)
selected=("$@")
if [ ${#selected[@]} -eq 0 ]; then
  selected=("${programs[@]}")
fi
mkdir -p "$out"
failed=0
for sel in "${selected[@]}"; do
  program=${sel%%/*}
  exe="$build/studies/lumx_study_$program"
  if [ ! -x "$exe" ]; then
    echo "run.sh: no study program $exe (build the target lumx_study_$program)" >&2
    failed=1
    continue
  fi
  if [[ "$sel" == */* ]]; then
    names=("${sel#*/}")
  else
    mapfile -t names < <("$exe" --list | cut -f1)
  fi
  for name in "${names[@]}"; do
    csv="$out/$program-$name.csv"
    start=$(date +%s)
    if "$exe" "$name" --out "$csv.part" "${quick[@]}"; then
      mv "$csv.part" "$csv"
      echo "$program/$name: $csv ($(( $(date +%s) - start )) s)" >&2
    else
      rm -f "$csv.part"
      echo "$program/$name: failed" >&2
      failed=1
    fi
  done
done
exit $failed
