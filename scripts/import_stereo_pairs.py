#!/usr/bin/python3
"""Turn a folder of plain-chessboard left/right image pairs from another tool
(OpenCV's samples, Kalibr, MATLAB, ...) into a stereorig calibration dataset
(docs/formats.md, "Datasets"; docs/targets.md, "Plain boards"):

  OUT/calibration/NNN/cam0.png   left image of pair NNN, 8-bit grey
  OUT/calibration/NNN/cam1.png   right image of pair NNN
  OUT/layout.yaml                one module: {name: module0, left: 0, right: 1}
  OUT/target.yaml                the plain board (with --corners and --square-mm)

Pairs are matched by the first number in each file name (left07.jpg with
right07.jpg, or L_0007.png with R_0007.png); without numbers, by sorted order.
Nothing is resampled: images are only converted to 8-bit grey.

usage:
  import_stereo_pairs.py --left 'pairs/left*.jpg' --right 'pairs/right*.jpg' \\
      --corners 9x6 --square-mm 25 --out dataset/
"""
import argparse
import glob
import os
import re
import sys

import cv2


def number(path):
    m = re.search(r'(\d+)', os.path.basename(path))
    return int(m.group(1)) if m else None


def pairs(left, right):
    lnum, rnum = {number(p): p for p in left}, {number(p): p for p in right}
    if None not in lnum and None not in rnum and len(lnum) == len(left) and len(rnum) == len(right):
        common = sorted(set(lnum) & set(rnum))
        unmatched = (set(lnum) | set(rnum)) - set(common)
        if unmatched:
            print(f'warning: {len(unmatched)} image(s) without a partner skipped', file=sys.stderr)
        return [(lnum[k], rnum[k]) for k in common]
    if len(left) != len(right):
        sys.exit(f'error: {len(left)} left and {len(right)} right images, and no numbers in their names to pair them')
    return list(zip(sorted(left), sorted(right)))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--left', required=True, help="glob of the left camera's images (quote it)")
    ap.add_argument('--right', required=True, help="glob of the right camera's images (quote it)")
    ap.add_argument('--out', required=True, help='dataset folder to create (must not exist)')
    ap.add_argument('--corners', help='inner corners of the plain board, COLSxROWS, e.g. 9x6')
    ap.add_argument('--square-mm', type=float, help='measured square size of the printed board, mm')
    args = ap.parse_args()

    left, right = sorted(glob.glob(args.left)), sorted(glob.glob(args.right))
    if not left or not right:
        sys.exit(f'error: no images match {args.left if not left else args.right}')
    if os.path.exists(args.out):
        sys.exit(f'error: {args.out} exists; choose a new folder')
    if (args.corners is None) != (args.square_mm is None):
        sys.exit('error: give --corners and --square-mm together (or neither, and write target.yaml yourself)')
    todo = pairs(left, right)
    size = {}
    for i, (lp, rp) in enumerate(todo):
        d = os.path.join(args.out, 'calibration', f'{i:03d}')
        os.makedirs(d)
        for cam, p in ((0, lp), (1, rp)):
            img = cv2.imread(p, cv2.IMREAD_GRAYSCALE)
            if img is None:
                sys.exit(f'error: {p}: cannot read the image')
            if size.setdefault(cam, img.shape) != img.shape:
                sys.exit(f'error: {p}: {img.shape[1]}x{img.shape[0]}, but camera {cam} images are '
                         f'{size[cam][1]}x{size[cam][0]}')
            cv2.imwrite(os.path.join(d, f'cam{cam}.png'), img)
    with open(os.path.join(args.out, 'layout.yaml'), 'w') as f:
        f.write('# stereorig layout: which cameras form each stereo module (global camera indices).\n'
                'modules:\n  - {name: module0, left: 0, right: 1}\n')
    if args.corners:
        m = re.fullmatch(r'(\d+)x(\d+)', args.corners)
        if not m:
            sys.exit('error: --corners must look like 9x6')
        with open(os.path.join(args.out, 'target.yaml'), 'w') as f:
            f.write('# stereorig target file (docs/targets.md): a plain one-sided chessboard.\n'
                    'format: stereorig-target\nversion: 1\nunits: mm\n'
                    f'corners_x: {m.group(1)}\ncorners_y: {m.group(2)}\n'
                    f'square_size_mm: {args.square_mm:g}\ndouble_sided: false\n')
    print(f'wrote {len(todo)} pair(s) to {args.out}/calibration/, layout.yaml'
          + (', target.yaml' if args.corners else ''))


if __name__ == '__main__':
    main()
