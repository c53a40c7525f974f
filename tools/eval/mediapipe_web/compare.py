#!/usr/bin/env python3
"""Compares two pose reference files in the goldens' layout (landmarks_px, world), e.g. the
output of reference.py against the shared data's golden/upper_body_portrait_pose.json:
prints the max / mean pixel distance over all 33 points and over the in-frame visible ones
(visibility > 0.5 in B, inside the image), the max |dz| px, the max visibility difference and
the max world-point distance (m). Exit 1 when the in-frame max exceeds --tolerance px."""

import argparse
import json
import math
import sys


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("a")
    ap.add_argument("b", help="the reference to compare with")
    ap.add_argument("--tolerance", type=float, default=3.0, help="px, in-frame max")
    args = ap.parse_args()
    a, b = json.load(open(args.a)), json.load(open(args.b))
    if (a["w"], a["h"]) != (b["w"], b["h"]):
        print(f"sizes differ: {a['w']}x{a['h']} vs {b['w']}x{b['h']}")
        return 1
    pa, pb = a["landmarks_px"], b["landmarks_px"]
    if not pa or not pb:
        print(f"landmarks: {len(pa)} vs {len(pb)}")
        return 0 if len(pa) == len(pb) else 1
    w, h = b["w"], b["h"]
    d = [math.hypot(p[0] - q[0], p[1] - q[1]) for p, q in zip(pa, pb)]
    seen = [i for i, q in enumerate(pb) if q[3] > 0.5 and 0 <= q[0] < w and 0 <= q[1] < h]
    ds = [d[i] for i in seen]
    dz = max(abs(p[2] - q[2]) for p, q in zip(pa, pb))
    dv = max(abs(p[3] - q[3]) for p, q in zip(pa, pb))
    dw = max(math.dist(p[:3], q[:3]) for p, q in zip(a["world"], b["world"])) \
        if a["world"] and b["world"] else float("nan")
    print(f"all 33: max {max(d):.3f} mean {sum(d) / len(d):.3f} px; in-frame visible "
          f"{len(seen)}: max {max(ds):.3f} mean {sum(ds) / len(ds):.3f} px; max |dz| {dz:.3f} px; "
          f"max |dvis| {dv:.4f}; world max {dw:.4f} m")
    return 0 if max(ds) <= args.tolerance else 1


if __name__ == "__main__":
    sys.exit(main())
