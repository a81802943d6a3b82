#!/usr/bin/env bash
# `facet merge`: crop splits merge to the single render's pixels exactly; passes merge to the
# pixels of the render of all the passes in one process (`--passes N` alone) whatever the crop
# split; overlapping, missing and mismatched parts are refused with
# an error that names them.
# Usage: merge_test.sh <facet> <scene.xml> <work dir>
set -euo pipefail
FACET=$1 SCENE=$2 WORK=$3
rm -rf "$WORK" && mkdir -p "$WORK" && cd "$WORK"
D=(-D res=40 -D spp=4 -D max_depth=3)
render() { "$FACET" render "$SCENE" "${D[@]}" -q -t 2 "$@"; }
# Pixel-exact comparison: no channel of any pixel may differ (and the sizes must agree).
same() { idiff -q -fail 0 -failpercent 0 -warn 0 "$1" "$2" >/dev/null || { echo "FAIL: $1 and $2 differ"; idiff -fail 0 -warn 0 "$1" "$2" || true; exit 1; }; }
# A command that must fail with a message matching $1.
refuses() {
    local pattern=$1; shift
    if out=$("$@" 2>&1); then echo "FAIL: '$*' succeeded, expected an error matching '$pattern'"; exit 1; fi
    if ! grep -Eq -- "$pattern" <<<"$out"; then echo "FAIL: '$*' said '$out', expected '$pattern'"; exit 1; fi
    echo "refused as expected: $out"
}

render -o full.exr
# A 2x2 split with uneven tiles, and a 3x1 split.
render --crop 0 0 17 23 -o a.exr
render --crop 17 0 40 23 -o b.exr
render --crop 0 23 17 40 -o c.exr
render --crop 17 23 40 40 -o d.exr
"$FACET" merge d.exr b.exr a.exr c.exr -o merged4.exr
same full.exr merged4.exr
render --crop 0 0 40 11 -o r0.exr
render --crop 0 11 40 30 -o r1.exr
render --crop 0 30 40 40 -o r2.exr
"$FACET" merge r0.exr r1.exr r2.exr -o merged3.exr
same full.exr merged3.exr

# Two passes: tiles of each pass merge to the pixels of the two whole-film passes merged.
render --pass 0 --passes 2 -o p0.exr
render --pass 1 --passes 2 -o p1.exr
"$FACET" merge p0.exr p1.exr -o passes.exr
render --pass 0 --passes 2 --crop 0 0 40 20 -o p0top.exr
render --pass 0 --passes 2 --crop 0 20 40 40 -o p0bottom.exr
render --pass 1 --passes 2 --crop 0 0 23 40 -o p1left.exr
render --pass 1 --passes 2 --crop 23 0 40 40 -o p1right.exr
"$FACET" merge p0top.exr p1right.exr p0bottom.exr p1left.exr -o passes_tiled.exr
same passes.exr passes_tiled.exr
# Both are bit-identical to the two passes rendered one after the other in one process (the
# default gaussian filter reaches across every crop edge: the parts merge by their raw sums).
render --passes 2 -o passes_single.exr
same passes_single.exr passes.exr
same passes_single.exr passes_tiled.exr
oiiotool --info -v p0.exr | grep -q 'facet.weight' || { echo "FAIL: a pass has no facet.weight channel"; oiiotool --info -v p0.exr; exit 1; }
# ... and carry the total sample count.
oiiotool --info -v passes.exr | grep -q 'facet:spp: "8"' || { echo "FAIL: merged passes do not say facet:spp 8"; oiiotool --info -v passes.exr; exit 1; }

# Refusals.
render --crop 0 0 20 40 -o left.exr
render --crop 15 0 40 40 -o right_wide.exr
refuses 'left\.exr .*right_wide\.exr .*overlap.*\[15, 20\)' "$FACET" merge left.exr right_wide.exr -o x.exr
refuses 'a\.exr is given twice' "$FACET" merge a.exr b.exr c.exr d.exr a.exr -o x.exr
refuses 'uncovered.*\[17, 40\) x \[23, 40\).*missing' "$FACET" merge a.exr b.exr c.exr -o x.exr
refuses 'pass 1 of 2 is missing' "$FACET" merge p0top.exr p0bottom.exr -o x.exr
refuses 'pass 1 \(of 2\) leave 680 .*uncovered.*\[23, 40\) x \[0, 40\)' "$FACET" merge p0.exr p1left.exr -o x.exr
"$FACET" render "$SCENE" -D res=48 -D spp=4 -D max_depth=3 -q --crop 17 0 48 23 -o other_size.exr
refuses 'other_size\.exr .*48x48.*40x40.*different' "$FACET" merge a.exr other_size.exr -o x.exr
"$FACET" render "$SCENE" -D res=40 -D spp=4 -D max_depth=4 -q --crop 17 0 40 23 -o other_scene.exr
refuses 'other_scene\.exr .*scene_hash.*different scenes' "$FACET" merge a.exr other_scene.exr c.exr d.exr -o x.exr
render --seed 7 --crop 17 0 40 23 -o other_seed.exr
refuses 'other_seed\.exr .*seed.*different seeds' "$FACET" merge a.exr other_seed.exr c.exr d.exr -o x.exr
refuses 'pass.*p0\.exr|p0\.exr.*pass' "$FACET" merge p0.exr full.exr -o x.exr
refuses 'no such file' "$FACET" merge a.exr missing.exr -o x.exr
[ ! -e x.exr ] || { echo "FAIL: a refused merge wrote x.exr"; exit 1; }
echo "merge: all checks passed"
