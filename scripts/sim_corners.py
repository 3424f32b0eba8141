#!/usr/bin/python3
"""Corner accuracy on a simulated dataset: OpenCV findChessboardCornersSB (CALIB_CB_ACCURACY) on every
calibration image that shows the whole board, against python3-mrcal projecting the true corners (truth/).
Usage: /usr/bin/python3 sim_corners.py DATASET"""
import cv2, numpy as np, mrcal, yaml, sys
d=sys.argv[1]
rig=yaml.safe_load(open(d+'/truth/rig.yaml'))
poses=yaml.safe_load(open(d+'/truth/calibration_poses.yaml'))
tgt=yaml.safe_load(open(d+'/target.yaml'))
cx,cy,s=tgt['corners_x'],tgt['corners_y'],tgt['square_size_mm']
S01=np.array(rig['S'][0][1]) if len(rig['S'])>1 else None
def cam_from_ref(k):
    for mi,m in enumerate(rig['modules']):
        M = np.linalg.inv(np.array(rig['S'][0][mi]))  # module_from_module0
        if m['left']==k: return M
        if m['right']==k: return np.array(m['right_from_left'])@M
bff=np.array(poses['board']['true_back_from_front'])
grid=np.array([[ (i%cx)*s, (i//cx)*s, 0,1] for i in range(cx*cy)]).T
allerr=[]
for cap in poses['captures']:
    Mf=np.array(cap['module0_from_front'])
    for c in cap['cameras']:
        k=c['camera']; cam=rig['cameras'][k]
        P = Mf@grid if c['face']=='front' else Mf@np.linalg.inv(bff)@grid
        p=np.ascontiguousarray((cam_from_ref(k)@P)[:3].T)
        q=mrcal.project(p, cam['lensmodel'], np.array(cam['intrinsics']))
        im=cv2.imread(f"{d}/{cap['folder']}/cam{k}.png",0)
        ok,corners=cv2.findChessboardCornersSB(im,(cx,cy),flags=cv2.CALIB_CB_ACCURACY)
        if not ok or corners is None: print(cap['index'],k,'no detection', c['corners_in_view']); continue
        corners=corners.reshape(-1,2)
        if len(sys.argv)>2: corners=cv2.cornerSubPix(im,corners.reshape(-1,1,2).astype(np.float32),(5,5),(-1,-1),(cv2.TERM_CRITERIA_EPS+cv2.TERM_CRITERIA_MAX_ITER,100,1e-4)).reshape(-1,2)
        # match by nearest
        dd=np.linalg.norm(corners[:,None,:]-q[None,:,:],axis=2)
        j=dd.argmin(1); e=corners-q[j]
        allerr.append(e)
        print(cap['index'],k,len(corners),'mean',e.mean(0),'rms',np.sqrt((e**2).sum(1).mean()))
e=np.vstack(allerr); print('ALL mean',e.mean(0),'rms',np.sqrt((e**2).sum(1).mean()))
