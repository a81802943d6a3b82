#!/usr/bin/env bash
# `facet bench`'s measure of Embree's own work: the queries of a second render, recorded and
# sent to Embree again. Checks that every replayed query got the answer it got in the render
# (the replay traces the render's rays, not others), that at least as many rays were replayed as
# the render traced, and that the share and facet's remainder are printed, also as the --machine
# line's key=value pairs.
#   embree_share_test.sh <facet> <scene.xml> [-D key=value]...
set -euo pipefail
facet=$1 scene=$2
shift 2
out=$("$facet" bench "$scene" "$@" --spp 4 -t 2 --machine)
printf '%s\n' "$out"
fail() { echo "FAIL: $*" >&2; exit 1; }

rays=$(sed -nE 's/^ +([0-9.]+) Mrays \(ray_intersect \+ ray_test calls.*/\1/p' <<<"$out")
[ -n "$rays" ] || fail "no ray count"
line=$(grep -E '^embree alone: [0-9.]+ Mrays from a [0-9]+-spp render sent again to Embree (once|[0-9]+ times), on one thread with nothing around them: [0-9.]+ Mrays in [0-9.]+ CPU-s = [0-9.]+ CPU-ns per ray \(every answer as in the render\)$' <<<"$out") ||
    fail "no replay line, or answers that differ from the render's"
replayed=$(sed -nE 's/.*: ([0-9.]+) Mrays in .*/\1/p' <<<"$line")
awk -v a="$replayed" -v b="$rays" 'BEGIN { exit !(a >= b && b > 0) }' ||
    fail "replayed $replayed Mrays, fewer than the render's $rays"
grep -Eq "^share       : Embree's own work is [0-9]+\.[0-9]% of the render's CPU time \($rays Mrays at [0-9.]+ CPU-ns\); the rest, [0-9.]+ CPU-ns per sample, is facet's$" \
    <<<"$out" || fail "no share line"
grep -Eq '^machine: spp=4 threads=[0-9]+ samples=[0-9]+ rays=[0-9]+ cpu_seconds=[0-9.]+ cpu_ns_per_sample=[0-9.]+ rays_per_sample=[0-9.]+ embree_share=[0-9.]+ rmse=-$' \
    <<<"$out" || fail "no machine: line"
echo "PASS"
