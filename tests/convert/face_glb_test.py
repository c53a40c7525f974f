#!/usr/bin/env python3
"""The avatar's face in the animated .glb (docs/export.md, "The face"): `avatarmap convert
take.pose.jsonl --avatar A -o take.glb` writes morph-target weight channels driven by the
poses' expressions through the avatar's own definitions. The written GLB is read back here by
an independent reader (the GLB container, the JSON, raw accessor bytes) and checked against
weights computed here from the avatar file's definitions:

- VRM 1.0: the built-in avatar (`avatarmap avatar`), its VRMC_vrm expressions (bound to its
  52 ARKit morph targets) and its targets named after ARKit's shapes.
- VRM 0.x: the same avatar rewritten here as VRM 0.x (blendShapeMaster, bind weights 0-100,
  preset names a/i/u/e/o/blink/blink_l.../joy/angry/sorrow/fun, one group isBinary, bind
  weights other than 100) with Perfect Sync groups named after ARKit's shapes in UniVRM's
  capitalised spelling ("EyeBlinkLeft").
- plain glTF: the same avatar without VRM, its targets renamed "blendShape1.<ARKit name>" (the
  prefix Maya and FBX exports put there).
- each with two clips: expressions only (a pose file from before the blendshapes: the
  expressions drive every bind), and expressions with ARKit blendshapes (the blendshapes drive
  the targets an ARKit shape reaches; expression binds onto those targets are dropped).
- avatars without morph targets (the shared vrm1_spec_expressions.vrm, vrm1_debug_robot.vrm
  and vrm0_sphere.vrm, when $AVATARMAP_TEST_DATA is set): joints only, no error.

The expected weights are computed here from the avatar file's own definitions with the rules
of docs/export.md ("The face"), written again in Python.

With node and npm's gltf-validator (Khronos's validator; NODE_PATH naming its node_modules)
each written file is also validated: no errors. With chromium, `avatarmap render` (three-vrm in
headless Chromium) shows the face change between a neutral frame and a moving one, on the
VRM 1.0 and the VRM 0.x avatar, for the expressions and for the ARKit shapes.
Usage: face_glb_test.py AVATARMAP_EXE WORKDIR."""

import json
import os
import shutil
import struct
import subprocess
import sys

NAMES = ["blink", "blinkLeft", "blinkRight", "aa", "ih", "ou", "ee", "oh", "lookUp",
         "lookDown", "lookLeft", "lookRight", "browUpLeft", "browUpRight", "browDownLeft",
         "browDownRight", "happy", "angry", "sad", "relaxed", "surprised"]
# ARKit's 52 (Apple's ARFaceAnchor.BlendShapeLocation names), written out independently.
SHAPES = ["browDownLeft", "browDownRight", "browInnerUp", "browOuterUpLeft", "browOuterUpRight",
          "cheekPuff", "cheekSquintLeft", "cheekSquintRight", "eyeBlinkLeft", "eyeBlinkRight",
          "eyeLookDownLeft", "eyeLookDownRight", "eyeLookInLeft", "eyeLookInRight",
          "eyeLookOutLeft", "eyeLookOutRight", "eyeLookUpLeft", "eyeLookUpRight",
          "eyeSquintLeft", "eyeSquintRight", "eyeWideLeft", "eyeWideRight", "jawForward",
          "jawLeft", "jawOpen", "jawRight", "mouthClose", "mouthDimpleLeft", "mouthDimpleRight",
          "mouthFrownLeft", "mouthFrownRight", "mouthFunnel", "mouthLeft", "mouthLowerDownLeft",
          "mouthLowerDownRight", "mouthPressLeft", "mouthPressRight", "mouthPucker",
          "mouthRight", "mouthRollLower", "mouthRollUpper", "mouthShrugLower",
          "mouthShrugUpper", "mouthSmileLeft", "mouthSmileRight", "mouthStretchLeft",
          "mouthStretchRight", "mouthUpperUpLeft", "mouthUpperUpRight", "noseSneerLeft",
          "noseSneerRight", "tongueOut"]
