// Loads avatarmap's files with three.js and @pixiv/three-vrm (the libraries the viewer uses) in
// Node and checks what a viewer would see. Usage (NODE_PATH = a folder with node_modules):
//   node three_vrm_check.mjs AVATAR.vrm ANIMATED.glb OURS.json
// AVATAR.vrm: the built-in avatar; it must load as VRM 1.0 with all 55 humanoid bones, the
// expressions the project promises, and `blink` must close both eyes (morph weights 1).
// ANIMATED.glb: the avatar with a motion (`convert --avatar AVATAR.vrm --fps 30`); OURS.json:
// avatarmap's own joint positions of that file (`convert --dump-positions`). three.js plays the
// animation; every bone's world position at several frames must match ours within 1 mm.
// Prints one line per check; exits 1 on a failure.
import fs from 'fs';
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { VRMLoaderPlugin } from '@pixiv/three-vrm';

function load(file) {
  const b = fs.readFileSync(file);
  const loader = new GLTFLoader();
  loader.register((parser) => new VRMLoaderPlugin(parser));
  return new Promise((resolve, reject) =>
    loader.parse(b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength), '', resolve, reject));
}

let failed = false;
const check = (ok, what) => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failed = true;
};

const [avatarFile, animatedFile, oursFile] = process.argv.slice(2);
const avatar = await load(avatarFile);
const vrm = avatar.userData.vrm;
check(vrm && vrm.meta.metaVersion === '1', `${avatarFile}: three-vrm reads it as VRM 1.0`);
const bones = Object.keys(vrm.humanoid.humanBones).filter((b) => vrm.humanoid.getRawBoneNode(b));
check(bones.length === 55, `${avatarFile}: ${bones.length} humanoid bones (55 expected)`);
const names = vrm.expressionManager.expressions.map((e) => e.expressionName);
const wanted = ['blink', 'blinkLeft', 'blinkRight', 'aa', 'ih', 'ou', 'ee', 'oh', 'happy',
  'angry', 'sad', 'relaxed', 'surprised', 'browUpLeft', 'browUpRight', 'browDownLeft',
  'browDownRight'];
const missing = wanted.filter((n) => !names.includes(n));
check(missing.length === 0, `${avatarFile}: expressions (missing: ${missing.join(',') || 'none'})`);
let face = null;
avatar.scene.traverse((o) => { if (o.isMesh && o.morphTargetDictionary) face = o; });
vrm.expressionManager.setValue('blink', 1);
vrm.update(0);
const dict = face ? face.morphTargetDictionary : {};
const closed = face && face.morphTargetInfluences[dict.eyeBlinkLeft] === 1 &&
  face.morphTargetInfluences[dict.eyeBlinkRight] === 1;
check(closed, `${avatarFile}: blink = 1 closes both eyes (eyeBlinkLeft and eyeBlinkRight targets at 1)`);

const animated = await load(animatedFile);
const ours = JSON.parse(fs.readFileSync(oursFile, 'utf8'));
check(animated.animations.length === 1, `${animatedFile}: one animation`);
const mixer = new THREE.AnimationMixer(animated.scene);
mixer.clipAction(animated.animations[0]).play();
const nodes = {};
animated.scene.traverse((o) => { nodes[o.name] = o; });
let worst = 0, compared = 0;
const frames = ours.frames.length;
for (const f of [0, Math.floor(frames / 3), Math.floor((2 * frames) / 3), frames - 1]) {
  mixer.setTime(f / ours.fps);
  animated.scene.updateMatrixWorld(true);
  for (const [name, want] of Object.entries(ours.frames[f])) {
    if (!nodes[name]) continue;
    const p = new THREE.Vector3();
    nodes[name].getWorldPosition(p);
    worst = Math.max(worst, Math.hypot(p.x - want[0], p.y - want[1], p.z - want[2]));
    ++compared;
  }
}
check(compared >= 4 * 55 && worst < 1e-3,
  `${animatedFile}: ${compared} joint positions played by three.js, largest difference ` +
  `${(worst * 1000).toFixed(3)} mm (1 mm allowed)`);
process.exit(failed ? 1 : 0);
