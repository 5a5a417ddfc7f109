#!/bin/bash
# kapaint's AO bake beside Embree's occlusion rays, on the same meshes and ray counts, one run.
# Usage: benches/peers/ao_side_by_side.sh PYTHON_WITH_EMBREEX [KAPAINT]
# (PYTHON_WITH_EMBREEX: a python with `pip install embreex numpy`; not part of kapaint.)
set -euo pipefail
py=$1
k=${2:-target/release/kapaint}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for mesh in "$root/tests/data/meshes/teapot.obj" "$root/../shared/testdata/spot/spot_triangulated.obj"; do
  name=$(basename "$mesh" .obj)
  unwrap=()
  if ! grep -q '^vt ' "$mesh"; then unwrap=(--unwrap); fi
  "$k" new --size 2048 --mesh "$mesh" "${unwrap[@]}" --out "$tmp/$name.kapaint" > /dev/null
  "$k" new --size 512 --mesh "$mesh" "${unwrap[@]}" --out "$tmp/${name}_512.kapaint" > /dev/null
  echo "== $name, 2048^2, 64 rays, every core"
  "$k" bake "$tmp/$name.kapaint" --map ao --rays 64 --out "$tmp/$name.png" | head -1
  echo "== $name, 512^2, 64 rays, one thread, then Embree with as many rays"
  line=$(RAYON_NUM_THREADS=1 "$k" bake "$tmp/${name}_512.kapaint" --map ao --rays 64 --out "$tmp/${name}_512.png" | head -1)
  echo "$line"
  rays=$(echo "$line" | sed -E 's/.* ([0-9]+) rays \(.*/\1/')
  "$py" "$here/ao_embree.py" "$mesh" "$rays" 64
done