FPS = 30
# Per frame: (expression values, blendshape values), others 0. Clip "expr": frame 2 sums blink
# and blinkLeft past 1 (clamped); frame 3 has a value above 1 (clamped) and aa at 0.4 (a binary
# expression reads 0); frame 4 the emotions. Clip "arkit": the same avatar driven by shapes too.
CLIPS = {
    "expr": [
        ({}, {}),
        ({"blink": 0.6, "aa": 0.3}, {}),
        ({"blink": 0.8, "blinkLeft": 0.5, "aa": 0.9, "browUpLeft": 0.25}, {}),
        ({"ih": 1.5, "aa": 0.4, "lookUp": 0.2}, {}),
        ({"happy": 0.7, "sad": 0.4, "surprised": 1.0, "relaxed": 0.2, "angry": 0.3}, {}),
    ],
    "arkit": [
        ({}, {}),
        ({"aa": 0.8, "happy": 0.5},
         {"eyeBlinkLeft": 0.7, "jawOpen": 0.9, "mouthSmileLeft": 0.5, "mouthSmileRight": 0.5}),
        ({"browDownLeft": 0.2, "blink": 1.0},
         {"tongueOut": 1.3, "browDownLeft": 0.6, "mouthFrownRight": 0.4}),
        ({"surprised": 1.0}, {"cheekPuff": 0.9, "eyeWideLeft": 0.5, "eyeWideRight": 0.5}),
    ],
}
# The frame each clip's rendering compares with frame 0.
MOVING_FRAME = {"expr": 2, "arkit": 1}

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print(f"FAIL: {what}")


def read_glb(path):
    data = open(path, "rb").read()
    magic, version, length = struct.unpack_from("<III", data, 0)
    assert magic == 0x46546C67 and version == 2 and length == len(data), path
    jlen, jtype = struct.unpack_from("<II", data, 12)
    assert jtype == 0x4E4F534A
    doc = json.loads(data[20:20 + jlen])
    bin_chunk = b""
    if 20 + jlen < len(data):
        blen, btype = struct.unpack_from("<II", data, 20 + jlen)
        assert btype == 0x004E4942
        bin_chunk = data[28 + jlen:28 + jlen + blen]
    return doc, bin_chunk


def write_glb(path, doc, bin_chunk):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    bin_chunk += b"\0" * (-len(bin_chunk) % 4)
    out = struct.pack("<II", len(js), 0x4E4F534A) + js
    if bin_chunk:
        out += struct.pack("<II", len(bin_chunk), 0x004E4942) + bin_chunk
    with open(path, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(out)) + out)


def floats(doc, bin_chunk, accessor):
    a = doc["accessors"][accessor]
    assert a["componentType"] == 5126, "FLOAT"
    comps = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[a["type"]]
    view = doc["bufferViews"][a["bufferView"]]
    start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
    stride = view.get("byteStride", 4 * comps)
    out = []
    for i in range(a["count"]):
        out.extend(struct.unpack_from(f"<{comps}f", bin_chunk, start + i * stride))
    return out


def target_count(doc, node):
    mesh = doc["nodes"][node].get("mesh")
    if mesh is None:
        return 0
    return len(doc["meshes"][mesh]["primitives"][0].get("targets", []))


def shape_of(name):
    """ARKit's shape a name stands for: any case, after a prefix up to the last '.' and then
    "ARKit_"; None when it is none."""
    n = name.rsplit(".", 1)[-1]
    if n.lower().startswith("arkit_") and len(n) > 6:
        n = n[6:]
    for s in SHAPES:
        if s.lower() == n.lower():
            return s
    return None


def expected_weights(defs, doc, frame):
    """{node: [weights]} for one frame (expressions, shapes) from definitions
    [(expression or None, shape or None, is_binary, [(node, index, weight)])]: the shapes drive
    what they reach when the clip carries shapes (frame[2]); the expressions the rest."""
    expr, shapes, active = frame
    reached = set()
    if active:
        for _, shape, _, binds in defs:
            if shape:
                reached.update((n, i) for n, i, _ in binds)
    out = {}
    for name, shape, binary, binds in defs:
        if active and shape:
            v = shapes.get(shape, 0.0)
        elif name:
            v = expr.get(name, 0.0)
        else:
            continue
        v = min(max(v, 0.0), 1.0)
        if binary:
            v = 1.0 if v > 0.5 else 0.0
        for node, index, weight in binds:
            n = target_count(doc, node)
            if index >= n:
                continue
            if not (active and shape) and (node, index) in reached:
                continue
            w = out.setdefault(node, [0.0] * n)
            w[index] += v * weight
    return {k: [min(max(x, 0.0), 1.0) for x in w] for k, w in out.items()}


