#!/bin/bash
# kapaint's ASTC 4x4 encoding (astcenc) beside ISPC's own ASTC encoder, one core each, on the
# same images, in one run; both decoded by texture2ddecoder for the PSNR.
# Usage: benches/peers/astc_side_by_side.sh PYTHON_WITH_ISPC_TEXCOMP [SIDE]
# (PYTHON_WITH_ISPC_TEXCOMP: a python with `pip install ispc_texcomp texture2ddecoder numpy`; not
# part of kapaint.)
set -euo pipefail
py=$1
side=${2:-2048}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$root"
cargo build --release --quiet --example astc_speed
RAYON_NUM_THREADS=1 target/release/examples/astc_speed "$tmp" "$side" | tee "$tmp/kapaint.txt"
"$py" "$here/astc_ispc.py" "$tmp"
