#!/usr/bin/env bash
# Remakes the seeds of the avatar, VRMA, BVH, tfjs and resampler fuzz targets that we made
# ourselves (tools/fuzz/corpus/{avatar,vrma,bvh,tfjs,resample}): small hand-written glTF/VRM
# texts and a hand-built .vrma (python3), and files written by our own writers through the
# CLI. Each stays under 20 kB. Real third-party files are never committed: tools/fuzz/run.sh
# adds them from $AVATARMAP_TEST_DATA at run time.
#   tools/fuzz/make_seeds.sh path/to/avatarmap
set -euo pipefail
exe=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
corpus=$(cd "$(dirname "$0")" && pwd)/corpus
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$corpus"/{avatar,vrma,bvh,tfjs,resample}
cd "$work"

python3 - "$corpus" <<'EOF'
import json, random, struct, sys
corpus = sys.argv[1]
def dump(path, doc):
    open(path, "w").write(json.dumps(doc, separators=(",", ":")))

# A 17-bone humanoid: (VRM 1.0 name, parent, translation in metres).
bones = [("hips", -1, [0, 0.95, 0]), ("spine", 0, [0, 0.1, 0]), ("chest", 1, [0, 0.15, 0]),
         ("neck", 2, [0, 0.25, 0]), ("head", 3, [0, 0.1, 0]),
         ("leftUpperArm", 2, [0.2, 0.2, 0]), ("leftLowerArm", 5, [0.3, 0, 0]),
         ("leftHand", 6, [0.25, 0, 0]), ("rightUpperArm", 2, [-0.2, 0.2, 0]),
         ("rightLowerArm", 8, [-0.3, 0, 0]), ("rightHand", 9, [-0.25, 0, 0]),
         ("leftUpperLeg", 0, [0.1, -0.05, 0]), ("leftLowerLeg", 11, [0, -0.45, 0]),
         ("leftFoot", 12, [0, -0.42, 0]), ("rightUpperLeg", 0, [-0.1, -0.05, 0]),
         ("rightLowerLeg", 14, [0, -0.45, 0]), ("rightFoot", 15, [0, -0.42, 0])]
def nodes(name_of):
    out = []
    for i, (b, _, t) in enumerate(bones):
        n = {"name": name_of(b), "translation": t}
        children = [j for j, (_, p, _) in enumerate(bones) if p == i]
        if children: n["children"] = children
        out.append(n)
    return out

# VRM 1.0 (.gltf text): humanoid, expression presets and a custom one, one rotated joint.
vrm1 = {"asset": {"version": "2.0", "generator": "avatarmap fuzz seed"}, "scene": 0,
        "scenes": [{"nodes": [0]}], "nodes": nodes(lambda b: "J_" + b),
        "extensionsUsed": ["VRMC_vrm"],
        "extensions": {"VRMC_vrm": {
            "specVersion": "1.0",
            "meta": {"name": "seed", "authors": ["avatarmap"],
                     "licenseUrl": "https://vrm.dev/licenses/1.0/"},
            "humanoid": {"humanBones": {b: {"node": i} for i, (b, _, _) in enumerate(bones)}},
            "expressions": {"preset": {"happy": {}, "aa": {}, "blink": {}},
                            "custom": {"browUp": {}}}}}}
vrm1["nodes"][3]["rotation"] = [0, 0.0871557, 0, 0.9961947]
vrm1["nodes"][5]["scale"] = [1, 1, 1]
dump(corpus + "/avatar/vrm1_minimal.gltf", vrm1)

# VRM 0.x (.gltf text): humanBones array, blend shape groups, the hips given as a matrix.
vrm0 = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": nodes(lambda b: b[0].upper() + b[1:]), "extensionsUsed": ["VRM"],
        "extensions": {"VRM": {
            "specVersion": "0.0",
            "humanoid": {"humanBones": [{"bone": b, "node": i}
                                        for i, (b, _, _) in enumerate(bones)]},
            "blendShapeMaster": {"blendShapeGroups": [
                {"name": "Joy", "presetName": "joy"}, {"name": "A", "presetName": "a"},
                {"name": "Custom", "presetName": "unknown"}]}}}}