def expected_clip(defs, doc, clip):
    frames = CLIPS[clip]
    active = any(v != 0 for _, sh in frames for v in sh.values())
    has_shape = any(shape for _, shape, _, _ in defs)
    return [expected_weights(defs, doc, (e, sh, active and has_shape)) for e, sh in frames]


def write_poses(path, clip):
    with open(path, "w") as f:
        f.write(json.dumps({"format": "avatarmap.pose", "version": 1, "fps": FPS}) + "\n")
        for i, (e, sh) in enumerate(CLIPS[clip]):
            line = {"t": i / FPS, "hips_position": [0, 0.95, 0],
                    "expressions": {k: e.get(k, 0.0) for k in NAMES}}
            if clip == "arkit":
                line["blendshapes"] = {k: sh.get(k, 0.0) for k in SHAPES}
            f.write(json.dumps(line) + "\n")


def check_glb(label, glb, expected, source_doc):
    doc, bin_chunk = read_glb(glb)
    frames = len(expected)
    anims = doc.get("animations", [])
    check(len(anims) == 1, f"{label}: one animation")
    anim = anims[0]
    channels = [c for c in anim["channels"] if c["target"]["path"] == "weights"]
    nodes = sorted(expected[0].keys())
    check(sorted(c["target"]["node"] for c in channels) == nodes,
          f"{label}: weight channels on nodes {sorted(c['target']['node'] for c in channels)}, "
          f"expected {nodes}")
    # Joints are still animated (the hips' translation at least).
    check(any(c["target"]["path"] in ("rotation", "translation") for c in anim["channels"]),
          f"{label}: joint channels kept")
    for c in channels:
        node = c["target"]["node"]
        s = anim["samplers"][c["sampler"]]
        times = floats(doc, bin_chunk, s["input"])
        check(len(times) == frames and
              all(abs(t - i / FPS) < 1e-5 for i, t in enumerate(times)),
              f"{label}: node {node} sampler times {times}")
        check(s.get("interpolation", "LINEAR") in ("LINEAR", "STEP"), f"{label}: interpolation")
        out = floats(doc, bin_chunk, s["output"])
        n = target_count(doc, node)
        check(len(out) == n * frames, f"{label}: node {node} has {len(out)} weights for "
              f"{n} targets x {frames} frames")
        for f in range(frames):
            got = out[f * n:(f + 1) * n]
            want = expected[f][node]
            bad = [(t, g, w) for t, (g, w) in enumerate(zip(got, want)) if abs(g - w) > 1e-4]
            check(not bad, f"{label}: node {node} frame {f} (target, got, want): {bad[:4]}")
    nonzero = sum(1 for e in expected for w in e.values() for x in w if x > 0)
    check(nonzero >= 4, f"{label}: the fixture moves the face ({nonzero} non-zero weights)")
    validate(label, glb, morphs=True)


NODE_VALIDATE = """
const v = require('gltf-validator');
const data = require('fs').readFileSync(process.argv[1]);
v.validateBytes(new Uint8Array(data), {maxIssues: 0})
  .then(r => console.log(JSON.stringify(r)))
  .catch(e => { console.error(String(e)); process.exit(2); });
"""


def validator_codes(glb):
    """The codes of the validator's errors on a file (None without the validator)."""
    node = shutil.which("node")
    if not node:
        return None
    r = subprocess.run([node, "-e", NODE_VALIDATE, glb], capture_output=True, text=True)
    try:
        return {m.get("code") for m in json.loads(r.stdout)["issues"]["messages"]
                if m.get("severity", 9) == 0}
    except (ValueError, KeyError):
        return None


