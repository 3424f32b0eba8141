#!/usr/bin/python3
"""Calibration coverage of a simulated dataset: corners per camera, 8x6 image cells reached, board tilts.
Usage: sim_coverage.py DATASET   (Debian python3 with python3-mrcal)"""
import numpy as np, mrcal, yaml, sys
d=sys.argv[1]
rig=yaml.safe_load(open(d+'/truth/rig.yaml')); poses=yaml.safe_load(open(d+'/truth/calibration_poses.yaml')); tgt=yaml.safe_load(open(d+'/target.yaml'))
cx,cy,s=tgt['corners_x'],tgt['corners_y'],tgt['square_size_mm']
def cam_from_ref(k):
    for mi,m in enumerate(rig['modules']):
        M=np.linalg.inv(np.array(rig['S'][0][mi]))
        if m['left']==k: return M
        if m['right']==k: return np.array(m['right_from_left'])@M
bff=np.array(poses['board']['true_back_from_front'])
grid=np.array([[(i%cx)*s,(i//cx)*s,0,1] for i in range(cx*cy)]).T
for k,cam in enumerate(rig['cameras']):
    W,H=cam['imagersize']; cells=np.zeros((6,8),bool); tilts=[]; n=0
    for cap in poses['captures']:
        c=cap['cameras'][k]
        Mf=np.array(cap['module0_from_front'])
        P=Mf@grid if c['face']=='front' else Mf@np.linalg.inv(bff)@grid
        p=np.ascontiguousarray((cam_from_ref(k)@P)[:3].T)
        q=mrcal.project(p,cam['lensmodel'],np.array(cam['intrinsics']))
        ok=(q[:,0]>=0)&(q[:,1]>=0)&(q[:,0]<=W-1)&(q[:,1]<=H-1)
        n+=ok.sum()
        for x,y in q[ok]: cells[int(y/H*6),int(x/W*8)]=True
        nrm=(cam_from_ref(k)@Mf)[:3,2]; tilts.append(np.degrees(np.arccos(abs(nrm[2]))))
    print("cam%d: %d corners in view over %d captures; image cells (8x6) covered: %d/48; board tilt vs optical axis: median %.0f, max %.0f deg"%(k,n,len(poses['captures']),cells.sum(),np.median(tilts),max(tilts)))
