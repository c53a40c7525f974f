"""The Blender add-on (bindings/blender) imports takes with the right timing and motion.

  python3 tests/blender/test_import.py --cli build/avatarmap --work DIR

Runs Debian's Blender headless, as a user would: `blender -b --factory-startup --python
bindings/blender/import_take.py -- TAKE --out scene.blend`, then dumps the saved scene
(tests/blender/dump_scene.py). Cases:
  cmu     a CMU clip ($AVATARMAP_TEST_DATA/motion/cmu-bvh/131_01.bvh) made a *.pose.jsonl by
          `avatarmap convert`; its frame count and rate come from the CMU file itself
  synth   a landmark file from `avatarmap synth` (2 s at 30 fps); count and rate from the
          file's lines and header
  glb     that take on the avatar vrm1_spec_53bones.vrm as an animated .glb (Blender's glTF
          importer); ours: the CLI's rig FK of its frames (`convert --dump-positions`)
Checks: the scene's rate (fps / fps_base) and frame range (1..frames) are the take's; the
left hand's and left foot's world positions at three frames equal an independent forward
kinematics (numpy, below) of the BVH `avatarmap convert TAKE -o ref.bvh --fps RATE` writes
(glb: the CLI's own FK), within 1 cm. Environment: AVATARMAP_C_LIBRARY (the library the
add-on loads), BLENDER (default `blender`), AVATARMAP_TEST_DATA (the cmu and glb cases).
Exit 0 passed, 1 failed, 77 skipped (no Blender or no numpy).
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
IMPORT_TAKE = os.path.join(REPO, "bindings", "blender", "import_take.py")
DUMP = os.path.join(HERE, "dump_scene.py")
BONES = ("leftHand", "leftFoot")
TOLERANCE_M = 0.01

try:
    import numpy as np
except ImportError:
    print("SKIP: numpy not found (Debian: python3-numpy)")
    sys.exit(77)


def run(cmd, log):
    with open(log, "w") as f:
        r = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT, timeout=240)
    if r.returncode != 0:
        print("FAIL: %s exited %d; its output (%s):" % (" ".join(cmd[:4]), r.returncode, log))
        print(open(log).read()[-3000:])
        raise SystemExit(1)


# --- independent BVH forward kinematics ------------------------------------------------------

def read_bvh(path):
    """(joints [(name, parent, offset(3), channels[])], frame_time, motion (frames, values))."""
    tokens = open(path).read().split()
    joints, stack, i, pending, end_site = [], [], 0, None, False
    while tokens[i] != "MOTION":
        t = tokens[i]
        if t in ("ROOT", "JOINT"):
            pending = tokens[i + 1]
            i += 2
        elif t == "End":
            end_site, i = True, i + 2
        elif t == "{":
            if end_site:
                stack.append(None)
            else:
                joints.append([pending, stack[-1] if stack else -1, None, []])
                stack.append(len(joints) - 1)
            i += 1
        elif t == "}":
            if stack.pop() is None:
                end_site = False
            i += 1
        elif t == "OFFSET":
            if not end_site:
                joints[stack[-1]][2] = np.array([float(v) for v in tokens[i + 1:i + 4]])
            i += 4
        elif t == "CHANNELS":
            n = int(tokens[i + 1])
            joints[stack[-1]][3] = tokens[i + 2:i + 2 + n]
            i += 2 + n
        else:
            i += 1
    frames = int(tokens[i + 2])
    frame_time = float(tokens[i + 5])
    values = np.array([float(v) for v in tokens[i + 6:]]).reshape(frames, -1)
    return joints, frame_time, values


def axis_rotation(axis, degrees):
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    if axis == "X":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "Y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def world_positions(joints, values, frame):
    """Every joint's world position at a frame (file units, file axes): a joint's local
    transform is its OFFSET plus its position channels, then its rotation channels multiplied
    in listed order (column vectors)."""
    rot, pos, col = [None] * len(joints), [None] * len(joints), 0
    row = values[frame]
    for j, (_name, parent, offset, channels) in enumerate(joints):
        local_t, local_r = offset.copy(), np.eye(3)
        for ch in channels:
            v = row[col]
            col += 1
            if ch.endswith("position"):
                local_t["XYZ".index(ch[0])] += v
            else:
                local_r = local_r @ axis_rotation(ch[0], v)
        if parent < 0:
            rot[j], pos[j] = local_r, local_t
        else:
            rot[j] = rot[parent] @ local_r
            pos[j] = pos[parent] + rot[parent] @ local_t
    return {joints[j][0]: pos[j] for j in range(len(joints))}


# --- the take's own figures ------------------------------------------------------------------

def jsonl_figures(path):
    """(frames, fps) of a *.landmarks.jsonl / *.pose.jsonl: lines with "t", the header's fps."""
    frames, fps = 0, 0.0
    with open(path) as f:
        for line in f:
            if not line.strip():
                continue
            obj = json.loads(line)
            if "format" in obj:
                fps = float(obj.get("fps", 0.0))
            elif "t" in obj:
                frames += 1
    return frames, fps


