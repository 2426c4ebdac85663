#!/usr/bin/env bash
# Render SCENE on a Slurm cluster as SHARDS array tasks, then merge them.
#   SCENE=scene.glb OUT=/shared/render SHARDS=16 SPP=1024 ./slurm-submit.sh
set -euo pipefail
: "${SCENE:?set SCENE to the scene file}" "${OUT:?set OUT to a shared folder}"
export SCENE OUT SHARDS="${SHARDS:-4}"
here="$(cd "$(dirname "$0")" && pwd)"
render=$(sbatch --parsable --array="0-$((SHARDS - 1))" --export=ALL "$here/slurm-render.sbatch")
sbatch --dependency="afterok:${render%%;*}" --export=ALL "$here/slurm-merge.sbatch"
