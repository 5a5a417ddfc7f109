"""ISPC's own ASTC encoder beside kapaint's (ARM's astcenc), on the same images, one thread.

Not part of kapaint: a peer measurement (pip install ispc_texcomp texture2ddecoder numpy). It reads
the raw RGBA8 images and kapaint's ASTC 4x4 blocks that `examples/astc_speed.rs` wrote into
DIR, encodes each image with ISPC's own ASTC profiles (4x4, timed alone), decodes
both encoders' blocks with texture2ddecoder (an independent decoder: neither encoder's own),
and prints per encoding its time, megatexels per second and PSNR over RGBA. Then, for each
ISPC profile, the fastest kapaint effort at the same quality or better (PSNR no lower) and
how its speed compares, and kapaint's time at exactly ISPC's PSNR, interpolated (log time
against PSNR) between the two efforts around it.

    python astc_ispc.py DIR
"""

import math
import os
import sys
import time

import ispc_texcomp as ispc
import numpy as np
import texture2ddecoder

EFFORTS = ["fastest", "fast", "medium", "thorough", "very-thorough"]
# ISPC's own profiles (ASTCEncSettings.from_profile): `fast` encodes RGB only (three
# channels, alpha dropped), `alpha_fast` and `alpha_slow` all four.
ISPC_PROFILES = ["fast", "alpha_fast", "alpha_slow"]


def psnr(rgba, blocks, w, h):
    bgra = np.frombuffer(texture2ddecoder.decode_astc(blocks, w, h, 4, 4), np.uint8)
    got = bgra.reshape(-1, 4)[:, [2, 1, 0, 3]].astype(np.float64)
    want = np.frombuffer(rgba, np.uint8).reshape(-1, 4).astype(np.float64)
    mse = float(np.mean((got - want) ** 2))
    return float("inf") if mse == 0 else 10 * math.log10(255 * 255 / mse)


def main():
    d = sys.argv[1]
    names = sorted(f[:-5] for f in os.listdir(d) if f.endswith(".rgba"))
    for name in names:
        rgba = open(os.path.join(d, name + ".rgba"), "rb").read()
        w, h = (int(x) for x in open(os.path.join(d, name + ".size")).read().split())
        mtex = w * h / 1e6
        print(f"== {name} {w}x{h}, ASTC 4x4, one thread, PSNR by texture2ddecoder")
        ours = {}
        for effort in EFFORTS:
            path = os.path.join(d, f"{name}_{effort}.astc")
            line = [l for l in open(os.path.join(d, "kapaint.txt")) if f" {name} " in l and f" {effort}:" in l]
            seconds = float(line[0].split(": ")[1].split(" s")[0])
            ours[effort] = (seconds, psnr(rgba, open(path, "rb").read(), w, h))
            s, p = ours[effort]
            print(f"kapaint astcenc {effort:13s} {s:7.3f} s {mtex / s:7.2f} Mtexel/s  {p:.2f} dB")
        theirs = {}
        surface = ispc.RGBASurface(rgba, w, h, w * 4)
        for profile in ISPC_PROFILES:
            settings = ispc.ASTCEncSettings.from_profile(profile, 4, 4)
            start = time.perf_counter()
            blocks = ispc.compress_blocks_astc(surface, settings)
            s = time.perf_counter() - start
            theirs[profile] = (s, psnr(rgba, blocks, w, h))
            print(f"ISPC astc       {profile:13s} {s:7.3f} s {mtex / s:7.2f} Mtexel/s  {theirs[profile][1]:.2f} dB")
        for profile, (s, p) in theirs.items():
            match = [(e, v) for e, v in ours.items() if v[1] >= p - 0.005]
            if not match:
                print(f"  ISPC {profile} ({p:.2f} dB): no kapaint effort as close")
                continue
            e, (os_, op) = min(match, key=lambda m: m[1][0])
            line = (f"  ISPC {profile} ({p:.2f} dB, {s:.3f} s): kapaint {e} ({op:.2f} dB, "
                    f"{os_:.3f} s), {s / os_:.2f}x ISPC's speed")
            curve = sorted(ours.values(), key=lambda v: v[1])
            for (t0, p0), (t1, p1) in zip(curve, curve[1:]):
                if p0 <= p <= p1 and p1 > p0:
                    f = (p - p0) / (p1 - p0)
                    t = math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
                    line += f"; at {p:.2f} dB exactly, {t:.3f} s, {s / t:.2f}x"
                    break
            print(line)

if __name__ == "__main__":
    main()
