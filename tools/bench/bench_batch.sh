#!/usr/bin/env bash
# Batch throughput of a shot: wall time end to end (`hairpipe run`, every
# stage, from an empty folder) with --jobs 1 and --jobs 2, and per stage the
# frames per minute (the simulation alone with `hairpipe sim`, then each frame
# stage alone from that cache with `run --stages S --cache-only`, --jobs 1 and
# 2). Per-stage runs add process start-up and scene loading per chunk, so
# their sum is a little above the end-to-end time.
#
#   tools/bench/bench_batch.sh [scene.yaml] [frames] [workdir]
#   (defaults: scenes/default.yaml, 1-24, a temporary folder)
#
# The default shot (84 frames) takes minutes per run on a 2-core machine, so
# the default measures frames 1-24; pass 1-84 for the whole shot. Needs a
# Release build in build/. Prints a Markdown table.
set -euo pipefail

root="$(cd "$(dirname "$0")/../.." && pwd)"
scene="${1:-$root/scenes/default.yaml}"
frames="${2:-1-24}"
work="${3:-$(mktemp -d)}"
hp="$root/build/tools/hairpipe"
[ -x "$hp" ] || { echo "bench_batch: $hp not built" >&2; exit 1; }
mkdir -p "$work"

now() { date +%s.%N; }
# seconds FOLDER ARGS...: runs hairpipe quietly into FOLDER, prints the wall
# seconds. Exit code 2 is accepted: the default scene's compare thresholds
# flag the preview's drift from the reference, which is not a batch failure.
seconds() {
  local out="$1"; shift
  local t0 rc=0; t0=$(now)
  "$hp" "$@" --out "$out" -q >"$out.log" 2>&1 || rc=$?
  [ "$rc" -eq 0 ] || [ "$rc" -eq 2 ] || { echo "bench_batch: hairpipe $* failed ($rc), see $out.log" >&2; exit 1; }
  echo "$(now) - $t0" | bc -l
}
# frames STAGE FOLDER: how many stage-frames the run wrote (its outputs' frame numbers).
count() { "$hp" farm status "$scene" --frames "$frames" --out "$2" 2>/dev/null | awk -v s="$1" '$1 == s && $2 ~ /^[0-9]+$/ { print $2; exit }' || true; }
fpm() { echo "scale=1; 60 * $1 / $2" | bc -l; }

echo "scene $scene, frames $frames, $(nproc) cores, $(date -u +%FT%TZ); workdir $work"
echo
echo "| run | jobs | wall s | frames | frames/min |"
echo "|---|---|---|---|---|"
for jobs in 1 2; do
  dir="$work/e2e-j$jobs"; rm -rf "$dir"
  s=$(seconds "$dir" run "$scene" --frames "$frames" --jobs "$jobs")
  n=$(count sim "$dir")
  printf "| end to end (every stage) | %s | %.1f | %s | %s |\n" "$jobs" "$s" "$n" "$(fpm "$n" "$s")"
done

dir="$work/stages"; rm -rf "$dir"
s=$(seconds "$dir" sim "$scene" --frames "$frames")
n=$(count sim "$dir")
printf "| sim (sequential) | 1 | %.1f | %s | %s |\n" "$s" "$n" "$(fpm "$n" "$s")"
for jobs in 1 2; do
  # Each jobs setting renders into its own copy of the cache.
  d="$work/stages-j$jobs"; rm -rf "$d"; mkdir -p "$d"; cp -r "$dir/cache" "$d/"
  for stage in preview reference vdb compare; do
    s=$(seconds "$d" run "$scene" --frames "$frames" --stages "$stage" --cache-only --jobs "$jobs")
    n=$(count "$stage" "$d")
    printf "| %s | %s | %.1f | %s | %s |\n" "$stage" "$jobs" "$s" "$n" "$(fpm "$n" "$s")"
  done
done
