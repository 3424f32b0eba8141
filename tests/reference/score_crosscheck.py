#!/usr/bin/python3
"""Recomputes `stereorig score`'s accuracy figures with scipy and numpy only.

usage: score_crosscheck.py SCORE_JSON DATASET CLOUD_DIR [TOLERANCE_MM]

SCORE_JSON: `stereorig score --report` of DATASET; CLOUD_DIR/<scene>.ply: the
clouds `stereorig reconstruct` writes for the same scenes, rig and options.
For each scene in the report: reads the cloud and the simulator's dense truth
(DATASET/truth/scenes/<scene>/surface.ply), aligns the cloud by its own
point-to-plane ICP from the identity, then takes each measured point's
distance to the plane through its 8 nearest truth samples (or, for a point
whose nearest sample is more than 1 mm away, that sample's distance), signed
by the cloud's normal (the definition in reconstruct/score.h; none of its
code).
Compares per module and merged: the point count exactly, mean |e| and std
within TOLERANCE_MM (default 0.001). Prints one line per figure; exit 0 if all
agree, 1 if not, 2 on bad arguments.

Why 0.001 mm: the two alignments differ by design only where the surface
hardly fixes the motion (score.cc damps those directions, this script leaves
them out), and there the distances change by well under a micrometre
(score_test.cc measured 0.6 um on an ellipsoidal cap); the scorer also aligns
on a 20 000-point subsample. Measured on the demo's five scenes: 0.03 um at
most. The score gate (scripts/score_gate.py) acts on 0.002 mm, so the scorer
must be right to better than that.

Shares nothing with the C++ scorer but the definition: PLY parsing, the k-d
tree (scipy.spatial.cKDTree against reconstruct/kd_tree.h), the plane fits
(numpy.linalg.eigh against Eigen), the alignment (an undamped least-squares
ICP with a minimum-norm step against a damped one).
"""
import json
import os
import sys

import numpy as np
from scipy.spatial import cKDTree

FILLED_MODULE = 255  # hole-filling points (reconstruct/point_cloud.h): not scored as measured
MAX_PAIR_MM = 2.0    # ICP pairs whose nearest truth sample is farther are left out (score.h)
K = 8                # truth samples per local plane (score.h)
PLANE_REACH_MM = 1.0  # a point whose nearest truth sample is farther is scored by that distance (score.h)

PLY_TYPES = {'float': '<f4', 'double': '<f8', 'uchar': 'u1', 'char': 'i1', 'ushort': '<u2', 'short': '<i2',
             'uint': '<u4', 'int': '<i4'}


def read_ply(path):
    """The vertex element of a binary little-endian PLY as a numpy record array."""
    with open(path, 'rb') as f:
        if f.readline().strip() != b'ply':
            raise ValueError(f'{path}: not a PLY file')
        fields, count = [], None
        while True:
            line = f.readline()
            if not line:
                raise ValueError(f'{path}: header without end_header')
            words = line.decode('ascii').split()
            if not words:
                continue
            if words[0] == 'format' and words[1] != 'binary_little_endian':
                raise ValueError(f'{path}: format {words[1]} (expected binary_little_endian)')
            if words[0] == 'element':
                if words[1] != 'vertex' or count is not None:
                    raise ValueError(f'{path}: expected one vertex element')
                count = int(words[2])
            if words[0] == 'property':
                fields.append((words[2], PLY_TYPES[words[1]]))
            if words[0] == 'end_header':
                break
        data = np.frombuffer(f.read(), dtype=np.dtype(fields), count=count)
    return data


def local_planes(tree, truth, points):
    """Centroid, unit normal and nearest-sample distance of the K-sample plane at each point."""
    dist, idx = tree.query(points, k=K, workers=-1)
    nb = truth[idx]  # (n, K, 3)
    centroid = nb.mean(axis=1)
    d = nb - centroid[:, None, :]
    cov = np.einsum('nki,nkj->nij', d, d)
    _, vectors = np.linalg.eigh(cov)  # ascending eigenvalues: column 0 is the normal
    return centroid, vectors[:, :, 0], dist[:, 0]


def rotation(w):
    angle = np.linalg.norm(w)
    if angle == 0:
        return np.eye(3)
    k = w / angle
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * kx + (1 - np.cos(angle)) * kx @ kx


