#!/usr/bin/python3
"""Realism figures of a simulated dataset (docs/simulator.md).

Usage: sim_realism.py DATASET CLEAN_DATASET
  DATASET        stereorig simulate --out DATASET --seed S
  CLEAN_DATASET  the same spec and seed with render.noise: false (scenes only is enough):
                 the same poses, so DATASET - CLEAN is exactly the sensor noise.
Prints: sensor noise (DN) by signal level, laser-line contrast, fraction of
object pixels lit by the grid, active/passive levels, per scene and camera.
"""
import glob
import os
import sys

import cv2
import numpy as np


def read(p):
    im = cv2.imread(p, cv2.IMREAD_UNCHANGED)
    if im is None:
        sys.exit("cannot read " + p)
    return im.astype(np.float64)


def main():
    ds, clean = sys.argv[1], sys.argv[2]
    scenes = sorted(os.listdir(os.path.join(ds, "scenes")))
    noise_bins = {}
    print("scene   cam  object_px  lit_frac  line_contrast  line_p2v_DN  passive_DN  active_DN")
    for s in scenes:
        for p in sorted(glob.glob(os.path.join(ds, "scenes", s, "passive", "cam*.png"))):
            cam = os.path.basename(p)
            ids = read(os.path.join(ds, "truth", "scenes", s, "id_" + cam))
            obj = ids > 0
            # Interior object pixels: the noise figure must not see edges.
            interior = cv2.erode(obj.astype(np.uint8), np.ones((7, 7), np.uint8)) > 0
            noisy_p = read(p)
            clean_p = read(os.path.join(clean, "scenes", s, "passive", cam))
            clean_a = read(os.path.join(clean, "scenes", s, "active", cam))
            noisy_a = read(os.path.join(ds, "scenes", s, "active", cam))
            diff = noisy_p - clean_p
            for name, mask in (("background", ids == 0), ("object", interior)):
                sel = mask & (clean_p > 0) & (clean_p < 255)
                if sel.sum() > 1000:
                    noise_bins.setdefault(name, []).append((diff[sel].std(), clean_p[sel].mean()))
            laser = clean_a - clean_p  # laser light (with speckle), noise free
            lit = interior & (laser > 10)
            frac = lit.sum() / max(1, interior.sum())
            # Line contrast: Michelson contrast of the noise-free active image
            # in 9x9 windows (one grid period is ~8 px), on lit object pixels.
            k = np.ones((9, 9), np.uint8)
            hi = cv2.dilate(clean_a.astype(np.float32), k)
            lo = cv2.erode(clean_a.astype(np.float32), k)
            win = cv2.erode(interior.astype(np.uint8), k) > 0
            sel = win & lit
            contrast = np.median(((hi - lo) / np.maximum(1, hi + lo))[sel]) if sel.sum() else float("nan")
            p2v = np.median((hi - lo)[sel]) if sel.sum() else float("nan")
            print("%-7s %-5s %9d  %8.3f  %13.3f  %11.1f  %10.1f  %9.1f" %
                  (s, cam[:-4], interior.sum(), frac, contrast, p2v, noisy_p[interior].mean(), noisy_a[interior].mean()))
    for name, v in noise_bins.items():
        v = np.array(v)
        print("sensor noise on %s pixels (mean level %.1f DN): %.2f DN RMS" % (name, v[:, 1].mean(), v[:, 0].mean()))


if __name__ == "__main__":
    main()
