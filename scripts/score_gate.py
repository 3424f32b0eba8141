#!/usr/bin/env python3
"""usage: scripts/score_gate.py BASEDIR NEWDIR: per-module comparison of two scripts/score_four_datasets.sh outputs.
The gate (session 9): per module, fill may drop at most 0.2 points and mean|e| / std may rise at most 0.002 mm;
issue-5 targets (mean<=0.1, std<=0.1 per module) must not be newly broken (not checked on the speckle-0.4
rows, datasets named high*, where the targets are not met). Modules are paired by their number; a scene or module missing on either side fails. Prints every module and a verdict;
exit 0 on pass, 1 on fail, 2 on bad arguments."""
import json, sys, os
if len(sys.argv) != 3:
    print(__doc__, file=sys.stderr); sys.exit(2)
base, new = sys.argv[1], sys.argv[2]
fails = 0; rows = 0; worst = {'fill': 0, 'mean': 0, 'std': 0}
# The datasets: every <name>.json in BASEDIR (score_four_datasets.sh writes demo, s7, off and high; more
# realizations may sit beside them, names starting 'high' for speckle 0.4).
for d in (base, new):
    if not os.path.isdir(d):
        print(f'{d}: not a folder', file=sys.stderr); sys.exit(2)
# Both folders' datasets: one on a side only is reported missing (a row that fails).
datasets = sorted({f[:-5] for d in (base, new) for f in os.listdir(d) if f.endswith('.json')})
if not datasets:
    print(f'{base}, {new}: no <dataset>.json', file=sys.stderr); sys.exit(2)
sums = {'fill': 0.0, 'mean': 0.0, 'std': 0.0}
missing = 0  # datasets on one side only
for ds in datasets:
    pb, pn = os.path.join(base, ds + '.json'), os.path.join(new, ds + '.json')
    if not (os.path.exists(pb) and os.path.exists(pn)):
        side = 'BASEDIR' if not os.path.exists(pb) else 'NEWDIR'
        print(f'{ds}: missing in {side}'); fails += 1; missing += 1; continue
    B = {s['scene']: s for s in json.load(open(pb))['scenes']}
    N = {s['scene']: s for s in json.load(open(pn))['scenes']}
    for sc in set(N) - set(B): print(f'{ds} {sc}: only in new'); fails += 1
    for sc in B:
        if sc not in N: print(f'{ds} {sc}: missing in new'); fails += 1; continue
        MB = {m['module']: m for m in B[sc]['modules']}; MN = {m['module']: m for m in N[sc]['modules']}
        if set(MB) != set(MN): print(f'{ds} {sc}: modules {sorted(MB)} vs {sorted(MN)}'); fails += 1
        for mb, mn in ((MB[k], MN[k]) for k in sorted(set(MB) & set(MN))):
            fb, fn = 100 * mb['fill']['fill'], 100 * mn['fill']['fill']
            eb, en = mb['accuracy']['mean_abs_mm'], mn['accuracy']['mean_abs_mm']
            sb, sn = mb['accuracy']['std_mm'], mn['accuracy']['std_mm']
            if None in (eb, en, sb, sn):  # a module without a point: null figures (score's JSON)
                same = eb is None and en is None
                print(f"{ds:5s} {sc:8s} m{mb['module']}: no point {'on both sides' if same else 'on one side'}"
                      f"{'' if same else ' NOPOINT'}")
                rows += 1; fails += not same; continue
            bad = []
            if fn < fb - 0.2: bad.append('fill')
            if en > eb + 0.002: bad.append('mean')
            if sn > sb + 0.002: bad.append('std')
            if not ds.startswith('high') and ((en > 0.1 >= eb) or (sn > 0.1 >= sb)): bad.append('TARGET')
            worst['fill'] = min(worst['fill'], fn - fb); worst['mean'] = max(worst['mean'], en - eb); worst['std'] = max(worst['std'], sn - sb)
            sums['fill'] += fn - fb; sums['mean'] += en - eb; sums['std'] += sn - sb
            rows += 1; fails += bool(bad)
            print(f"{ds:5s} {sc:8s} m{mb['module']}: fill {fb:5.1f}->{fn:5.1f} ({fn-fb:+.2f})  |e| {eb:.4f}->{en:.4f} ({en-eb:+.4f})  std {sb:.4f}->{sn:.4f} ({sn-sb:+.4f}) {' '.join(bad)}")
print(f"worst: fill {worst['fill']:+.2f} pts, mean {worst['mean']:+.4f} mm, std {worst['std']:+.4f} mm; "
      f"{fails - missing} of {rows} module rows fail the gate" + (f"; {missing} dataset(s) missing on one side" if missing else ""))
if rows:
    print(f"average over the rows: fill {sums['fill']/rows:+.2f} pts, mean {sums['mean']/rows:+.4f} mm, std {sums['std']/rows:+.4f} mm")
print('GATE PASS' if fails == 0 else 'GATE FAIL')
sys.exit(0 if fails == 0 else 1)
