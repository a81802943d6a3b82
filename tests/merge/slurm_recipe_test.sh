#!/usr/bin/env bash
# Runs the Slurm job-array script of README.md ("A Slurm job array") for every task id in a
# loop, as the array would, merges the parts as the merge job would and checks the result is
# bit-identical to the render it replaces.
# Usage: slurm_recipe_test.sh <facet> <README.md> <scene.xml> <work dir>
set -euo pipefail
FACET=$1 README=$2 SCENE=$3 WORK=$4
rm -rf "$WORK" && mkdir -p "$WORK" && cd "$WORK"
# The fenced block after the slurm-recipe marker.
awk '/<!-- slurm-recipe/ { found = 1; next } found && /^```/ { if (inside) exit; inside = 1; next } inside' \
    "$README" > facet-parts.sbatch
grep -q '^#SBATCH' facet-parts.sbatch || { echo "FAIL: no job script found in $README"; exit 1; }
same() { idiff -q -fail 0 -failpercent 0 -warn 0 "$1" "$2" >/dev/null || { echo "FAIL: $1 and $2 differ"; idiff -fail 0 -warn 0 "$1" "$2" || true; exit 1; }; }
D=(-D res=40 -D spp=4 -D max_depth=3)

run_array() { # tasks, then the environment of the array
    local n=$1; shift
    for ((task = 0; task < n; ++task)); do
        env "$@" SLURM_ARRAY_TASK_ID=$task SLURM_CPUS_PER_TASK=2 SCENE="$SCENE" WIDTH=40 HEIGHT=40 \
            FACET="$FACET" bash facet-parts.sbatch "${D[@]}"
    done
}

# 3 x 2 windows, one pass: the merge is the single render.
run_array 6 TILES_X=3 TILES_Y=2 PASSES=1 OUT=parts1
"$FACET" merge parts1/part-*.exr -o merged1.exr
"$FACET" render "$SCENE" "${D[@]}" -q -o single.exr
same single.exr merged1.exr

# 2 x 2 windows, 2 passes: the merge is the two whole-film passes merged.
run_array 8 TILES_X=2 TILES_Y=2 PASSES=2 OUT=parts2
"$FACET" merge parts2/part-*.exr -o merged2.exr
"$FACET" render "$SCENE" "${D[@]}" -q --pass 0 --passes 2 -o pass0.exr
"$FACET" render "$SCENE" "${D[@]}" -q --pass 1 --passes 2 -o pass1.exr
"$FACET" merge pass0.exr pass1.exr -o passes.exr
same passes.exr merged2.exr
# ... which is the render of the two passes in one process.
"$FACET" render "$SCENE" "${D[@]}" -q --passes 2 -o single_passes.exr
same single_passes.exr merged2.exr

# A task id past the parts fails.
if env TILES_X=2 TILES_Y=2 PASSES=2 OUT=parts2 SLURM_ARRAY_TASK_ID=8 SCENE="$SCENE" WIDTH=40 \
    HEIGHT=40 FACET="$FACET" bash facet-parts.sbatch "${D[@]}" 2>/dev/null; then
    echo "FAIL: task 8 of 8 succeeded"; exit 1
fi
echo "slurm recipe: all checks passed"
