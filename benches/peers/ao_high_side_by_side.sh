#!/bin/bash
# AO baked from the issue-57 sculpt onto spot beside Embree's occlusion rays on the sculpt, one
# thread each, the same rays per point, in one run.
# Usage: benches/peers/ao_high_side_by_side.sh PYTHON_WITH_EMBREEX [KAPAINT] [SIZE]
# Then, where `cargo build --release --example ao_rays` has been run, kapaint's rays alone on
# the sculpt (points picked as Embree's are, only the occlusion queries timed), beside Embree
# again.
# (PYTHON_WITH_EMBREEX: a python with `pip install embreex numpy`; not part of kapaint.)
# The sculpt is made by the mesh bench's generator (spot welded, split four times and
# displaced along its normals, ~1.5M triangles), written as an OBJ, never committed.
set -euo pipefail
py=$1
k=${2:-target/release/kapaint}
size=${3:-512}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
spot="$root/../shared/testdata/spot/spot_triangulated.obj"
(cd "$root" && KAPAINT_WRITE_SCULPT="$tmp/sculpt.obj" cargo bench --bench mesh -- bake_from_high_1_5m 2>&1 | grep '^wrote')
"$k" new --size "$size" --mesh "$spot" --out "$tmp/spot.kapaint" > /dev/null
echo "== kapaint: AO from the sculpt onto spot, ${size}^2, 64 rays, one thread"
line=$(RAYON_NUM_THREADS=1 "$k" bake "$tmp/spot.kapaint" --map ao --high "$tmp/sculpt.obj" --rays 64 --out "$tmp/ao.png" | head -1)
echo "$line"
rays=$(echo "$line" | sed -E 's/.* ([0-9]+) rays \(.*/\1/')
echo "== Embree on the sculpt, as many rays, 64 a point, one thread"
"$py" "$here/ao_embree.py" "$tmp/sculpt.obj" "$rays" 64
ao_rays="$root/target/release/examples/ao_rays"
if [ -x "$ao_rays" ]; then
    echo "== kapaint's rays alone on the sculpt (examples/ao_rays), as many rays, one thread"
    "$ao_rays" "$tmp/sculpt.obj" $((rays / 64)) 1 2>/dev/null
    echo "== Embree again"
    "$py" "$here/ao_embree.py" "$tmp/sculpt.obj" $((rays / 64 * 64)) 64
    echo "== both again, the points in Morton order (near points one after another, as a bake's texels)"
    "$ao_rays" "$tmp/sculpt.obj" $((rays / 64)) 1 coherent 2>/dev/null
    "$py" "$here/ao_embree.py" "$tmp/sculpt.obj" $((rays / 64 * 64)) 64 coherent
fi
