#!/usr/bin/python3
"""Rasterise the black rects of a stereorig target SVG, independently of the
C++ writer: parse the XML, fill each rect (class square, tag-cell or
scale-bar) at `px_per_mm` with 4x4 supersampling, blur slightly (sigma 0.7 px,
like optics) and write an 8-bit PNG. Pixel (i, j) covers page
[i, i+1] x [j, j+1] / px_per_mm, so its centre is at (i + 0.5) / px_per_mm mm.

usage: rasterize_svg_rects.py PX_PER_MM IN.svg OUT.png [IN2.svg OUT2.png ...]
"""
import sys
import xml.etree.ElementTree as ET

import cv2
import numpy as np


def rasterise(svg, out, ppm):
    root = ET.parse(svg).getroot()
    ns = '{http://www.w3.org/2000/svg}'
    vb = [float(v) for v in root.get('viewBox').split()]
    ss = 4
    w, h = int(round(vb[2] * ppm)), int(round(vb[3] * ppm))
    img = np.full((h * ss, w * ss), 220, np.float32)
    for rect in root.iter(ns + 'rect'):
        if rect.get('class') not in ('square', 'tag-cell', 'scale-bar'):
            continue
        x, y, rw, rh = (float(rect.get(k)) for k in ('x', 'y', 'width', 'height'))
        x0, y0 = int(round(x * ppm * ss)), int(round(y * ppm * ss))
        x1, y1 = int(round((x + rw) * ppm * ss)), int(round((y + rh) * ppm * ss))
        img[y0:y1, x0:x1] = 30
    img = cv2.resize(img, (w, h), interpolation=cv2.INTER_AREA)  # the mean of each 4x4 block
    img = cv2.GaussianBlur(img, (0, 0), 0.7)
    cv2.imwrite(out, np.clip(np.round(img), 0, 255).astype(np.uint8))


ppm = float(sys.argv[1])
for i in range(2, len(sys.argv) - 1, 2):
    rasterise(sys.argv[i], sys.argv[i + 1], ppm)