def align(tree, truth, points, iterations=40):
    """truth_from_cloud (R, t) by point-to-plane ICP from the identity, and whether it converged.

    As score.h defines it: pairs whose nearest truth sample is farther than
    MAX_PAIR_MM are left out, and so are those whose distance exceeds
    max(0.05 mm, 3 x the median |distance|) (mismatches)."""
    r, t = np.eye(3), np.zeros(3)
    previous_rms = np.inf
    for _ in range(iterations):
        p = points @ r.T + t
        c, n, nearest = local_planes(tree, truth, p)
        residual = np.einsum('ni,ni->n', p - c, n)
        keep = nearest <= MAX_PAIR_MM
        keep &= np.abs(residual) <= max(0.05, 3 * np.median(np.abs(residual[keep])))
        p, n, residual = p[keep], n[keep], residual[keep]
        rms = np.sqrt(np.mean(residual**2))
        # Converged when the fit no longer improves (1e-6 mm: three orders
        # below the figures' tolerance). Not on the step: along directions
        # the surface hardly fixes (a sphere or a cylinder turning about its
        # centre or axis) the 8-sample planes' noise moves the pose by up to
        # degrees from one step to the next without changing any distance.
        if abs(previous_rms - rms) < 1e-6:
            return r, t, True
        previous_rms = rms
        pivot = p.mean(axis=0)  # rotations about the points' centroid: rotation and translation decoupled
        jacobian = np.hstack([np.cross(p - pivot, n), n])  # d residual / d (rotation vector, translation)
        # Truncated least squares: a direction the surface fixes 100 times
        # more weakly than its best-fixed one (a plate sliding in its plane,
        # a cylinder turning about its axis) is not moved. Undamped there,
        # the plate slid until the mismatch cut hid its overhang.
        step = np.linalg.lstsq(jacobian, -residual, rcond=1e-2)[0]
        dr = rotation(step[:3])
        r, t = dr @ r, dr @ (t - pivot) + pivot + step[3:]
    return r, t, False


def figures(e):
    return {'points': len(e), 'mean_abs_mm': float(np.mean(np.abs(e))) if len(e) else 0.0,
            'std_mm': float(np.std(e)) if len(e) else 0.0}


def score_scene(cloud, truth):
    tree = cKDTree(truth)
    measured = cloud['module'] != FILLED_MODULE
    xyz = np.stack([cloud['x'], cloud['y'], cloud['z']], axis=1).astype(np.float64)[measured]
    normal = np.stack([cloud['nx'], cloud['ny'], cloud['nz']], axis=1).astype(np.float64)[measured]
    module = cloud['module'][measured]
    r, t, converged = align(tree, truth, xyz)
    if not converged:
        raise RuntimeError('the alignment did not converge')
    p = xyz @ r.T + t
    c, n, nearest = local_planes(tree, truth, p)
    sign = np.where(np.einsum('ni,ni->n', n, normal @ r.T) >= 0, 1.0, -1.0)
    plane = np.einsum('ni,ni->n', p - c, n)
    e = sign * np.where(nearest > PLANE_REACH_MM, np.copysign(nearest, plane), plane)
    return figures(e), {int(m): figures(e[module == m]) for m in np.unique(module)}


def main():
    if len(sys.argv) not in (4, 5):
        print(__doc__, file=sys.stderr)
        return 2
    report = json.load(open(sys.argv[1]))
    dataset, cloud_dir = sys.argv[2], sys.argv[3]
    tolerance = float(sys.argv[4]) if len(sys.argv) == 5 else 0.001
    if not report.get('scenes') or not all(scene.get('modules') for scene in report['scenes']):
        print(f'{sys.argv[1]}: no scene or no module to compare', file=sys.stderr)
        return 2
    bad = 0
    for scene in report['scenes']:
        name = scene['scene']
        truth_ply = read_ply(os.path.join(dataset, 'truth', 'scenes', name, 'surface.ply'))
        truth = np.stack([truth_ply['x'], truth_ply['y'], truth_ply['z']], axis=1).astype(np.float64)
        merged, per_module = score_scene(read_ply(os.path.join(cloud_dir, name + '.ply')), truth)
        rows = [('merged', scene['merged'], merged)]
        rows += [(f"m{m['module']}", m['accuracy'], per_module.get(m['module'], figures([])))
                 for m in scene['modules']]
        for label, theirs, ours in rows:
            if theirs['points'] == 0 or ours['points'] == 0:
                # No point: score's figures are null (JSON), nothing to compare but the count.
                ok = theirs['points'] == ours['points']
                bad += not ok
                print(f"{name:8s} {label:6s} points {theirs['points']} / {ours['points']}"
                      f"{'' if ok else '  DIFFERS'}")
                continue
            ok = (theirs['points'] == ours['points'] and
                  abs(theirs['mean_abs_mm'] - ours['mean_abs_mm']) <= tolerance and
                  abs(theirs['std_mm'] - ours['std_mm']) <= tolerance)
            bad += not ok
            print(f"{name:8s} {label:6s} points {theirs['points']} / {ours['points']}  "
                  f"|e| {theirs['mean_abs_mm']:.5f} / {ours['mean_abs_mm']:.5f}  "
                  f"std {theirs['std_mm']:.5f} / {ours['std_mm']:.5f} mm (stereorig score / scipy)"
                  f"{'' if ok else '  DIFFERS'}")
    print('agree' if bad == 0 else f'{bad} figures differ by more than {tolerance} mm')
    return 0 if bad == 0 else 1


if __name__ == '__main__':
    sys.exit(main())
