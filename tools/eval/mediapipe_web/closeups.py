#!/usr/bin/env python3
"""Helpers of tools/eval/closeups.sh (docs/closeups.md).

  closeups.py boxes SOURCES.tsv REFDIR
      SOURCES.tsv: lines "name image offset_x offset_y full_w full_h" (the source's
      reference was made on `image`, a region of the full photo at the offset; the crops are
      cut from the full photo). REFDIR holds Google's reference of each source
      (<stem of image>_pose.json). Prints one line per crop: "crop_name name x y side cut",
      a square in the full photo's pixels.

  closeups.py table CROPS.tsv REFDIR OURSDIR
      CROPS.tsv: the lines of `boxes`. Compares ours (OURSDIR/<crop>.landmarks.jsonl, first
      frame) with Google's (REFDIR/<crop>_pose.json) on each 512x512 crop and prints the
      per-crop table and a summary line.

The crop: W = Google's shoulder width on the source (points 11-12), M = the shoulders'
midpoint, N = the nose. Top = N.y - 0.6 W (the head with a margin), bottom = M.y + cut x W
(cut 0.30: just below the shoulders ... 1.10: the chest below the elbows), side = bottom -
top, centred on M.x; shifted (never scaled) to stay inside the photo, and shrunk to the
photo's smaller side if larger. A fifth crop per source, <name>_t030, is tighter still: top =
N.y - 0.25 W (the top of the head cut off), cut 0.30."""

import json
import math
import os
import sys

CUTS = (0.30, 0.55, 0.80, 1.10)
HEAD_MARGIN = 0.6
# The tightest framing: the top of the head cut (top = N.y - 0.25 W), the body at cut 0.30.
TIGHT = ("t", 0.25, 0.30)


def load_ref(path):
    with open(path) as f:
        return json.load(f)


def boxes(sources_tsv, refdir):
    for line in open(sources_tsv):
        if not line.strip() or line.startswith("#"):
            continue
        name, image, ox, oy, fw, fh = line.split()
        ox, oy, fw, fh = int(ox), int(oy), int(fw), int(fh)
        stem = os.path.splitext(os.path.basename(image))[0]
        ref = load_ref(os.path.join(refdir, f"{stem}_pose.json"))
        p = ref["landmarks_px"]
        if not p:
            print(f"# {name}: Google finds no person on the source; skipped", file=sys.stderr)
            continue
        ls, rs, nose = p[11], p[12], p[0]
        w = math.hypot(ls[0] - rs[0], ls[1] - rs[1])
        mx, my = (ls[0] + rs[0]) / 2 + ox, (ls[1] + rs[1]) / 2 + oy
        for tag, margin, cut in [("c", HEAD_MARGIN, c) for c in CUTS] + [TIGHT]:
            top = nose[1] + oy - margin * w
            bottom = my + cut * w
            side = min(bottom - top, fw, fh)
            x = min(max(mx - side / 2, 0), fw - side)
            y = min(max(top, 0), fh - side)
            side, x, y = int(round(side)), int(round(x)), int(round(y))
            side = min(side, fw - x, fh - y)
            real_cut = (y + side - my) / w
            print(f"{name}_{tag}{int(round(cut * 100)):03d} {name} {x} {y} {side} {real_cut:.2f}")


def read_ours(path):
    with open(path) as f:
        lines = [json.loads(l) for l in f if l.strip()]
    head = lines[0]
    frames = [l for l in lines[1:] if "pose" in l]
    size = head.get("image_size")
    return size, (frames[0]["pose"] if frames else None)


