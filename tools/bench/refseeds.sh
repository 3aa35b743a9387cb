#!/usr/bin/env bash
# B-converge (docs/benchmarks.md): renders the default shot's frame 1 as a
# physical reference with sampler seeds 1 and 2, then measures the noise left
# as FLIP / SSIM between the two on the hair mask (never against a same-seed
# render, which shares its first samples).
#
#   tools/bench/refseeds.sh TAG [--set KEY=VALUE ...]
#
# Needs the shot's strand cache in $OUT (default /tmp/hairpipe-converge;
# `hairpipe sim scenes/default.yaml --out $OUT` writes it, or the render
# simulates first). HAIRPIPE names the binary (default build/tools/hairpipe).
set -u
BIN=${HAIRPIPE:-build/tools/hairpipe}
OUT=${OUT:-/tmp/hairpipe-converge}
TAG=$1
shift
rm -rf "${OUT:?}/$TAG"
for s in 1 2; do
  /usr/bin/time -f "%e s wall" "$BIN" render scenes/default.yaml --reference --out "$OUT" --frames 1 -v \
    --set reference.kajiya_kay.enabled=false --set reference.seed=$s \
    --set "reference.exr=$TAG/s$s.####.exr" --set "reference.png=$TAG/s$s.####.png" "$@" 2>&1 |
    grep -E "reference: frame 1:|wall|pass to" | tail -4
done
"$BIN" compare "$OUT/$TAG/s1.####.exr" "$OUT/$TAG/s2.####.exr" --mask hair --out "$OUT/$TAG/cmp" 2>&1 | tail -3
