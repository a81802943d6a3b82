#!/usr/bin/env bash
# `facet bench --suite`: a suite file of two scenes, a tiny Cornell box and a scene file that does
# not exist, written in the format of a suite (comments, blank lines, aligned columns). Checks
# that both rows are printed, the good one with its figures and a peak memory above 0, the
# failing one with its error, and that the command exits non-zero after running both; then the
# equal-error column of --references.
#   suite_test.sh <facet> <scenes folder> <work folder>
set -uo pipefail
facet=$1 scenes=$2 work=$3
mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }

cat >"$work/suite.txt" <<'SUITE'
# name | scene file | -D arguments
cbox    | cornell-box/scene.xml | -D res=16 -D max_depth=3 -D spp=4

missing | no-such/scene.xml     | -D spp=4
SUITE
out=$("$facet" bench --suite "$work/suite.txt" --root "$scenes" --runs 2 -t 2 2>&1)
rc=$?
printf '%s\n' "$out"
[ "$rc" -ne 0 ] || fail "exit code 0 with a failing scene"
grep -Eq '^scene +CPU-ns/sample +rays/sample +Embree % +peak MiB$' <<<"$out" || fail "no header"
row=$(grep -E '^cbox +[0-9.]+ +[0-9.]+ +([0-9.]+|-) +[0-9.]+$' <<<"$out") || fail "no cbox row"
mib=$(awk '{ print $NF }' <<<"$row")
awk -v m="$mib" 'BEGIN { exit !(m > 0) }' || fail "peak MiB $mib"
grep -Eq '^missing +error: .*no-such/scene\.xml.*does not exist' <<<"$out" ||
    fail "no error row for the missing scene"
grep -q '1 of 2 scenes failed' <<<"$out" || fail "no failure count"

# Without --root, scene paths are relative to the suite file's folder.
mkdir -p "$work/here"
cp -r "$scenes/cornell-box" "$work/here/"
printf 'cbox | cornell-box/scene.xml | -D res=8 -D max_depth=2 -D spp=1\n' >"$work/here/suite.txt"
out=$("$facet" bench --suite "$work/here/suite.txt" -t 1 2>&1) || fail "suite without --root: $out"
grep -Eq '^cbox +[0-9.]+ ' <<<"$out" || fail "no row without --root: $out"
# --references: the missing reference is rendered first and kept; the table gains the CPU-s to
# an RMSE of 0.01 against it; a second run reuses the reference.
printf 'cbox | cornell-box/scene.xml | -D res=16 -D max_depth=3 -D spp=4\n' >"$work/one.txt"
rm -rf "$work/refs"
out=$("$facet" bench --suite "$work/one.txt" --root "$scenes" --references "$work/refs" \
    --reference-spp 64 -t 2 2>&1) || fail "suite with --references: $out"
printf '%s\n' "$out"
grep -q "^reference cbox: rendering $work/refs/cbox.exr at 64 spp$" <<<"$out" ||
    fail "no reference rendered"
[ -s "$work/refs/cbox.exr" ] || fail "no reference file"
grep -Eq '^scene +CPU-ns/sample +rays/sample +Embree % +peak MiB +s to RMSE \.01$' <<<"$out" ||
    fail "no equal-error column"
row=$(grep -E '^cbox +[0-9.]+ +[0-9.]+ +([0-9.]+|-) +[0-9.]+ +[0-9.e+-]+$' <<<"$out") ||
    fail "no cbox row with an equal-error figure"
eq=$(awk '{ print $NF }' <<<"$row")
awk -v e="$eq" 'BEGIN { exit !(e > 0 && e < 1e9) }' || fail "equal-error figure $eq"
before=$(stat -c %Y "$work/refs/cbox.exr")
out=$("$facet" bench --suite "$work/one.txt" --root "$scenes" --references "$work/refs" -t 2 2>&1) ||
    fail "second suite with --references: $out"
grep -q '^reference ' <<<"$out" && fail "the reference was rendered again"
[ "$(stat -c %Y "$work/refs/cbox.exr")" = "$before" ] || fail "the reference changed"
grep -Eq '^cbox .* [0-9.e+-]+$' <<<"$out" || fail "no row on the second run"
# A scene whose reference cannot be rendered prints that error in its row; the others still run.
out=$("$facet" bench --suite "$work/suite.txt" --root "$scenes" --references "$work/refs" -t 2 2>&1)
rc=$?
printf '%s\n' "$out"
[ "$rc" -ne 0 ] || fail "exit code 0 with a scene whose reference failed"
grep -Eq '^missing +error: reference: .*no-such/scene\.xml.*does not exist' <<<"$out" ||
    fail "no reference error in the missing scene's row"
grep -Eq '^cbox .* [0-9.e+-]+$' <<<"$out" || fail "no cbox row next to the failed reference"
echo "PASS"
