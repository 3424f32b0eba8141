#!/usr/bin/python3
# Reference for calib/projection_uncertainty_test.cc: python3-mrcal's own
# projection_uncertainty on the same solved problem.
#
# usage: mrcal_uncertainty.py problem.json out.txt
# problem.json: the solved problem (intrinsics, extrinsics, frames, observation
# indices, the observation pool, lens model, selections) and "queries": a list
# of {"icam": i, "p_cam": [x, y, z]}.
# out.txt: one line per query: Var(q) as 4 numbers (row-major 2x2), then
# sigma (observed_pixel_uncertainty as mrcal estimates it), then the residual
# RMS from mrcal's own callback.
import json
import sys

import mrcal
import numpy as np

d = json.load(open(sys.argv[1]))
W, H = d["corners_x"], d["corners_y"]
nobs = len(d["indices"]) // 3
optimization_inputs = dict(
    intrinsics=np.array(d["intrinsics"], dtype=float).reshape(d["ncams"], -1),
    extrinsics_rt_fromref=np.array(d["extrinsics"], dtype=float).reshape(-1, 6),
    frames_rt_toref=np.array(d["frames"], dtype=float).reshape(-1, 6),
    points=None,
    observations_board=np.array(d["pool"], dtype=float).reshape(nobs, H, W, 3),
    indices_frame_camintrinsics_camextrinsics=np.array(d["indices"], dtype=np.int32).reshape(nobs, 3),
    observations_point=None,
    indices_point_camintrinsics_camextrinsics=None,
    lensmodel=d["lensmodel"],
    imagersizes=np.array(d["imagersizes"], dtype=np.int32).reshape(d["ncams"], 2),
    calobject_warp=None,
    do_optimize_intrinsics_core=bool(d["core"]),
    do_optimize_intrinsics_distortions=bool(d["distortions"]),
    do_optimize_extrinsics=True,
    do_optimize_frames=True,
    do_optimize_calobject_warp=False,
    do_apply_regularization=bool(d["regularization"]),
    do_apply_outlier_rejection=False,
    calibration_object_spacing=d["spacing"],
)
if optimization_inputs["extrinsics_rt_fromref"].size == 0:
    optimization_inputs["extrinsics_rt_fromref"] = None
x = mrcal.optimizer_callback(**optimization_inputs, no_jacobian=True, no_factorization=True)[1]
with open(sys.argv[2], "w") as f:
    for q in d["queries"]:
        icam = q["icam"]
        model = mrcal.cameramodel(optimization_inputs=optimization_inputs, icam_intrinsics=icam)
        p = np.array(q["p_cam"], dtype=float)
        var = mrcal.projection_uncertainty(p, model, what="covariance")
        sigma = np.std(mrcal.residuals_chessboard(optimization_inputs, residuals=x).ravel())
        f.write(" ".join("%.17g" % v for v in var.ravel()) + " %.17g\n" % sigma)