def validate(label, glb, morphs=False, source=None):
    """Khronos's glTF validator (npm's gltf-validator, found through NODE_PATH, e.g. the
    node_modules folder of `npm install gltf-validator`); skipped without node or the module."""
    node = shutil.which("node")
    probe = node and subprocess.run([node, "-e", "require('gltf-validator')"],
                                    capture_output=True).returncode == 0
    if not probe:
        print(f"{label}: no node with gltf-validator (NODE_PATH), validation skipped")
        return
    r = subprocess.run([node, "-e", NODE_VALIDATE, glb], capture_output=True, text=True)
    try:
        issues = json.loads(r.stdout)["issues"]
    except (ValueError, KeyError):
        check(False, f"{label}: gltf-validator failed: {r.stderr[:300]}")
        return
    info = json.loads(r.stdout).get("info", {})
    print(f"{label}: glTF validator: {issues['numErrors']} errors, {issues['numWarnings']} "
          f"warnings, {issues['numInfos']} infos, {issues['numHints']} hints; "
          f"animationCount {info.get('animationCount')}, "
          f"maxAttributes {info.get('maxAttributes')}, hasMorphTargets "
          f"{info.get('hasMorphTargets')}")
    if morphs:
        check(info.get("hasMorphTargets") is True, f"{label}: the validator sees morph targets")
    # Errors the avatar file itself has (a shared avatar's non-unit normals) are its own: only
    # new ones count against the writer.
    own = validator_codes(source) if source and issues["numErrors"] else set()
    new = [m for m in issues.get("messages", [])
           if m.get("severity", 9) == 0 and m.get("code") not in (own or set())]
    shown = {}
    for m in issues.get("messages", []):
        if m.get("severity", 9) <= 1 and shown.get(m.get("code"), 0) < 3:
            shown[m.get("code")] = shown.get(m.get("code"), 0) + 1
            print(f"    {m.get('code')}: {m.get('message')} ({m.get('pointer', '')})")
    if own:
        print(f"    the avatar itself has these errors: {sorted(own)}")
    check(not new, f"{label}: glTF validator errors the avatar does not have")


def named_target_defs(doc, claimed, expressions):
    """Morph targets named after an ARKit shape (or, when `expressions`, an expression) that no
    definition claimed: weight 1."""
    defs = []
    for n, node in enumerate(doc["nodes"]):
        if "mesh" not in node:
            continue
        mesh = doc["meshes"][node["mesh"]]
        names = mesh.get("extras", {}).get("targetNames") or \
            mesh["primitives"][0].get("extras", {}).get("targetNames", [])
        for i, name in enumerate(names):
            shape = shape_of(name)
            expr = next((e for e in NAMES if e.lower() == name.lower()), None) \
                if expressions else None
            if ("s", shape) in claimed:
                shape = None
            if ("e", expr) in claimed:
                expr = None
            if shape or expr:
                defs.append((expr, shape, False, [(n, i, 1.0)]))
    for e, sh, _, _ in defs:
        claimed.update(x for x in (("e", e), ("s", sh)) if x[1])
    return defs


def claim(defs, claimed, expr, shape, binary, binds):
    """The first definition of an expression or a shape wins (`claimed`: ("e"|"s", name))."""
    expr = None if ("e", expr) in claimed else expr
    shape = None if ("s", shape) in claimed else shape
    if expr or shape:
        claimed.update(x for x in (("e", expr), ("s", shape)) if x[1])
        defs.append((expr, shape, binary, binds))


def vrm1_defs(doc):
    ex = doc["extensions"]["VRMC_vrm"]["expressions"]
    defs, claimed = [], set()
    for group in ("preset", "custom"):
        for name, d in ex.get(group, {}).items():
            claim(defs, claimed, name if name in NAMES else None, shape_of(name),
                  d.get("isBinary", False),
                  [(b["node"], b["index"], b["weight"]) for b in d.get("morphTargetBinds", [])])
    return defs + named_target_defs(doc, claimed, False)


VRM0_PRESET = {"aa": "a", "ih": "i", "ou": "u", "ee": "e", "oh": "o", "blink": "blink",
               "blinkLeft": "blink_l", "blinkRight": "blink_r", "lookUp": "lookup",
               "lookDown": "lookdown", "lookLeft": "lookleft", "lookRight": "lookright",
               "happy": "joy", "angry": "angry", "sad": "sorrow", "relaxed": "fun"}