def table(crops_tsv, refdir, oursdir):
    rows = []
    others = []
    print("| crop | source | box x,y,side (px of the photo) | cut (x W below shoulders) | "
          "points seen | mean % diag | mean px | max px (point) | shoulders 11 / 12 px | "
          "elbows 13 / 14 px |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for line in open(crops_tsv):
        if not line.strip() or line.startswith("#"):
            continue
        crop, name, x, y, side, cut = line.split()
        ref = load_ref(os.path.join(refdir, f"{crop}_pose.json"))
        w, h = ref["w"], ref["h"]
        diag = math.hypot(w, h)
        size, ours = read_ours(os.path.join(oursdir, f"{crop}.landmarks.jsonl"))
        g = ref["landmarks_px"]
        box = f"{x},{y},{side}"
        if not g or not ours:
            print(f"| {crop} | {name} | {box} | {cut} | Google {'none' if not g else 33}, "
                  f"ours {'none' if not ours else 33} | — | — | — | — | — |")
            continue
        if size and tuple(size) != (w, h):
            raise SystemExit(f"{crop}: image sizes differ {size} vs {w}x{h}")
        o = [(p[0] * w, p[1] * h) for p in ours]
        d = [math.hypot(o[i][0] - g[i][0], o[i][1] - g[i][1]) for i in range(33)]
        seen = [i for i in range(33) if g[i][3] > 0.5 and 0 <= g[i][0] < w and 0 <= g[i][1] < h]

        def pt(i):
            mark = "" if i in seen else "*"
            return f"{d[i]:.1f}{mark}"

        if not seen:
            print(f"| {crop} | {name} | {box} | {cut} | 0 | — | — | — | {pt(11)} / {pt(12)} | "
                  f"{pt(13)} / {pt(14)} |")
            continue
        # Another person: the torso centres (shoulder midpoints) further apart than half
        # Google's shoulder width. Listed, left out of the summary (a choice of person, not
        # a landmark error).
        gw = math.hypot(g[11][0] - g[12][0], g[11][1] - g[12][1])
        gc = ((g[11][0] + g[12][0]) / 2, (g[11][1] + g[12][1]) / 2)
        oc = ((o[11][0] + o[12][0]) / 2, (o[11][1] + o[12][1]) / 2)
        other = math.dist(gc, oc) > 0.5 * gw
        ds = [d[i] for i in seen]
        mean = sum(ds) / len(ds)
        if other:
            print(f"| {crop} | {name} | {box} | {cut} | {len(seen)} | another person: "
                  f"{mean / diag * 100:.2f} | {mean:.1f} | — | {pt(11)} / {pt(12)} | "
                  f"{pt(13)} / {pt(14)} |")
            others.append(crop)
            continue
        worst = max(seen, key=lambda i: d[i])
        rows.append((crop, name, mean / diag * 100, mean, d[11], d[12], d[13], d[14],
                     float(cut), 11 in seen and 12 in seen, 13 in seen, 14 in seen))
        print(f"| {crop} | {name} | {box} | {cut} | {len(seen)} | {mean / diag * 100:.2f} | "
              f"{mean:.1f} | {d[worst]:.1f} ({worst}) | {pt(11)} / {pt(12)} | "
              f"{pt(13)} / {pt(14)} |")
    if rows:
        n = len(rows)
        pct = sum(r[2] for r in rows) / n
        over = sum(1 for r in rows if r[2] > 1.0)
        sh = [v for r in rows for v in (r[4], r[5])]
        el = [v for r in rows for v in (r[6], r[7])]
        print(f"\nsummary: {n} crops, mean {pct:.2f} % of the diagonal (worst "
              f"{max(r[2] for r in rows):.2f} %, {over} over 1 %), shoulders mean "
              f"{sum(sh) / len(sh):.1f} px (max {max(sh):.1f}), elbows mean "
              f"{sum(el) / len(el):.1f} px (max {max(el):.1f}); "
              f"another person than Google's: {len(others)} {' '.join(others)}")
        print("  (shoulder and elbow means over every crop kept, whether Google sees the "
              "point or not; * in the table: Google does not see it)")
        for tag, c in [("c", c) for c in CUTS] + [(TIGHT[0], TIGHT[2])]:
            sel = [r for r in rows if r[0].endswith(f"_{tag}{int(round(c * 100)):03d}")]
            if sel:
                what = "head cut, cut" if tag == "t" else "cut"
                print(f"  {what} {c:.2f}: {len(sel)} crops, mean "
                      f"{sum(r[2] for r in sel) / len(sel):.2f} % of the diagonal")


def main():
    if len(sys.argv) == 4 and sys.argv[1] == "boxes":
        boxes(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 5 and sys.argv[1] == "table":
        table(sys.argv[2], sys.argv[3], sys.argv[4])
    else:
        print(__doc__, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