def cmu_figures(path):
    """(frames, fps) of a BVH's MOTION header."""
    frames, frame_time = None, None
    with open(path) as f:
        for line in f:
            if line.startswith("Frames:"):
                frames = int(line.split(":")[1])
            elif line.startswith("Frame Time:"):
                frame_time = float(line.split(":")[1])
                break
    return frames, round(1.0 / frame_time, 3)


def bvh_reference(cli, take, fps, frames, work, name):
    """Our FK of the take: `avatarmap convert TAKE -o ref.bvh --fps RATE` through the numpy FK
    above; a function of a 1-based scene frame -> {joint: xyz metres, Y up}."""
    ref = os.path.join(work, name + ".ref.bvh")
    run([cli, "convert", take, "-o", ref, "--fps", repr(fps), "--quiet"],
        os.path.join(work, name + ".ref.log"))
    joints, _frame_time, values = read_bvh(ref)
    if len(values) != frames:
        print("  FAIL: the reference BVH has %d frames, the take %d" % (len(values), frames))
        raise SystemExit(1)
    return lambda f: {k: v * 0.01 for k, v in world_positions(joints, values, f - 1).items()}


def check_case(name, take, frames, fps, blender, work, joints, reference):
    print("case %s: %s (%d frames at %g fps)" % (name, os.path.basename(take), frames, fps))
    blend = os.path.join(work, name + ".blend")
    summary = os.path.join(work, name + ".summary.json")
    run([blender, "-b", "--factory-startup", "--python", IMPORT_TAKE, "--", take, "--clear",
         "--armature", "take", "--out", blend, "--summary", summary],
        os.path.join(work, name + ".import.log"))
    picks = [1, (frames + 1) // 2, frames]  # scene frames; motion frame = scene frame - 1
    dump = os.path.join(work, name + ".dump.json")
    run([blender, "-b", blend, "--python", DUMP, "--", "--armature", "take", "--bones",
         ",".join(joints), "--frames", ",".join(map(str, picks)), "--out", dump],
        os.path.join(work, name + ".dump.log"))
    scene = json.load(open(dump))
    ok = True
    scene_fps = scene["fps"] / scene["fps_base"]
    print("  scene: %g fps (fps %d / fps_base %.6f), frames %d..%d, action %r keys %g..%g"
          % (scene_fps, scene["fps"], scene["fps_base"], scene["frame_start"],
             scene["frame_end"], scene["action"], *scene["action_range"]))
    if abs(scene_fps - fps) > 1e-3 * fps:
        print("  FAIL: scene rate %g, the take's %g" % (scene_fps, fps))
        ok = False
    if (scene["frame_start"], scene["frame_end"]) != (1, frames):
        print("  FAIL: scene frames %d..%d, expected 1..%d"
              % (scene["frame_start"], scene["frame_end"], frames))
        ok = False
    if [round(v, 3) for v in scene["action_range"]] != [1, frames]:
        print("  FAIL: the action's keys span %s, expected [1, %d]"
              % (scene["action_range"], frames))
        ok = False
    worst = 0.0
    for f in picks:
        ours = reference(f)
        for joint in joints:
            x, y, z = scene["frames"][str(f)][joint]
            got = np.array([x, z, -y])  # Blender's Z up -> the files' Y up (the importers' axes)
            want = np.asarray(ours[joint])
            err = float(np.linalg.norm(got - want))
            worst = max(worst, err)
            print("  frame %4d %-9s blender [%8.4f %8.4f %8.4f]  ours [%8.4f %8.4f %8.4f]  "
                  "%.3g mm" % (f, joint, *got, *want, err * 1000))
    if worst > TOLERANCE_M:
        print("  FAIL: a position is %.2f cm off (tolerance 1 cm)" % (worst * 100))
        ok = False
    print("  %s: worst position error %.4g mm" % ("ok" if ok else "FAIL", worst * 1000))
    return ok


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--cli", required=True, help="the avatarmap executable")
    p.add_argument("--work", required=True)
    args = p.parse_args()
    blender = os.environ.get("BLENDER", "blender")
    if not shutil.which(blender):
        print("SKIP: %s not on PATH (Debian: sudo apt-get install blender, or "
              "AVATARMAP_WITH_BLENDER=1 scripts/setup.sh)" % blender)
        return 77
    # A sanitizer build's C library needs the ASan runtime loaded first, which Blender's own
    # process does not do: the add-on is tested on the normal build.
    lib = os.environ.get("AVATARMAP_C_LIBRARY", "")
    deps = subprocess.run(["ldd", lib], capture_output=True, text=True).stdout if lib else ""
    if "libclang_rt.asan" in deps or "libasan" in deps:
        print("SKIP: a sanitizer build (the Blender add-on is tested on the normal build)")
        return 77
    os.makedirs(args.work, exist_ok=True)
    cli = os.path.abspath(args.cli)
    ok = True

    synth = os.path.join(args.work, "synth.landmarks.jsonl")
    run([cli, "synth", "-o", synth, "--seconds", "2", "--fps", "30"],
        os.path.join(args.work, "synth.log"))
    frames, fps = jsonl_figures(synth)
    ok &= check_case("synth", synth, frames, fps, blender, args.work, BONES,
                     bvh_reference(cli, synth, fps, frames, args.work, "synth"))

    data = os.environ.get("AVATARMAP_TEST_DATA", "")
    clip = os.path.join(data, "motion", "cmu-bvh", "131_01.bvh")
    if data and os.path.isfile(clip):
        take = os.path.join(args.work, "cmu.pose.jsonl")
        run([cli, "convert", clip, "-o", take, "--quiet"], os.path.join(args.work, "cmu.log"))
        frames, fps = cmu_figures(clip)
        pose_frames, pose_fps = jsonl_figures(take)
        print("CMU clip: %d frames at %g fps; its .pose.jsonl: %d frames, header fps %g"
              % (frames, fps, pose_frames, pose_fps))
        ok &= check_case("cmu", take, frames, fps, blender, args.work, BONES,
                         bvh_reference(cli, take, fps, frames, args.work, "cmu"))
    else:
        print("note: no shared data (AVATARMAP_TEST_DATA): the CMU case is skipped")

    avatar = os.path.join(data, "avatars", "vrm1_spec_53bones.vrm")
    if data and os.path.isfile(avatar):
        # The synthetic take on an avatar as an animated .glb, through Blender's glTF
        # importer; ours: the CLI's rig FK of the frames it wrote (--dump-positions). This
        # avatar has no skin: its joints come in as empties, the hand's and foot's named
        # hand.L and foot.L (its node names).
        take = os.path.join(args.work, "avatar.glb")
        ours = os.path.join(args.work, "avatar.ours.json")
        run([cli, "convert", synth, "-o", take, "--fps", "30", "--avatar", avatar,
             "--dump-positions", ours, "--quiet"], os.path.join(args.work, "avatar.log"))
        positions = json.load(open(ours))["frames"]
        frames, fps = jsonl_figures(synth)
        ok &= check_case("glb", take, frames, fps, blender, args.work, ("hand.L", "foot.L"),
                         lambda f: positions[f - 1])
    else:
        print("note: no shared data (AVATARMAP_TEST_DATA): the .glb case is skipped")
    print("blender import: %s" % ("passed" if ok else "FAILED"))
    return 0 if ok else 1


sys.exit(main())
