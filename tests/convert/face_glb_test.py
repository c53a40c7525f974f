#!/usr/bin/env python3
"""The avatar's face in the animated .glb (docs/export.md, "The face"): `avatarmap convert
take.pose.jsonl --avatar A -o take.glb` writes morph-target weight channels driven by the
poses' expressions through the avatar's own definitions. The written GLB is read back here by
an independent reader (the GLB container, the JSON, raw accessor bytes) and checked against
weights computed here from the avatar file's definitions:

- VRM 1.0: the built-in avatar (`avatarmap avatar`), its VRMC_vrm expressions.
- VRM 0.x: the same avatar rewritten here as VRM 0.x (blendShapeMaster, bind weights 0-100,
  preset names a/i/u/e/o/blink/blink_l..., one group isBinary, bind weights other than 100).
- plain glTF: the same avatar without VRM, its mesh.extras.targetNames only.
- an avatar whose expressions bind no morph target (the shared vrm1_spec_expressions.vrm,
  when $AVATARMAP_TEST_DATA is set): joints only, no error.

With node and npm's gltf-validator (Khronos's validator; NODE_PATH naming its node_modules)
each written file is also validated: no errors. Usage: face_glb_test.py AVATARMAP_EXE WORKDIR."""

import json
import os
import shutil
import struct
import subprocess
import sys

NAMES = ["blink", "blinkLeft", "blinkRight", "aa", "ih", "ou", "ee", "oh", "lookUp",
         "lookDown", "lookLeft", "lookRight", "browUpLeft", "browUpRight", "browDownLeft",
         "browDownRight"]
FPS = 30
# Per frame: expression values (others 0). Frame 2 sums blink and blinkLeft past 1 (clamped);
# frame 3 has a value above 1 (clamped) and aa at 0.4 (a binary expression reads 0).
FRAMES = [
    {},
    {"blink": 0.6, "aa": 0.3},
    {"blink": 0.8, "blinkLeft": 0.5, "aa": 0.9, "browUpLeft": 0.25},
    {"ih": 1.5, "aa": 0.4, "lookUp": 0.2},
]

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


def expected_weights(defs, doc, frame):
    """{node: [weights]} from definitions [(name, is_binary, [(node, index, weight)])]."""
    out = {}
    for name, binary, binds in defs:
        if name not in NAMES:
            continue
        v = min(max(frame.get(name, 0.0), 0.0), 1.0)
        if binary:
            v = 1.0 if v > 0.5 else 0.0
        for node, index, weight in binds:
            n = target_count(doc, node)
            if index >= n:
                continue
            w = out.setdefault(node, [0.0] * n)
            w[index] += v * weight
    return {k: [min(max(x, 0.0), 1.0) for x in w] for k, w in out.items()}


def write_poses(path):
    with open(path, "w") as f:
        f.write(json.dumps({"format": "avatarmap.pose", "version": 1, "fps": FPS}) + "\n")
        for i, e in enumerate(FRAMES):
            f.write(json.dumps({"t": i / FPS, "hips_position": [0, 0.95, 0],
                                "expressions": {k: e.get(k, 0.0) for k in NAMES}}) + "\n")


def check_glb(label, glb, defs, source_doc):
    doc, bin_chunk = read_glb(glb)
    anims = doc.get("animations", [])
    check(len(anims) == 1, f"{label}: one animation")
    anim = anims[0]
    channels = [c for c in anim["channels"] if c["target"]["path"] == "weights"]
    expected = [expected_weights(defs, source_doc, f) for f in FRAMES]
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
        check(len(times) == len(FRAMES) and
              all(abs(t - i / FPS) < 1e-5 for i, t in enumerate(times)),
              f"{label}: node {node} sampler times {times}")
        check(s.get("interpolation", "LINEAR") in ("LINEAR", "STEP"), f"{label}: interpolation")
        out = floats(doc, bin_chunk, s["output"])
        n = target_count(doc, node)
        check(len(out) == n * len(FRAMES), f"{label}: node {node} has {len(out)} weights for "
              f"{n} targets x {len(FRAMES)} frames")
        for f in range(len(FRAMES)):
            got = out[f * n:(f + 1) * n]
            want = expected[f][node]
            bad = [(t, g, w) for t, (g, w) in enumerate(zip(got, want)) if abs(g - w) > 1e-4]
            check(not bad, f"{label}: node {node} frame {f} (target, got, want): {bad[:4]}")
    nonzero = sum(1 for e in expected for w in e.values() for x in w if x > 0)
    check(nonzero >= 4, f"{label}: the fixture moves the face ({nonzero} non-zero weights)")
    validate(label, glb)