VRM0_BONE = {"leftThumbMetacarpal": "leftThumbProximal",
             "leftThumbProximal": "leftThumbIntermediate",
             "rightThumbMetacarpal": "rightThumbProximal",
             "rightThumbProximal": "rightThumbIntermediate"}


def turn_around(doc, bin_chunk):
    """The model turned half a turn about Y (x, z -> -x, -z), as VRM 0.x models face -Z: node
    translations, vertex positions, normals and morph target offsets, and the inverse bind
    matrices' translations (the built-in avatar's are pure translations). Returns the new BIN."""
    data = bytearray(bin_chunk)
    vec3 = set()
    for mesh in doc["meshes"]:
        for prim in mesh["primitives"]:
            for key in ("POSITION", "NORMAL"):
                if key in prim["attributes"]:
                    vec3.add(prim["attributes"][key])
            for t in prim.get("targets", []):
                vec3.update(t.values())
    for a in vec3:
        acc = doc["accessors"][a]
        view = doc["bufferViews"][acc["bufferView"]]
        start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        stride = view.get("byteStride", 12)
        for i in range(acc["count"]):
            x, y, z = struct.unpack_from("<3f", data, start + i * stride)
            struct.pack_into("<3f", data, start + i * stride, -x, y, -z)
        if "min" in acc and "max" in acc:
            lo, hi = acc["min"], acc["max"]
            acc["min"] = [-hi[0], lo[1], -hi[2]]
            acc["max"] = [-lo[0], hi[1], -lo[2]]
    for skin in doc.get("skins", []):
        acc = doc["accessors"][skin["inverseBindMatrices"]]
        view = doc["bufferViews"][acc["bufferView"]]
        start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        for i in range(acc["count"]):
            m = list(struct.unpack_from("<16f", data, start + 64 * i))
            m[12], m[14] = -m[12], -m[14]
            struct.pack_into("<16f", data, start + 64 * i, *m)
    for node in doc["nodes"]:
        if "translation" in node:
            x, y, z = node["translation"]
            node["translation"] = [-x, y, -z]
    return bytes(data)


def make_vrm0(src, dst):
    """The built-in avatar as VRM 0.x (turned to face -Z, as VRM 0.x models do): humanBones as a
    list, expressions as blend shape groups
    (weights 0-100; blink's binds at 60, aa binary; surprised as a custom "Surprised"), then a
    Perfect Sync group per ARKit target named in UniVRM's capitalised spelling ("EyeBlinkLeft";
    jawOpen's bind at 80). Returns the definitions written."""
    doc, bin_chunk = read_glb(src)
    vrm = doc["extensions"].pop("VRMC_vrm")
    for k in ("VRMC_springBone", "VRMC_materials_mtoon"):
        doc["extensions"].pop(k, None)
    bones = [{"bone": VRM0_BONE.get(name, name), "node": b["node"]}
             for name, b in vrm["humanoid"]["humanBones"].items()]
    defs, groups, claimed = [], [], set()
    for group in ("preset", "custom"):
        for name, d in vrm["expressions"].get(group, {}).items():
            binds = [(b["node"], b["index"], b["weight"]) for b in d.get("morphTargetBinds", [])]
            scale = 0.6 if name == "blink" else 1.0
            binary = name == "aa"
            preset = VRM0_PRESET.get(name, "unknown")
            # A custom name is matched by name (any case).
            gname = name.upper() if preset != "unknown" else \
                ("Surprised" if name == "surprised" else name)
            groups.append({"name": gname, "presetName": preset, "isBinary": binary,
                           "binds": [{"mesh": doc["nodes"][n]["mesh"], "index": i,
                                      "weight": w * scale * 100} for n, i, w in binds]})
            claim(defs, claimed, name if name in NAMES else None,
                  shape_of(name) if preset == "unknown" else None, binary,
                  [(n, i, w * scale) for n, i, w in binds])
    face = next(n for n, node in enumerate(doc["nodes"]) if node.get("name") == "Face")
    names = doc["meshes"][doc["nodes"][face]["mesh"]]["extras"]["targetNames"]
    for i, name in enumerate(names):
        w = 0.8 if name == "jawOpen" else 1.0
        groups.append({"name": name[0].upper() + name[1:], "presetName": "unknown",
                       "binds": [{"mesh": doc["nodes"][face]["mesh"], "index": i,
                                  "weight": w * 100}]})
        claim(defs, claimed, None, shape_of(name), False, [(face, i, w)])
    bin_chunk = turn_around(doc, bin_chunk)
    doc["extensions"]["VRM"] = {"specVersion": "0.0", "exporterVersion": "face_glb_test",
                                "meta": {"title": "builtin as VRM 0.x"},
                                "humanoid": {"humanBones": bones},
                                "blendShapeMaster": {"blendShapeGroups": groups}}
    doc["extensionsUsed"] = ["VRM"] + [e for e in doc.get("extensionsUsed", [])
                                       if e not in ("VRMC_vrm", "VRMC_springBone",
                                                    "VRMC_materials_mtoon")]
    write_glb(dst, doc, bin_chunk)
    return defs + named_target_defs(doc, claimed, False)


