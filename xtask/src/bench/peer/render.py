"""Mitsuba 3 driver of `cargo xtask bench peer` (xtask writes this file into its cache folder and
runs it with the Python of the peer's virtual environment; see scripts/setup-peer.sh).

usage: render.py SCENE.xml OUT.f32 spp N PASS_SPP   render N samples per pixel
       render.py SCENE.xml OUT.f32 time T PASS_SPP  render as many samples as fit T seconds

Renders in passes of PASS_SPP samples per pixel (seeds 1, 2, ...) after one discarded warm-up pass
(seed 0) that JIT-compiles the kernels, so compilation is not in the timed figure. With `time`, a
second discarded pass measures the time per sample and the pass size becomes the power of two (at
most 64) that gives about 16 passes in T (its kernels compiled by one more discarded pass); then timed
passes follow while the next one is expected to end less than half a pass past T (at least one). Writes the mean of the passes as little-endian f32 RGB, rows top to bottom, and
prints one line `radcache-peer spp=.. time_s=.. warmup_s=.. passes=.. width=.. height=..`
(warmup_s: the discarded passes)
(time_s: the timed passes).
"""
import sys
import time

import drjit as dr
import mitsuba as mi
import numpy as np

mi.set_variant("llvm_ad_rgb")


def main():
    xml, out, mode, value, pass_spp = sys.argv[1:6]
    value, pass_spp = float(value), int(pass_spp)
    if mode not in ("spp", "time") or pass_spp < 1 or value <= 0:
        sys.exit(f"render.py: bad arguments {sys.argv[1:]}")
    scene = mi.load_file(xml)

    current = {"spp": pass_spp}

    def one_pass(seed):
        t0 = time.perf_counter()
        img = mi.render(scene, spp=current["spp"], seed=seed)
        arr = np.array(img, dtype=np.float64)
        dr.sync_thread()
        return arr, time.perf_counter() - t0

    warm, warmup_s = one_pass(0)
    if mode == "time":
        # Passes of about T / 16 (a power of two, at most 64 spp): fewer passes cost less overhead.
        _, calib = one_pass(0)
        warmup_s += calib
        per_spp = calib / pass_spp
        k = 1
        while k < 64 and 2 * k * per_spp * 16 <= value:
            k *= 2
        if k != pass_spp:
            current["spp"] = k
            _, more = one_pass(0)
            warmup_s += more
        pass_spp = k
    passes = []
    acc = np.zeros_like(warm)
    count = max(1, int(round(value / pass_spp)))
    seed = 1
    while True:
        arr, secs = one_pass(seed)
        acc += arr
        passes.append(secs)
        seed += 1
        if mode == "spp" and len(passes) >= count:
            break
        # Time: one more pass while it is expected to end less than half a pass past T.
        if mode == "time" and sum(passes) + 0.5 * sum(passes) / len(passes) > value:
            break
    mean = (acc / len(passes))[:, :, :3].astype("<f4")
    mean.tofile(out)
    print(f"radcache-peer spp={len(passes) * pass_spp} time_s={sum(passes):.6f} "
          f"warmup_s={warmup_s:.6f} passes={len(passes)} width={mean.shape[1]} height={mean.shape[0]}")

if __name__ == "__main__":
    main()
