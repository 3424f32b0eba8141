#!/usr/bin/python3
"""Recomputes `stereorig score`'s accuracy figures with scipy and numpy only.

usage: score_crosscheck.py SCORE_JSON DATASET CLOUD_DIR [TOLERANCE_MM]

SCORE_JSON: `stereorig score --report` of DATASET; CLOUD_DIR/<scene>.ply: the
clouds `stereorig reconstruct` writes for the same scenes, rig and options;
CLOUD_DIR/<scene>_passive.ply, where the report scored a scene's passive
capture: its cloud with score's passive options (where the report gives it
no point, the cloud must hold no measured point).
For each scene in the report: reads the cloud and the simulator's dense truth
(DATASET/truth/scenes/<scene>/surface.ply), aligns the cloud by its own
point-to-plane ICP from the identity, then takes each measured point's
distance to the plane through its 8 nearest truth samples (or, for a point
whose nearest sample is more than 1 mm away, that sample's distance), signed
by the cloud's normal (the definition in reconstruct/score.h; none of its
code).
Compares per module and merged: the point count exactly, mean |e| and std
within TOLERANCE_MM (default 0.001). The passive cloud is scored under the
active cloud's alignment (score's rule: its mismatches would pull their own)
and compared the same way, and so are the counts within 0.5 mm (active
merged, whether or not a passive cloud was scored, and passive) and
active_over_passive_within_0_5_mm: a count may differ by the points whose
|e| lies within TOLERANCE_MM of 0.5 mm (the distances'
own tolerance, carried to the count), the ratio by what those allow. Prints
one line per figure; exit 0 if all agree, 1 if not, 2 on bad arguments.

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


def figures(e, tolerance=0.0):
    """Count, mean |e|, std; the count within 0.5 mm and how many of those
    could flip with a change of `tolerance` mm in |e| (the points that near
    the bound)."""
    a = np.abs(e)
    return {'points': len(e), 'mean_abs_mm': float(np.mean(a)) if len(e) else 0.0,
            'std_mm': float(np.std(e)) if len(e) else 0.0, 'within': int(np.count_nonzero(a <= 0.5)),
            'within_slack': int(np.count_nonzero(np.abs(a - 0.5) <= tolerance))}


def measured_points(cloud):
    measured = cloud['module'] != FILLED_MODULE
    xyz = np.stack([cloud['x'], cloud['y'], cloud['z']], axis=1).astype(np.float64)[measured]
    normal = np.stack([cloud['nx'], cloud['ny'], cloud['nz']], axis=1).astype(np.float64)[measured]
    return xyz, normal, cloud['module'][measured]


def errors(tree, truth, xyz, normal, r, t):
    """Each point's signed distance to the truth under truth_from_cloud (r, t)."""
    p = xyz @ r.T + t
    c, n, nearest = local_planes(tree, truth, p)
    sign = np.where(np.einsum('ni,ni->n', n, normal @ r.T) >= 0, 1.0, -1.0)
    plane = np.einsum('ni,ni->n', p - c, n)
    return sign * np.where(nearest > PLANE_REACH_MM, np.copysign(nearest, plane), plane)


def score_scene(cloud, truth, tolerance, passive=None):
    """Merged and per-module figures of `cloud`, and (None without `passive`)
    the passive cloud's merged figures under the active cloud's alignment."""
    tree = cKDTree(truth)
    xyz, normal, module = measured_points(cloud)
    r, t, converged = align(tree, truth, xyz)
    if not converged:
        raise RuntimeError('the alignment did not converge')
    e = errors(tree, truth, xyz, normal, r, t)
    passive_figures = None
    if passive is not None:
        pxyz, pnormal, _ = measured_points(passive)
        passive_figures = figures(errors(tree, truth, pxyz, pnormal, r, t), tolerance)
    return (figures(e, tolerance), {int(m): figures(e[module == m]) for m in np.unique(module)}, passive_figures)


def within_agrees(theirs, ours):
    """score's within_0_5_mm count against ours, up to the points near 0.5 mm."""
    count = round(theirs['within_0_5_mm'] * theirs['points'])
    return abs(count - ours['within']) <= ours['within_slack'], count


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
        passive_ply = os.path.join(cloud_dir, name + '_passive.ply')
        passive_scored = isinstance(scene.get('passive'), dict) and scene['passive'].get('points', 0) > 0
        # The report counts the passive capture's points but scores none (no
        # "passive" figures) where it gave none: the plate.
        passive_empty = not passive_scored and scene.get('passive_points') == 0
        if (passive_scored or passive_empty) and not os.path.exists(passive_ply):
            print(f'{passive_ply}: missing (the report read the passive capture)', file=sys.stderr)
            return 2
        merged, per_module, passive = score_scene(read_ply(os.path.join(cloud_dir, name + '.ply')), truth,
                                                  tolerance, read_ply(passive_ply) if passive_scored else None)
        rows = [('merged', scene['merged'], merged)]
        rows += [(f"m{m['module']}", m['accuracy'], per_module.get(m['module'], figures([])))
                 for m in scene['modules']]
        # The active cloud's count within 0.5 mm, whether or not a passive
        # one was scored (the plate's passive cloud holds no point).
        active_ok, active_count = within_agrees(scene['merged'], merged)
        if not passive_scored and not passive_empty:
            bad += not active_ok
            print(f"{name:8s} within 0.5 mm: active {active_count} / {merged['within']} "
                  f"(+-{merged['within_slack']} near the bound) (stereorig score / scipy)"
                  f"{'' if active_ok else '  DIFFERS'}")
        elif passive_empty:
            # The report says the passive capture gave no point: so must its cloud.
            passive_points = len(measured_points(read_ply(passive_ply))[0])
            ok = active_ok and passive_points == 0
            bad += not ok
            print(f"{name:8s} within 0.5 mm: active {active_count} / {merged['within']} "
                  f"(+-{merged['within_slack']} near the bound); passive points 0 / {passive_points} "
                  f"(stereorig score / scipy){'' if ok else '  DIFFERS'}")
        if passive is not None:
            rows.append(('passive', scene['passive'], passive))
            passive_ok, passive_count = within_agrees(scene['passive'], passive)
            # The ratio's range over the counts the slack allows; score writes
            # null where no passive point lies within 0.5 mm.
            ratio = scene['active_over_passive_within_0_5_mm']
            if passive['within'] + passive['within_slack'] == 0:
                low = high = float('nan')
                ok = active_ok and passive_ok and ratio is None
            else:
                low = (merged['within'] - merged['within_slack']) / (passive['within'] + passive['within_slack'])
                high = (merged['within'] + merged['within_slack']) / max(1, passive['within'] - passive['within_slack'])
                ok = active_ok and passive_ok and ratio is not None and low - 1e-9 <= ratio <= high + 1e-9
            bad += not ok
            print(f"{name:8s} within 0.5 mm: active {active_count} / {merged['within']}, passive {passive_count} / "
                  f"{passive['within']} (+-{merged['within_slack']}, +-{passive['within_slack']} near the bound); "
                  f"active/passive {ratio} / [{low:.4f}, {high:.4f}] (stereorig score / scipy)"
                  f"{'' if ok else '  DIFFERS'}")
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
