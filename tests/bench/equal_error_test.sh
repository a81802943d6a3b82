#!/usr/bin/env bash
# `facet bench --reference` (the equal-error mode) on a scene at tiny settings: renders a
# reference, runs the bench against it and checks the output's format and sense: one row per
# round (spp doubling, CPU-s, RMSE, efficiency), an error that falls with the sample count, and
# the time to a target RMSE; and the rmse= of the --machine line.
#   equal_error_test.sh <facet> <scene.xml> <work dir> [-D key=value]...
set -euo pipefail
facet=$1 scene=$2 work=$3
shift 3
mkdir -p "$work"
ref=$work/reference.exr
"$facet" render "$scene" "$@" --spp 256 -q -t 2 -o "$ref"
out=$("$facet" bench "$scene" "$@" --spp 1 --rounds 4 -t 1 --reference "$ref" --target-rmse 1e-3)
printf '%s\n' "$out"
fail() { echo "FAIL: $*" >&2; exit 1; }

grep -q "^equal error : RMSE against $ref (R, G, B)$" <<<"$out" || fail "no equal-error header"
grep -Eq '^ +spp +CPU-s +RMSE +1/\(RMSE² s\)$' <<<"$out" || fail "no column header"
rows=$(grep -E '^ +[0-9]+ +[0-9]+\.[0-9]{3} +[0-9.e+-]+ +[0-9.e+-]+$' <<<"$out")
[ "$(wc -l <<<"$rows")" -eq 4 ] || fail "expected 4 rounds, got: $rows"
spps=$(awk '{print $1}' <<<"$rows" | tr '\n' ' ')
[ "$spps" = "1 2 4 8 " ] || fail "the sample counts do not double from 1: $spps"
# Against a 256-spp reference, 8 spp has about a third of the error of 1 spp; less than 3/4 of
# it holds with a wide margin on any seed.
awk 'NR==1{first=$3} END{if (!($3 < 0.75*first && $3 > 0)) exit 1}' <<<"$rows" ||
    fail "the RMSE does not fall with the sample count"
# Efficiency = 1 / (RMSE² · CPU-s), within the rounding of the printed CPU-s (3 decimals).
awk '{lo=1/($3*$3*($2+0.0005)); hi=($2>0.0005)?1/($3*$3*($2-0.0005)):1e300;
      if ($4 < 0.99*lo || $4 > 1.01*hi) exit 1}' <<<"$rows" ||
    fail "the efficiency column is not 1/(RMSE² · CPU-s)"
grep -Eq '^ +RMSE 0\.001 reached after [0-9.]+ CPU-s \((interpolated|extrapolated with RMSE ~ 1/sqrt\(time\))\)$' \
    <<<"$out" || fail "no time to the target RMSE"
# --machine gives the first round's RMSE (what `facet bench --suite --references` reads): the
# same render, the same error.
machine=$("$facet" bench "$scene" "$@" --spp 1 --rounds 1 -t 1 --reference "$ref" --machine |
    grep '^machine: ') || fail "no machine: line"
rmse=$(sed -nE 's/.* rmse=([0-9.e+-]+)( .*)?$/\1/p' <<<"$machine")
first=$(awk 'NR==1{print $3}' <<<"$rows")
awk -v a="$rmse" -v b="$first" 'BEGIN{exit !(a > 0 && a - b < 1e-5 * b && b - a < 1e-5 * b)}' ||
    fail "machine: rmse=$rmse, the first round's RMSE is $first"
echo "PASS"
