#!/usr/bin/env bash
# Compares the static-model subdivision methods (issue 8) on one scene in the format of
# Tables 2-4 of "Scene subdivision for occlusion culling": for each method, `dyncull bench
# SCENE --subdivide METHOD` runs vfc, full and front10 interleaved over the same frames,
# and the table lists nodes, leaves, times, % of geometry drawn and frame rates.
# Usage: scripts/subdivision_tables.sh SCENE MAX_TRIS FRAMES SIZE OUTDIR [extra bench options...]
set -euo pipefail
scene=$1 maxTris=$2 frames=$3 size=$4 out=$5
shift 5
dyncull=${DYNCULL:-build/bin/dyncull}
methods="phbvo dbvs octree grid"
mkdir -p "$out"
for m in $methods; do
  "$dyncull" bench "$scene" --subdivide "$m" --max-tris "$maxTris" --modes vfc,full,front10 --frames "$frames" \
    --size "$size" --quiet --out "$out/$m" "$@" > "$out/$m.log"
done
# col FILE MODE COLUMN: one value of summary.csv by mode and column name.
col() { awk -F, -v mode="$2" -v name="$3" 'NR==1{for(i=1;i<=NF;i++) c[$i]=i; next} $1==mode{print $c[name]}' "$1"; }
kv() { grep -o "$2=[0-9.]*" "$1" | head -1 | cut -d= -f2; }
{
  echo "| $scene, at most $maxTris triangles per leaf, $frames frames, $size | $(echo $methods | sed 's/ / | /g') |"
  echo "|---|$(for m in $methods; do printf -- '---|'; done)"
  row() { printf '| %s |' "$1"; for m in $methods; do printf ' %s |' "$("$2" "$m")"; done; echo; }
  s() { echo "$out/$1/summary.csv"; }
  tris() { kv "$out/$1.log" triangles; }
  inner() { kv "$out/$1.log" inner; }
  leaves() { kv "$out/$1.log" leaves; }
  build() { kv "$out/$1.log" build_ms | awk '{printf "%.0f", $1}'; }
  vfcT() { col "$(s "$1")" vfc ms_traversal | awk '{printf "%.2f", $1}'; }
  occT() { paste <(col "$(s "$1")" full ms_traversal) <(col "$(s "$1")" full ms_query) <(col "$(s "$1")" full ms_wait) | awk '{printf "%.2f", $1+$2+$3}'; }
  renT() { paste <(col "$(s "$1")" full ms_mean) <(col "$(s "$1")" full ms_traversal) <(col "$(s "$1")" full ms_query) <(col "$(s "$1")" full ms_wait) | awk '{printf "%.2f", $1-$2-$3-$4}'; }
  rate() { paste <(col "$(s "$1")" "$2" triangles) <(tris "$1") | awk '{printf "%.1f", 100*$1/$2}'; }
  fps() { col "$(s "$1")" "$2" ms_mean | awk '{printf "%.1f", 1000/$1}'; }
  rateFull() { rate "$1" full; }
  rateVfc() { rate "$1" vfc; }
  fpsFull() { fps "$1" full; }
  fpsVfc() { fps "$1" vfc; }
  fpsFront() { fps "$1" front10; }
  rateFront() { rate "$1" front10; }
  fnFront() { col "$(s "$1")" front10 false_negatives; }
  row "#Subdiv (inner) nodes" inner
  row "#Leaf nodes (objects)" leaves
  row "Subdivision time [ms]" build
  row "Time for vfc [ms] (vfc mode, traversal)" vfcT
  row "Time for occ [ms] (full: traversal+queries+waits)" occT
  row "Time for ren [ms] (full: rest of the frame)" renT
  row "Render rate [%] (full)" rateFull
  row "Frame rate [fps] (full)" fpsFull
  row "Render rate of vfc only [%]" rateVfc
  row "Frame rate of vfc only [fps]" fpsVfc
  row "Render rate, front 10% untested [%]" rateFront
  row "Frame rate, front 10% untested [fps]" fpsFront
  row "Missed visible parts, front 10% (sum)" fnFront
} | tee "$out/table.md"
best=$(for m in $methods; do echo "$(col "$out/$m/summary.csv" full ms_mean) $m"; done | sort -g | head -1 | cut -d' ' -f2)
echo "best (highest full frame rate): $best" | tee -a "$out/table.md"