NODE_VALIDATE = """
const v = require('gltf-validator');
const data = require('fs').readFileSync(process.argv[1]);
v.validateBytes(new Uint8Array(data), {maxIssues: 0})
  .then(r => console.log(JSON.stringify(r)))
  .catch(e => { console.error(String(e)); process.exit(2); });
"""


def validate(label, glb):
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
    print(f"{label}: glTF validator: {issues['numErrors']} errors, {issues['numWarnings']} "
          f"warnings, {issues['numInfos']} infos, {issues['numHints']} hints")
    for m in issues.get("messages", []):
        if m.get("severity", 9) <= 1:
            print(f"    {m.get('code')}: {m.get('message')} ({m.get('pointer', '')})")
    check(issues["numErrors"] == 0, f"{label}: glTF validator errors")


def vrm1_defs(doc):
    ex = doc["extensions"]["VRMC_vrm"]["expressions"]
    defs = []
    for group in ("preset", "custom"):
        for name, d in ex.get(group, {}).items():
            defs.append((name, d.get("isBinary", False),
                         [(b["node"], b["index"], b["weight"])
                          for b in d.get("morphTargetBinds", [])]))
    return defs


VRM0_PRESET = {"aa": "a", "ih": "i", "ou": "u", "ee": "e", "oh": "o", "blink": "blink",
               "blinkLeft": "blink_l", "blinkRight": "blink_r", "lookUp": "lookup",
               "lookDown": "lookdown", "lookLeft": "lookleft", "lookRight": "lookright"}
VRM0_BONE = {"leftThumbMetacarpal": "leftThumbProximal",
             "leftThumbProximal": "leftThumbIntermediate",
             "rightThumbMetacarpal": "rightThumbProximal",
             "rightThumbProximal": "rightThumbIntermediate"}


def make_vrm0(src, dst):
    """The built-in avatar as VRM 0.x: humanBones as a list, expressions as blend shape groups
    (weights 0-100); blink's binds at 60, aa binary. Returns the definitions written."""
    doc, bin_chunk = read_glb(src)
    vrm = doc["extensions"].pop("VRMC_vrm")
    for k in ("VRMC_springBone", "VRMC_materials_mtoon"):
        doc["extensions"].pop(k, None)
    bones = [{"bone": VRM0_BONE.get(name, name), "node": b["node"]}
             for name, b in vrm["humanoid"]["humanBones"].items()]
    defs, groups = [], []
    for name, _, binds in vrm1_defs(doc | {"extensions": {"VRMC_vrm": vrm}}):
        scale = 0.6 if name == "blink" else 1.0
        binary = name == "aa"
        groups.append({"name": name.upper(), "presetName": VRM0_PRESET.get(name, "unknown"),
                       "isBinary": binary,
                       "binds": [{"mesh": doc["nodes"][n]["mesh"], "index": i,
                                  "weight": w * scale * 100}
                                 for n, i, w in binds]})
        defs.append((name, binary, [(n, i, w * scale) for n, i, w in binds]))
    # The custom names are matched by name (any case): keep them as the proxy spells them.
    for g, (name, _, _) in zip(groups, defs):
        if g["presetName"] == "unknown":
            g["name"] = name
    doc["extensions"]["VRM"] = {"specVersion": "0.0", "exporterVersion": "face_glb_test",
                                "meta": {"title": "builtin as VRM 0.x"},
                                "humanoid": {"humanBones": bones},
                                "blendShapeMaster": {"blendShapeGroups": groups}}
    doc["extensionsUsed"] = ["VRM"] + [e for e in doc.get("extensionsUsed", [])
                                       if e not in ("VRMC_vrm", "VRMC_springBone",
                                                    "VRMC_materials_mtoon")]
    write_glb(dst, doc, bin_chunk)
    return defs