vrm0["nodes"][0]["matrix"] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0.95, 0, 1]
del vrm0["nodes"][0]["translation"]
dump(corpus + "/avatar/vrm0_minimal.gltf", vrm0)

# Plain glTF with Mixamo names in centimetres under a 0.01-scaled armature (auto-detected).
mixamo = {"hips": "Hips", "spine": "Spine", "chest": "Spine1", "neck": "Neck", "head": "Head",
          "leftUpperArm": "LeftArm", "leftLowerArm": "LeftForeArm", "leftHand": "LeftHand",
          "rightUpperArm": "RightArm", "rightLowerArm": "RightForeArm",
          "rightHand": "RightHand", "leftUpperLeg": "LeftUpLeg", "leftLowerLeg": "LeftLeg",
          "leftFoot": "LeftFoot", "rightUpperLeg": "RightUpLeg", "rightLowerLeg": "RightLeg",
          "rightFoot": "RightFoot"}
plain = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [17]}],
         "nodes": nodes(lambda b: "mixamorig:" + mixamo[b]) +
                  [{"name": "Armature", "children": [0], "scale": [0.01, 0.01, 0.01],
                    "extras": {"note": [1, {"a": [2]}]}}]}
for n in plain["nodes"][:17]: n["translation"] = [x * 100 for x in n["translation"]]
dump(corpus + "/avatar/mixamo_minimal.gltf", plain)

# A hand-built .vrma: a non-humanoid root above the hips, LINEAR, STEP and CUBICSPLINE
# samplers, an expression node.
times = [0.0, 0.5, 1.0]
rot = [0, 0, 0, 1, 0, 0.3826834, 0, 0.9238795, 0, 0.7071068, 0, 0.7071068]
trans = [0, 0.9, 0, 0, 0.85, 0.1, 0, 0.9, 0.2]
cubic = []
for k in range(3): cubic += [0, 0, 0, 0] + rot[4 * k:4 * k + 4] + [0, 0, 0, 0]
expr = [0, 0, 0, 0.5, 0, 0, 1, 0, 0]
buf, views = b"", []
for a in (times, rot, trans, cubic, expr):
    blob = struct.pack("<%df" % len(a), *a)
    views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(blob)})
    buf += blob