def make_plain(src, dst):
    """The built-in avatar without VRM, its targets renamed "blendShape1.<name>" (eyeBlinkLeft
    as "ARKit_eyeBlinkLeft"): its morph targets' names only."""
    doc, bin_chunk = read_glb(src)
    doc.pop("extensions", None)
    doc.pop("extensionsUsed", None)
    for mesh in doc["meshes"]:
        names = mesh.get("extras", {}).get("targetNames")
        if names:
            mesh["extras"]["targetNames"] = [
                "ARKit_" + n if n == "eyeBlinkLeft" else "blendShape1." + n for n in names]
    write_glb(dst, doc, bin_chunk)
    return named_target_defs(doc, set(), True)


def convert(exe, poses, avatar, glb):
    r = subprocess.run([exe, "convert", poses, "--avatar", avatar, "-o", glb],
                       capture_output=True, text=True)
    check(r.returncode == 0, f"convert --avatar {os.path.basename(avatar)}: {r.stderr.strip()}")
    return r.returncode == 0


def face_moves_in_the_viewer(exe, work, glb, label, clip):
    """`avatarmap render` (three-vrm in headless Chromium, the viewer's render mode) of the
    .glb: frame 0 (no expression) and the clip's moving frame differ, and only in the head's
    region (the poses hold the body still). Skipped without chromium."""
    if not shutil.which("chromium"):
        print("chromium is missing: the viewer's rendering of the face is not checked")
        return
    try:
        from PIL import Image, ImageChops
    except ImportError:
        print("Pillow is missing: the viewer's rendering of the face is not checked")
        return
    stem = os.path.splitext(glb)[0]
    out = stem + ".mp4"
    t = MOVING_FRAME[clip] / FPS
    r = subprocess.run([exe, "render", glb, "-o", out, "--size", "480x640", "--fps", str(FPS),
                        "--stills", "0,%.6f" % t, "--quiet"],
                       capture_output=True, text=True)
    if r.returncode != 0 and "viewer's modules" in r.stderr:
        print("the viewer's modules are missing: the face's rendering is not checked")
        return
    check(r.returncode == 0, f"{label}: render the .glb: " + r.stderr.strip()[-300:])
    if r.returncode != 0:
        return
    a = Image.open(stem + "_t0.png").convert("RGB")
    b = Image.open(stem + "_t%g.png" % round(t, 6)).convert("RGB")
    diff = ImageChops.difference(a, b).convert("L").point(lambda v: 255 if v > 24 else 0)
    box = diff.getbbox()
    changed = sum(1 for v in diff.getdata() if v)
    print(f"{label}: rendered face: {changed} pixels changed, box {box}")
    check(box is not None, f"{label}: the face changes between a neutral frame and frame "
          f"{MOVING_FRAME[clip]}")
    if box:
        # The whole body is framed: the head is the top fifth of the avatar's height.
        check(box[3] < 0.35 * a.size[1], f"{label}: only the head changes (changed box {box})")


