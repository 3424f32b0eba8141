#!/usr/bin/python3
"""What a lens drift of one camera does to a module's 3D points: the default module (pinhole, f 1024 px,
752x582, 90 mm baseline, 6 deg verging), points on the plane 200 mm in front of it that both cameras see (41 x 37
grid over 120 x 110 mm), the right camera's TRUE lens drifted, each point triangulated (midpoint) with the STORED
lens. Prints |error| mean, p95 and max (mm) for focal drifts and principal-point shifts.
Independent of stereorig (numpy only). Usage: /usr/bin/python3 lens_drift_points.py"""
import numpy as np
f, cx, cy, W, H = 1024.0, 375.5, 290.5, 752, 582
B, verging = 90.0, np.radians(6.0)
def turn_about_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
# module frame: x along the baseline, z toward the look-at point; (module_from_cam rotation, camera centre)
cams = {"left": (turn_about_y(+verging / 2), np.array([-B / 2, 0, 0.0])),
        "right": (turn_about_y(-verging / 2), np.array([+B / 2, 0, 0.0]))}
def project(cam, p, K):
    R, t = cam
    pc = R.T @ (p - t)
    return np.array([K[0] * pc[0] / pc[2] + K[2], K[1] * pc[1] / pc[2] + K[3]])
def ray(cam, q, K):
    R, t = cam
    v = R @ np.array([(q[0] - K[2]) / K[0], (q[1] - K[3]) / K[1], 1.0])
    return t, v / np.linalg.norm(v)
def midpoint(o1, v1, o2, v2):
    s = np.linalg.lstsq(np.array([v1, -v2]).T, o2 - o1, rcond=None)[0]
    return 0.5 * ((o1 + s[0] * v1) + (o2 + s[1] * v2))
stored = np.array([f, f, cx, cy])
def errors(focal_percent=0.0, dpp=(0.0, 0.0)):
    true = stored.copy()
    true[:2] *= 1 + focal_percent / 100
    true[2:] += dpp
    e = []
    for X in np.linspace(-60, 60, 41):
        for Y in np.linspace(-55, 55, 37):
            p = np.array([X, Y, 200.0])
            ql, qr = project(cams["left"], p, stored), project(cams["right"], p, true)
            if all(0 <= q[0] < W and 0 <= q[1] < H for q in (ql, qr)):
                e.append(np.linalg.norm(midpoint(*ray(cams["left"], ql, stored), *ray(cams["right"], qr, stored)) - p))
    e = np.array(e)
    return f"mean {e.mean():.3f}  p95 {np.percentile(e, 95):.3f}  max {e.max():.3f} mm ({len(e)} points)"
for pct in (0.005, 0.01, 0.015, 0.02, 0.05, 0.1, 0.2):
    print(f"focal {pct:+.3f} %:        {errors(focal_percent=pct)}")
for d in (0.03, 0.05, 0.1, 0.2, 0.5):
    print(f"cx {d:+.2f} px:           {errors(dpp=(d, 0))}")
    print(f"cy {d:+.2f} px:           {errors(dpp=(0, d))}")
