#!/usr/bin/python3
# Reference for calib/crosscheck_test.cc: reads a .cameramodel written by
# mrcal-calibrate-cameras and prints, on one line, the RMS of its inlier
# chessboard residual coordinates (px, x and y pooled, as our reports give it),
# the number of outliers, then its intrinsics.
import sys

import mrcal
import numpy as np

m = mrcal.cameramodel(sys.argv[1])
oi = m.optimization_inputs()
x = mrcal.optimizer_callback(**oi, no_jacobian=True, no_factorization=True)[1]
r = mrcal.residuals_chessboard(oi, residuals=x).ravel()
outliers = int(np.sum(oi["observations_board"][..., 2] <= 0))
print("%.17g %d %s" % (np.sqrt(np.mean(r * r)), outliers, " ".join("%.17g" % v for v in m.intrinsics()[1])))
