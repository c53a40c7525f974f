#!/usr/bin/env python3
"""How far the noisy figure can fall with bursts handled perfectly (docs/accuracy.md).

Usage: tools/eval/burst_floor.py [SEEDS...]     (default: the tuning seeds 1-5)

For each seed it synthesises the noisy scenario (`avatarmap synth --scenario noisy`, 20 s,
30 fps, 1280x720, with its truth), solves it with the default options, and evaluates three pose
files with `avatarmap eval-pose`:

  solved   what `avatarmap solve` gives (the figure issue 9 states its targets in);
  truth    the same, but every bone the truth marks as in a low-visibility burst (confidence 0)
           replaced by the true rotation: what a perfect treatment of the bursts would give,
           the rest left as solved;
  edges    the same, but the marked bones replaced by the slerp between their TRUE local
           rotations just before and just after the burst: the best that filling a burst from
           its two sides can do, with the sides known exactly.

Every frame outside the bursts is the solver's in all three, so "truth" is a floor for any
treatment of the bursts on top of the current solve, and "edges" the limit of filling them.
Rotations are replaced in local (parent-relative) space, as the pose files store them.

Environment: AVATARMAP (default build/avatarmap beside this checkout), KEEP (a folder to keep
the files in; default a temporary one, removed). Needs only Python's standard library.
"""
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile


def slerp(a, b, u):
    """Shortest-path slerp of two {x,y,z,w} quaternions, normalised."""
    d = sum(x * y for x, y in zip(a, b))
    if d < 0.0:
        b = [-x for x in b]
        d = -d
    d = min(1.0, d)
    th = math.acos(d)
    if th < 1e-6:
        r = list(a)
    else:
        s = math.sin(th)
        wa, wb = math.sin((1.0 - u) * th) / s, math.sin(u * th) / s
        r = [wa * x + wb * y for x, y in zip(a, b)]
    n = math.sqrt(sum(x * x for x in r)) or 1.0
    return [x / n for x in r]


def read_poses(path):
    with open(path, encoding="utf-8") as f:
        lines = f.read().splitlines()
    return lines[0], [json.loads(line) for line in lines[1:] if line.strip()]


def replace_bursts(truth, solved, mode):
    """Copies of `solved` with the truth's marked bones replaced (mode: truth | edges)."""
    n = min(len(truth), len(solved))
    out = [dict(s, bones=dict(s["bones"])) for s in solved[:n]]
    for bone in truth[0]["bones"]:
        marked = [truth[i].get("confidence", {}).get(bone, 1) == 0 for i in range(n)]
        i = 0
        while i < n:
            if not marked[i]:
                i += 1
                continue
            j = i
            while j < n and marked[j]:
                j += 1
            before, after = i - 1, j  # the true sides; either may be off the recording
            for k in range(i, j):
                if bone not in out[k]["bones"]:
                    continue
                if mode == "truth":
                    q = truth[k]["bones"][bone]
                elif before < 0:
                    q = truth[after]["bones"][bone]
                elif after >= n:
                    q = truth[before]["bones"][bone]
                else:
                    q = slerp(truth[before]["bones"][bone], truth[after]["bones"][bone],
                              (k - before) / (after - before))
                out[k]["bones"][bone] = q
            i = j
    return out


def write_poses(path, header, poses):
    with open(path, "w", encoding="utf-8") as f:
        f.write(header + "\n")
        for p in poses:
            f.write(json.dumps(p) + "\n")


def evaluate(exe, truth_path, path):
    out = subprocess.run([exe, "eval-pose", truth_path, path, "--json"], check=True,
                         capture_output=True, text=True).stdout
    d = json.loads(out)
    a = d["all"]
    row = [a[k]["mean"] for k in ("overall", "fingers", "arms")]
    n = sum(a[k]["count"] for k in ("torso", "arms", "legs"))
    row.append(sum(a[k]["mean"] * a[k]["count"] for k in ("torso", "arms", "legs")) / max(n, 1))
    row.append(d["marked"]["mean"] if d["marked"]["count"] > 0 else float("nan"))
    return row


def main(argv):
    here = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    exe = os.environ.get("AVATARMAP", os.path.join(here, "build", "avatarmap"))
    if not os.access(exe, os.X_OK):
        print(f"burst_floor.py: no avatarmap at {exe}; build it or set AVATARMAP", file=sys.stderr)
        return 2
    seeds = argv or ["1", "2", "3", "4", "5"]
    if not all(s.isdigit() for s in seeds):
        print("burst_floor.py: seeds are integers", file=sys.stderr)
        return 2
    keep = os.environ.get("KEEP")
    work = keep or tempfile.mkdtemp(prefix="avatarmap-burst-floor-")
    os.makedirs(work, exist_ok=True)
    try:
        print("%-6s %-8s %8s %8s %8s %8s %8s" % ("seed", "poses", "overall", "fingers", "arms",
                                                  "body", "lv-bone"))
        sums = {}
        for seed in seeds:
            base = os.path.join(work, f"noisy-{seed}")
            subprocess.run([exe, "synth", "--scenario", "noisy", "--seed", seed, "--seconds", "20",
                            "--fps", "30", "--size", "1280x720", "-o", base + ".landmarks.jsonl",
                            "--truth", base + ".truth.pose.jsonl"], check=True,
                           capture_output=True)
            subprocess.run([exe, "solve", base + ".landmarks.jsonl", "-o", base + ".pose.jsonl",
                            "--quiet"], check=True, capture_output=True)
            header, solved = read_poses(base + ".pose.jsonl")
            _, truth = read_poses(base + ".truth.pose.jsonl")
            paths = {"solved": base + ".pose.jsonl"}
            for mode in ("truth", "edges"):
                paths[mode] = f"{base}.bursts-{mode}.pose.jsonl"
                write_poses(paths[mode], header, replace_bursts(truth, solved, mode))
            for mode, path in paths.items():
                row = evaluate(exe, base + ".truth.pose.jsonl", path)
                print("%-6s %-8s %s" % (seed, mode, " ".join("%8.2f" % v for v in row)))
                acc = sums.setdefault(mode, [0.0] * len(row))
                for i, v in enumerate(row):
                    acc[i] += v
        for mode, acc in sums.items():
            print("%-6s %-8s %s" % ("mean", mode, " ".join("%8.2f" % (v / len(seeds)) for v in acc)))
    finally:
        if not keep:
            shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