accessors = [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "SCALAR",
              "min": [0], "max": [1]},
             {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC4"},
             {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC3"},
             {"bufferView": 3, "componentType": 5126, "count": 9, "type": "VEC4"},
             {"bufferView": 4, "componentType": 5126, "count": 3, "type": "VEC3"}]
doc = {"asset": {"version": "2.0", "generator": "avatarmap fuzz seed"}, "scene": 0,
       "scenes": [{"nodes": [0, 4]}],
       "nodes": [{"name": "root", "children": [1], "rotation": [0, 1, 0, 0]},
                 {"name": "hips", "children": [2], "translation": [0, 0.9, 0]},
                 {"name": "spine", "children": [3], "translation": [0, 0.1, 0]},
                 {"name": "head", "translation": [0, 0.5, 0]}, {"name": "happy"}],
       "buffers": [{"byteLength": len(buf)}], "bufferViews": views, "accessors": accessors,
       "animations": [{"channels": [
           {"sampler": 0, "target": {"node": 2, "path": "rotation"}},
           {"sampler": 1, "target": {"node": 1, "path": "translation"}},
           {"sampler": 2, "target": {"node": 3, "path": "rotation"}},
           {"sampler": 3, "target": {"node": 4, "path": "translation"}}],
           "samplers": [{"input": 0, "output": 1, "interpolation": "LINEAR"},
                        {"input": 0, "output": 2, "interpolation": "STEP"},
                        {"input": 0, "output": 3, "interpolation": "CUBICSPLINE"},
                        {"input": 0, "output": 4}]}],
       "extensionsUsed": ["VRMC_vrm_animation"],
       "extensions": {"VRMC_vrm_animation": {
           "specVersion": "1.0",
           "humanoid": {"humanBones": {"hips": {"node": 1}, "spine": {"node": 2},
                                       "head": {"node": 3}}},
           "expressions": {"preset": {"happy": {"node": 4}}}}}}
j = json.dumps(doc, separators=(",", ":")).encode()
j += b" " * ((4 - len(j) % 4) % 4)
buf += b"\0" * ((4 - len(buf) % 4) % 4)
glb = (b"glTF" + struct.pack("<II", 2, 12 + 8 + len(j) + 8 + len(buf)) +
       struct.pack("<I", len(j)) + b"JSON" + j + struct.pack("<I", len(buf)) + b"BIN\0" + buf)
for d in ("avatar", "vrma"): open(corpus + "/" + d + "/handmade.vrma", "wb").write(glb)

# tfjs-models pairs: two plausible frames; one frame with a null, integers and a 4th value.
random.seed(8)
img = [[[round(320 + random.uniform(-100, 100), 3), round(240 + random.uniform(-150, 150), 3),
         round(random.uniform(-50, 50), 3)] for _ in range(33)] for _ in range(2)]
wld = [[[round(random.uniform(-0.5, 0.5), 4), round(random.uniform(-0.8, 0.8), 4),
         round(random.uniform(-0.3, 0.3), 4)] for _ in range(33)] for _ in range(2)]
open(corpus + "/tfjs/two_frames.txt", "w").write(json.dumps(img) + "\n===\n" + json.dumps(wld))
odd = [[[1, 2, 3, 0.9]] * 33]
odd[0][5] = [None, 2, 3]
open(corpus + "/tfjs/odd_values.txt", "w").write(
    json.dumps(odd) + "\n===\n" + json.dumps([[[0, 0, 0]] * 33]))

# Resampler: random bytes of a few lengths, and zeros.
for i, n in enumerate([48, 120, 240, 400]):
    open(corpus + "/resample/random_%d" % i, "wb").write(
        bytes(random.getrandbits(8) for _ in range(n)))
open(corpus + "/resample/zeros", "wb").write(bytes(200))
EOF

# A hand-written BVH: CRLF line ends, two roots, a joint without channels, an End Site.
printf 'HIERARCHY\r\nROOT a\r\n{\r\n OFFSET 0 0 0\r\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\r\n JOINT b\r\n {\r\n  OFFSET 0 1 0\r\n  CHANNELS 3 Xrotation Yrotation Zrotation\r\n  End Site\r\n  {\r\n   OFFSET 0 0.5 0\r\n  }\r\n }\r\n}\r\nROOT c\r\n{\r\n OFFSET 1 0 0\r\n CHANNELS 0\r\n}\r\nMOTION\r\nFrames: 2\r\nFrame Time: 0.0333333\r\n0 1 0 0 0 0 10 20 30\r\n1 1 0 90 -45 180 -10 -20 -30\r\n' \
  >"$corpus/bvh/two_roots_crlf.bvh"

# Our writers: two synthetic frames as .vrma and proxy .bvh, onto the VRM 1.0 seed as .glb,
# onto the Mixamo seed as a rig .bvh.
"$exe" synth -o s.landmarks.jsonl --seconds 0.04 --fps 30 --no-face >/dev/null
"$exe" convert s.landmarks.jsonl -o "$corpus/vrma/writer.vrma" >/dev/null
"$exe" convert s.landmarks.jsonl -o "$corpus/bvh/writer.bvh" >/dev/null
"$exe" synth -o s3.landmarks.jsonl --seconds 0.1 --fps 30 --no-face >/dev/null
"$exe" convert s3.landmarks.jsonl -o "$corpus/avatar/vrm1_writer.glb" \
  --avatar "$corpus/avatar/vrm1_minimal.gltf" >/dev/null
"$exe" convert s3.landmarks.jsonl -o "$corpus/bvh/writer_rig.bvh" \
  --avatar "$corpus/avatar/mixamo_minimal.gltf" >/dev/null
ls -l "$corpus"/{avatar,vrma,bvh,tfjs,resample}