def make_plain(src, dst):
    """The built-in avatar without VRM: its morph targets' names only."""
    doc, bin_chunk = read_glb(src)
    doc.pop("extensions", None)
    doc.pop("extensionsUsed", None)
    write_glb(dst, doc, bin_chunk)
    defs = []
    for n, node in enumerate(doc["nodes"]):
        if "mesh" not in node:
            continue
        names = doc["meshes"][node["mesh"]].get("extras", {}).get("targetNames", [])
        for i, name in enumerate(names):
            defs.append((name, False, [(n, i, 1.0)]))
    return defs


def convert(exe, poses, avatar, glb):
    r = subprocess.run([exe, "convert", poses, "--avatar", avatar, "-o", glb],
                       capture_output=True, text=True)
    check(r.returncode == 0, f"convert --avatar {os.path.basename(avatar)}: {r.stderr.strip()}")
    return r.returncode == 0


def face_moves_in_the_viewer(exe, work, glb):
    """`avatarmap render` (three-vrm in headless Chromium, the viewer's render mode) of the
    VRM 1.0 .glb: frame 0 (no expression) and frame 2 (blink, aa) differ, and only in the
    head's region (the poses hold the body still). Skipped without chromium."""
    if not shutil.which("chromium"):
        print("chromium is missing: the viewer's rendering of the face is not checked")
        return
    try:
        from PIL import Image, ImageChops
    except ImportError:
        print("Pillow is missing: the viewer's rendering of the face is not checked")
        return
    out = os.path.join(work, "face.mp4")
    r = subprocess.run([exe, "render", glb, "-o", out, "--size", "480x640", "--fps", str(FPS),
                        "--stills", "0,%.6f" % (2 / FPS), "--quiet"],
                       capture_output=True, text=True)
    if r.returncode != 0 and "viewer's modules" in r.stderr:
        print("the viewer's modules are missing: the face's rendering is not checked")
        return
    check(r.returncode == 0, "render the .glb: " + r.stderr.strip()[-300:])
    if r.returncode != 0:
        return
    stem = os.path.join(work, "face")
    a = Image.open(stem + "_t0.png").convert("RGB")
    b = Image.open(stem + "_t%g.png" % round(2 / FPS, 6)).convert("RGB")
    box = ImageChops.difference(a, b).convert("L").point(lambda v: 255 if v > 24 else 0).getbbox()
    check(box is not None, "the face changes between a neutral frame and blink + aa")
    if box:
        # The whole body is framed: the head is the top fifth of the avatar's height.
        check(box[3] < 0.35 * a.size[1], f"only the head changes (changed box {box})")


def main():
    exe, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    poses = os.path.join(work, "face.pose.jsonl")
    write_poses(poses)
    builtin = os.path.join(work, "builtin.vrm")
    r = subprocess.run([exe, "avatar", "-o", builtin], capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stderr)
        return 1
    src_doc, _ = read_glb(builtin)

    glb = os.path.join(work, "vrm1.glb")
    if convert(exe, poses, builtin, glb):
        check_glb("VRM 1.0 (built-in)", glb, vrm1_defs(src_doc), src_doc)
        face_moves_in_the_viewer(exe, work, glb)

    vrm0 = os.path.join(work, "builtin0.vrm")
    defs0 = make_vrm0(builtin, vrm0)
    glb = os.path.join(work, "vrm0.glb")
    if convert(exe, poses, vrm0, glb):
        check_glb("VRM 0.x (built-in rewritten)", glb, defs0, read_glb(vrm0)[0])

    plain = os.path.join(work, "plain.glb")
    defs_plain = make_plain(builtin, plain)
    glb = os.path.join(work, "plain_out.glb")
    if convert(exe, poses, plain, glb):
        check_glb("plain glTF targetNames", glb, defs_plain, read_glb(plain)[0])

    data = os.environ.get("AVATARMAP_TEST_DATA")
    shared = os.path.join(data, "avatars", "vrm1_spec_expressions.vrm") if data else ""
    if shared and os.path.exists(shared):
        glb = os.path.join(work, "no_morphs.glb")
        if convert(exe, poses, shared, glb):
            doc, _ = read_glb(glb)
            paths = [c["target"]["path"] for a in doc.get("animations", []) for c in a["channels"]]
            check("weights" not in paths and paths, "no morph binds: joints only")
            validate("vrm1_spec_expressions (no morph binds)", glb)
    else:
        print("AVATARMAP_TEST_DATA not set: the shared avatar without morph binds is skipped")

    if failures:
        print(f"{len(failures)} failure(s)")
        return 1
    print("face .glb: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