def main():
    exe, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    poses = {}
    for clip in CLIPS:
        poses[clip] = os.path.join(work, f"face_{clip}.pose.jsonl")
        write_poses(poses[clip], clip)
    builtin = os.path.join(work, "builtin.vrm")
    r = subprocess.run([exe, "avatar", "-o", builtin], capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stderr)
        return 1
    vrm0 = os.path.join(work, "builtin0.vrm")
    plain = os.path.join(work, "plain.glb")
    avatars = [("VRM 1.0 (built-in)", "vrm1", builtin, vrm1_defs(read_glb(builtin)[0])),
               ("VRM 0.x (built-in rewritten, Perfect Sync)", "vrm0", vrm0,
                make_vrm0(builtin, vrm0)),
               ("plain glTF (prefixed ARKit names)", "plain", plain, make_plain(builtin, plain))]
    for label, key, avatar, defs in avatars:
        src_doc = read_glb(avatar)[0]
        for clip in CLIPS:
            expected = expected_clip(defs, src_doc, clip)
            if key == "plain" and clip == "expr":
                # No expression definitions, no shapes in the clip: joints only.
                check(not any(expected), "plain glTF: the expressions bind nothing")
            glb = os.path.join(work, f"{key}_{clip}.glb")
            if not convert(exe, poses[clip], avatar, glb):
                continue
            if any(expected[0]) or any(any(e) for e in expected):
                check_glb(f"{label}, {clip} clip", glb, expected, src_doc)
                if key != "plain":
                    face_moves_in_the_viewer(exe, work, glb, f"{label}, {clip} clip", clip)
            else:
                doc, _ = read_glb(glb)
                paths = [c["target"]["path"] for a in doc.get("animations", [])
                         for c in a["channels"]]
                check("weights" not in paths and paths, f"{label}, {clip}: joints only")
                validate(f"{label}, {clip} clip (joints only)", glb)

    # A face that moves from landmarks: `synth` (the scripted motion: blinks, talking) solved and
    # converted onto both avatars, as `animate` converts what it captures. The solver's
    # blendshapes or expressions must reach the face: some target's weight moves by 0.1 or more.
    synth = os.path.join(work, "synth.landmarks.jsonl")
    r = subprocess.run([exe, "synth", "-o", synth, "--seconds", "3"], capture_output=True,
                       text=True)
    check(r.returncode == 0, "synth: " + r.stderr.strip()[-300:])
    for label, key, avatar, _ in avatars[:2]:
        glb = os.path.join(work, f"{key}_synth.glb")
        if r.returncode != 0 or not convert(exe, synth, avatar, glb):
            continue
        doc, bin_chunk = read_glb(glb)
        anim = doc["animations"][0]
        spans = {}
        for c in anim["channels"]:
            if c["target"]["path"] != "weights":
                continue
            n = target_count(doc, c["target"]["node"])
            names = doc["meshes"][doc["nodes"][c["target"]["node"]]["mesh"]]["extras"][
                "targetNames"]
            out = floats(doc, bin_chunk, anim["samplers"][c["sampler"]]["output"])
            for t in range(n):
                col = out[t::n]
                spans[names[t]] = max(col) - min(col)
        moving = sorted((v, k) for k, v in spans.items() if v >= 0.1)
        print(f"{label}, synth landmarks: {len(moving)} of {len(spans)} targets move by 0.1 or "
              f"more (largest: {', '.join(f'{k} {v:.2f}' for v, k in moving[-4:])})")
        check(moving, f"{label}, synth landmarks: the face moves")
        validate(f"{label}, synth landmarks", glb, morphs=True)

    data = os.environ.get("AVATARMAP_TEST_DATA")
    shared = ["vrm1_spec_expressions.vrm", "vrm1_debug_robot.vrm", "vrm0_sphere.vrm"]
    if data and os.path.isdir(os.path.join(data, "avatars")):
        for name in shared:
            path = os.path.join(data, "avatars", name)
            if not os.path.exists(path):
                print(f"{name} is missing: skipped")
                continue
            glb = os.path.join(work, "shared_" + name.replace(".vrm", ".glb"))
            if convert(exe, poses["arkit"], path, glb):
                doc, _ = read_glb(glb)
                paths = [c["target"]["path"] for a in doc.get("animations", [])
                         for c in a["channels"]]
                check("weights" not in paths and paths, f"{name} (no morph binds): joints only")
                validate(f"{name} (no morph binds)", glb, source=path)
    else:
        print("AVATARMAP_TEST_DATA not set: the shared avatars without morph binds are skipped")

    if failures:
        print(f"{len(failures)} failure(s)")
        return 1
    print("face .glb: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
