#!/usr/bin/python3
"""Independent reference: project points with python3-mrcal.

Usage:
  mrcal_project.py raw  IN.json OUT.txt    IN.json = {"lensmodel", "intrinsics", "points": [[x,y,z],...]}
  mrcal_project.py model MODEL.cameramodel POINTS.txt OUT.txt
     loads the .cameramodel with mrcal (its own parser), projects the
     points (given in the camera frame) and also prints the model's fields.

Writes one "qx qy" line per point with %.17g. Run with Debian's
/usr/bin/python3, which has python3-mrcal.
"""
import json
import sys

import mrcal
import numpy as np


def write(path, q):
    with open(path, "w") as f:
        for row in np.atleast_2d(q):
            f.write("%.17g %.17g\n" % (row[0], row[1]))


def main():
    if sys.argv[1] == "raw":
        spec = json.load(open(sys.argv[2]))
        q = mrcal.project(np.array(spec["points"], dtype=float), spec["lensmodel"],
                          np.array(spec["intrinsics"], dtype=float))
        write(sys.argv[3], q)
    elif sys.argv[1] == "model":
        m = mrcal.cameramodel(sys.argv[2])
        p = np.loadtxt(sys.argv[3], ndmin=2)
        lensmodel, intrinsics = m.intrinsics()
        write(sys.argv[4], mrcal.project(p, lensmodel, intrinsics))
        # The exported extrinsics must read back too.
        print("extrinsics_rt_fromref", " ".join("%.17g" % x for x in m.extrinsics_rt_fromref()))
        print("imagersize", *m.imagersize())
    else:
        sys.exit("unknown mode " + sys.argv[1])


if __name__ == "__main__":
    main()
