// avatarmap's browser viewer (docs/viewer.md). Loads the avatar the server names in
// /config.json, then either applies the proxy poses that arrive on the WebSocket (one
// *.pose.jsonl line per message: VRM 1.0 normalised local rotations [x, y, z, w], the hips
// position in metres, expression weights) or plays an animation itself: the server's .vrma clip,
// its *.pose.jsonl (fetched whole, shown by time stamps), or the avatar .glb's own glTF
// animation — or one opened or dropped on the page. The controls (play/pause, Space, timeline,
// speed, loop) drive the animation's time; a video the server names is kept at that time.
// Poses from the WebSocket win over the animation: the first that arrives stops it (except the
// server's own stream of the pose file the page plays itself).
//
// Several people: a message with a "slot" key (and "person", the person's id) is that slot's
// person's pose; a message without one is slot 0's. Slot 0 is the page's avatar; every other slot
// that gets a pose gets an avatar of its own (the same file, parsed again from the bytes fetched
// once: three-vrm cannot clone a VRM), posed by the newest pose of its slot. A person whose poses
// carry a root translation (hips_position X or Z not 0) stands where it says, from the same
// origin as the others (the first pose's hips); one without stands 1 m to the right per slot.
// Once a pose has carried a "slot", an avatar whose slot got no pose for 1.5 s is hidden until
// its slot gets one again (slot 0's too, unless it plays an animation); one person's is never.
// A message {"gone":true,"person":ID,"slot":K} (the person left the slot) hides it at once.
//
// For tests and tools: window.avatarmapViewer.state() says what the page shows,
// boneRotation(name, slot = 0) / rawBoneRotation(name, slot = 0) the normalised / raw local
// rotation of a bone of a slot's avatar ([x, y, z, w]; null when the slot has none), people()
// each slot's avatar ({slot, person, visible, loading, failed, posesApplied, x: its hips' world
// X}); ?hud=0 hides the text box and the control bar (a clean picture for
// screenshots; the controls still work); the page logs "avatarmap-viewer: first posed frame N
// ms" and sends {"first_posed_ms": N} to the server once it has drawn its first posed frame (N
// counted from the start of the page's navigation).
//
// Render mode (?render=1; docs/world-benchmark-rendered.md): a fixed camera from the URL, a plain
// background and floor, no WebSocket, no animation loop — a frame is drawn only when asked:
// window.avatarmapViewer.renderAt(t) (the clip at time t) or renderPose(pose) (one pose object or
// *.pose.jsonl line), each a promise resolved once the frame is on screen (for screenshots).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { VRMLoaderPlugin, VRMUtils } from '@pixiv/three-vrm';
import { VRMAnimationLoaderPlugin, createVRMAnimationClip } from '@pixiv/three-vrm-animation';

const params = new URLSearchParams(location.search);
const hudElement = document.getElementById('hud');
const renderMode = params.get('render') === '1';
if (params.get('hud') === '0' || renderMode) hudElement.style.display = 'none';
if (renderMode) document.body.classList.add('render');  // no controls, message or video
if (params.get('hud') === '0') document.body.classList.add('bare');  // no control bar either

// Render mode's URL parameters (all optional): w, h (canvas pixels, device pixel ratio 1),
// cam=x,y,z (metres, the avatar's world: Y up, floor Y = 0, the avatar faces +Z), either
// look=x,y,z or yaw/pitch (degrees: yaw 0 looks along -Z, positive turns left; pitch positive
// looks up), roll (degrees, positive turns the camera counterclockwise as it looks: the scene
// turns clockwise in the image), hfov (horizontal field of view, degrees; converted to three.js's
// vertical one by tan(v/2) = tan(h/2) * h/w) or vfov, bg and floorColor (RRGGBB), floor=0 (none),
// performerHips (metres: the performer's standing hips height; poses' hips positions are scaled
// by the avatar's rest hips height over it and placed absolutely, not relative to the first
// pose), marker=BONE[,BONE...] (a small magenta dot drawn on top at each bone, for tests).
// A malformed parameter keeps its default and is named in state.error; ready() then rejects.
const renderErrors = [];
function numberList(name, count, fallback) {
  const text = params.get(name);
  if (text === null) return fallback;
  const values = text.split(',').map(Number);
  if (values.length === count && values.every(Number.isFinite)) return values;
  renderErrors.push(`render mode: ${name}=${text} is not ${count} comma-separated numbers`);
  return fallback;
}
function number(name, fallback) {
  const text = params.get(name);
  if (text === null) return fallback;
  const value = Number(text);
  if (text.trim() !== '' && Number.isFinite(value)) return value;
  renderErrors.push(`render mode: ${name}=${text} is not a number`);
  return fallback;
}
function colour(name, fallback) {
  const text = params.get(name);
  return text !== null && /^[0-9a-fA-F]{6}$/.test(text) ? parseInt(text, 16) : fallback;
}
const render = renderMode ? {
  width: Math.round(number('w', 640)),
  height: Math.round(number('h', 360)),
  cam: numberList('cam', 3, [0, 1.4, 3.5]),
  look: numberList('look', 3, null),
  yaw: number('yaw', 0),
  pitch: number('pitch', 0),
  roll: number('roll', 0),
  hfov: number('hfov', null),
  vfov: number('vfov', null),
  background: colour('bg', 0xb4b8bd),
  floor: params.get('floor') !== '0',
  floorColour: colour('floorColor', 0x8c8f86),
  performerHips: number('performerHips', null),
  markers: (params.get('marker') || '').split(',').filter((m) => m),
} : null;

const state = {
  avatar: 'none',        // none | loading | ready | failed
  avatarName: '',
  mode: 'rest',          // rest | live | clip
  socket: 'closed',      // closed | connecting | open
  socketUrl: '',
  posesReceived: 0,
  posesApplied: 0,
  people: 0,             // avatars shown (slot 0's, the page's own, included)
  arkitTargets: 0,       // morph targets named after ARKit's shapes that poses drive directly
  arkitExpressions: 0,   // expressions named after ARKit's shapes (Perfect Sync clips)
  badMessages: 0,
  lastPoseT: null,       // t of the newest applied pose (seconds)
  clipName: '',
  clipTime: null,        // seconds into the clip
  clipDuration: null,
  clipKind: '',          // the animation the page plays: vrma | glb | poses ('' none)
  playing: false,        // the controls: playing or paused, speed, loop
  speed: 1,
  loop: true,
  videoName: '',         // the video beside the avatar ('' none), its state and time
  video: 'none',         // none | loading | ready | failed
  videoTime: null,
  message: '',           // the newest message shown above the controls
  firstPosedMs: null,
  frames: 0,
  error: renderErrors.join('; '),
  render: renderMode,
  camera: null,          // render mode: the camera used (position, quaternion, fovs, size)
  hipsScale: null,       // render mode: avatar metres per performer metre
};
window.avatarmapViewer = { state: () => ({ ...state }) };

// ---- scene ----------------------------------------------------------------------------------
const renderer = new THREE.WebGLRenderer({ antialias: true });
renderer.setPixelRatio(renderMode ? 1 : window.devicePixelRatio);
if (renderMode) renderer.setSize(render.width, render.height);
else renderer.setSize(window.innerWidth, window.innerHeight);
renderer.setClearColor(renderMode ? render.background : 0x1e2430);
renderer.outputColorSpace = THREE.SRGBColorSpace;
document.body.appendChild(renderer.domElement);

const scene = new THREE.Scene();
scene.add(new THREE.AmbientLight(0xffffff, 1.2));
const sun = new THREE.DirectionalLight(0xffffff, 2.0);
sun.position.set(0.5, 1.5, 2.0);
scene.add(sun);

const camera = new THREE.PerspectiveCamera(30, window.innerWidth / window.innerHeight, 0.05, 50);
camera.position.set(0, 1.2, 4.5);
const controls = renderMode ? null : new OrbitControls(camera, renderer.domElement);
if (controls) {
  controls.target.set(0, 1.0, 0);
  controls.update();
}
const markers = [];

// Render mode: the camera exactly as the URL says (no framing, no orbiting).
function placeRenderCamera() {
  const aspect = render.width / render.height;
  let vfov = render.vfov;
  if (render.hfov !== null) {
    vfov = THREE.MathUtils.radToDeg(
      2 * Math.atan(Math.tan(THREE.MathUtils.degToRad(render.hfov) / 2) / aspect));
  }
  if (vfov === null) vfov = 40;
  camera.fov = vfov;
  camera.aspect = aspect;
  camera.near = 0.05;
  camera.far = 100;
  camera.position.set(...render.cam);
  if (render.look) {
    camera.up.set(0, 1, 0);
    camera.lookAt(...render.look);
    camera.rotateZ(THREE.MathUtils.degToRad(render.roll));
  } else {
    const rad = THREE.MathUtils.degToRad;
    camera.rotation.set(rad(render.pitch), rad(render.yaw), rad(render.roll), 'YXZ');
  }
  camera.updateProjectionMatrix();
  camera.updateMatrixWorld(true);
  const hfov = THREE.MathUtils.radToDeg(
    2 * Math.atan(Math.tan(THREE.MathUtils.degToRad(vfov) / 2) * aspect));
  const q = camera.quaternion;
  state.camera = {
    position: camera.position.toArray(), quaternion: [q.x, q.y, q.z, q.w], vfov, hfov,
    width: render.width, height: render.height,
    focalPixels: render.height / 2 / Math.tan(THREE.MathUtils.degToRad(vfov) / 2),
  };
}

if (renderMode) {
  placeRenderCamera();
  if (render.floor) {
    const material = new THREE.MeshStandardMaterial({ color: render.floorColour, roughness: 1 });
    const floor = new THREE.Mesh(new THREE.PlaneGeometry(40, 40), material);
    floor.rotation.x = -Math.PI / 2;
    scene.add(floor);
    const grid = new THREE.GridHelper(40, 40, 0x6d7068, 0x6d7068);
    grid.position.y = 0.001;
    scene.add(grid);
  }
}

// The interactive page's canvas: the window, or its left part when a video is shown.
function layout() {
  if (renderMode) return;
  const width = videoElement.style.display === 'block' ? Math.round(window.innerWidth * 0.55)
                                                       : window.innerWidth;
  camera.aspect = width / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(width, window.innerHeight);
}
window.addEventListener('resize', layout);

// ---- avatar ---------------------------------------------------------------------------------
let vrm = null;
let restHipsY = 1.0;     // the avatar's hips height in its rest pose (normalised space)
let restHips = [0, 1, 0];
let mixer = null;
let clipAction = null;

// A .glb's own animation drives its morph targets ("weights" channels: the face). three-vrm's
// expression manager would set every morph target an expression binds on each vrm.update()
// (to 0: nothing sets the expressions), after the mixer has written them, and the mixer does
// not write a value again while it is unchanged: so the avatar's expressions are left out.
function glbOwnsTheFace(v) {
  v.expressionManager = undefined;
  if (v.lookAt) v.lookAt.autoUpdate = false;
}

function gltfLoader() {
  const loader = new GLTFLoader();
  loader.register((parser) => new VRMLoaderPlugin(parser));
  loader.register((parser) => new VRMAnimationLoaderPlugin(parser));
  return loader;
}

// Frames the avatar from the front (it faces +Z after rotateVRM0), with room above the head for
// raised hands and on both sides for a T-pose.
function frameAvatar() {
  vrm.scene.updateMatrixWorld(true);
  const box = new THREE.Box3().setFromObject(vrm.scene);
  const height = Math.max(0.2, box.max.y - box.min.y);
  const centreY = box.min.y + 0.55 * height;
  const visible = 1.45 * height;
  const fov = THREE.MathUtils.degToRad(camera.fov);
  const fitHeight = visible / 2 / Math.tan(fov / 2);
  const fitWidth = (1.3 * height) / 2 / Math.tan(fov / 2) / Math.max(0.2, camera.aspect);
  const distance = Math.max(fitHeight, fitWidth);
  camera.position.set(0, centreY, distance);
  controls.target.set(0, centreY, 0);
  controls.update();
}

// Render mode's test markers: a small magenta dot at each named bone, drawn over everything.
function addMarkers() {
  for (const m of markers) m.parent?.remove(m);
  markers.length = 0;
  for (const name of render.markers) {
    const node = vrm.humanoid.getNormalizedBoneNode(name);
    if (!node) continue;
    const dot = new THREE.Mesh(new THREE.SphereGeometry(0.012, 12, 8),
                               new THREE.MeshBasicMaterial({ color: 0xff00ff, depthTest: false }));
    dot.renderOrder = 10;
    node.add(dot);
    markers.push(dot);
  }
}

// `animated`: the file is an avatar with its own glTF animation (`avatarmap convert -o x.glb`),
// played by the controls on the raw bones.
async function loadAvatar(url, name, animated = false) {
  state.avatar = 'loading';
  state.avatarName = name;
  try {
    const gltf = await gltfLoader().loadAsync(url);
    const loaded = gltf.userData.vrm;
    if (!loaded) throw new Error(`${name} is not a VRM avatar (no VRM extension)`);
    if (animated && !gltf.animations.length) throw new Error(`${name} holds no glTF animation`);
    if (vrm) {
      scene.remove(vrm.scene);
      VRMUtils.deepDispose(vrm.scene);
    }
    if (!renderMode && (player.kind === 'glb' || animated)) stopAnimation();
    VRMUtils.removeUnnecessaryVertices(gltf.scene);
    VRMUtils.rotateVRM0(loaded);  // VRM 0.x faces -Z: turn it to face +Z as VRM 1.0 does
    vrm = loaded;
    scene.add(vrm.scene);
    mainBody.face = findArkitTargets(vrm);
    state.arkitTargets = mainBody.face.targets.length;
    state.arkitExpressions = mainBody.face.expressions.size;
    forgetPeople(url);  // the other slots' avatars are this file's too, loaded when needed
    const rest = vrm.humanoid.normalizedRestPose.hips?.position ?? [0, 1, 0];
    restHips = rest;
    restHipsY = Math.max(0.1, rest[1]);
    standingHipsY = 0;
    firstHips = null;
    if (renderMode) addMarkers();
    else frameAvatar();
    state.avatar = 'ready';
    state.error = '';
    if (renderMode) {
      if (config.clip) await loadClip(config.clip, config.clip_name || 'clip');
    } else if (animated) {
      vrm.humanoid.autoUpdateHumanBones = false;  // the animation drives the raw bones
      glbOwnsTheFace(vrm);
      mixer = new THREE.AnimationMixer(vrm.scene);
      clipAction = mixer.clipAction(gltf.animations[0]);
      clipAction.play();
      startAnimation('glb', name, gltf.animations[0].duration, 0);
    } else if (clipSource) {
      await loadClip(clipSource.url, clipSource.name);  // the clip again, on this avatar
    } else if (player.kind === 'poses') {
      showAt(player.time);
    }
  } catch (e) {
    state.avatar = 'failed';
    state.error = `could not load the avatar ${name}: ${e.message ?? e}`;
    console.error('avatarmap-viewer:', state.error);
    if (!renderMode) showMessage(state.error);
  }
}

async function loadClip(url, name) {
  try {
    const gltf = await gltfLoader().loadAsync(url);
    const animation = gltf.userData.vrmAnimations?.[0];
    if (!animation) throw new Error(`${name} holds no VRM Animation`);
    const clip = createVRMAnimationClip(animation, vrm);
    if (!renderMode) {
      const keep = clipSource && clipSource.url === url ? player.time : 0;
      stopAnimation();
      clipSource = { url, name };
      player.time = keep;
    }
    mixer = new THREE.AnimationMixer(vrm.scene);
    clipAction = mixer.clipAction(clip);
    clipAction.setLoop(THREE.LoopRepeat, Infinity).play();
    if (renderMode) clipAction.paused = true;  // renderAt(t) sets the time
    state.clipName = name;
    state.clipDuration = clip.duration;
    if (state.mode !== 'live') state.mode = 'clip';
    if (!renderMode) startAnimation('vrma', name, clip.duration, 0, player.time);
  } catch (e) {
    state.error = `could not play ${name}: ${e.message ?? e}`;
    console.error('avatarmap-viewer:', state.error);
    if (!renderMode) showMessage(state.error);
  }
}

// ---- the interactive page's animation and its controls -------------------------------------
// One animation at a time: a .vrma clip or a .glb's animation (the mixer, stepped to the
// player's time) or a pose file (the newest pose at or before the time). Time runs from 0 (the
// first pose) to the duration; the video shows time + offset (a pose file's first t: its poses
// carry the video's time stamps).
const player = { kind: '', time: 0, duration: 0, offset: 0, playing: false, speed: 1, loop: true };
let clipSource = null;  // the .vrma playing ({url, name}): loaded again onto a new avatar
let poseTrack = null;   // the pose file playing: {poses, times}
const controlsElement = document.getElementById('controls');
const playButton = document.getElementById('play');
const timeline = document.getElementById('timeline');
const timeLabel = document.getElementById('time');
const speedSelect = document.getElementById('speed');
const loopBox = document.getElementById('loop');
const fileInput = document.getElementById('open-file');
const messageElement = document.getElementById('message');
const videoElement = document.getElementById('video');
let scrubbing = false;

function showMessage(text) {
  state.message = text;
  messageElement.textContent = text;
  messageElement.style.display = text ? 'block' : 'none';
}

function stopAnimation() {
  if (mixer) mixer.stopAllAction();
  mixer = null;
  clipAction = null;
  clipSource = null;
  poseTrack = null;
  if (vrm) vrm.humanoid.autoUpdateHumanBones = true;
  player.kind = '';
  state.clipKind = '';
  timeline.disabled = true;
  playButton.disabled = true;
}

function startAnimation(kind, name, duration, offset, time = 0) {
  Object.assign(player, { kind, duration: Math.max(0, duration), offset, time: 0 });
  player.playing = true;
  state.clipKind = kind;
  state.clipName = name;
  state.clipDuration = player.duration;
  state.mode = 'clip';
  timeline.max = String(player.duration);
  timeline.disabled = false;
  playButton.disabled = false;
  showMessage('');
  seek(time);
}

// Shows the animation at time t (seconds from its start), without changing play/pause.
function showAt(t) {
  if (!vrm || !player.kind) return;
  if (player.kind === 'poses') {
    const times = poseTrack.times;
    let lo = 0;
    let hi = times.length - 1;
    while (lo < hi) {  // the last pose whose time is <= t
      const mid = (lo + hi + 1) >> 1;
      if (times[mid] <= t) lo = mid;
      else hi = mid - 1;
    }
    firstHips = poseTrack.firstHips;
    standingHipsY = poseTrack.standing;
    applyPose(poseTrack.poses[lo]);
  } else if (clipAction) {
    // LoopRepeat wraps a time of exactly the duration to 0: the end shows the last key.
    clipAction.time = Math.min(t, Math.max(0, player.duration - 1e-6));
    mixer.update(0);
  }
  state.clipTime = t;
}

function seek(t) {
  player.time = Math.min(Math.max(0, Number(t) || 0), player.duration);
  showAt(player.time);
}

function setPlaying(playing) {
  if (!player.kind) return;
  if (playing && !player.loop && player.time >= player.duration) player.time = 0;
  player.playing = playing;
}

// Advances the player by a frame's wall-clock seconds.
function advance(delta) {
  if (!player.playing || !player.kind) return;
  let t = player.time + delta * player.speed;
  if (t >= player.duration) {
    if (player.loop && player.duration > 0) t %= player.duration;
    else {
      t = player.duration;
      player.playing = false;
    }
  }
  player.time = t;
  showAt(t);
}

// Parses a *.pose.jsonl text (the header line, if any, gives the rate that spaces poses whose
// t does not increase, as `view`'s player does) and plays it.
function loadPoses(text, name) {
  const poses = [];
  let fps = 30;
  for (const line of text.split('\n')) {
    if (!line.trim()) continue;
    let value;
    try {
      value = JSON.parse(line);
    } catch (e) {
      throw new Error(`${name} line ${poses.length + 1}: not JSON (${e.message})`);
    }
    if (typeof value.format === 'string') {
      if (value.fps > 0) fps = value.fps;
    } else if (typeof value.t === 'number' && Number.isFinite(value.t)) {
      poses.push(value);
    }
  }
  if (!poses.length) throw new Error(`${name} holds no poses`);
  const times = new Float64Array(poses.length);
  const t0 = poses[0].t;
  let standing = 0;
  for (let i = 0; i < poses.length; i++) {
    const t = poses[i].t - t0;
    times[i] = i === 0 ? 0 : t > times[i - 1] ? t : times[i - 1] + 1 / fps;
    const h = poses[i].hips_position;
    if (Array.isArray(h) && Number.isFinite(h[1])) standing = Math.max(standing, h[1]);
  }
  stopAnimation();
  // Hips: scaled by the whole file's standing height, relative to its first pose, so that any
  // time shows the same pose however it is reached.
  const h0 = poses[0].hips_position;
  poseTrack = {
    poses, times, firstHips: Array.isArray(h0) && h0.length === 3 ? h0 : null,
    standing: Math.min(2.5, Math.max(standing, 0.3)),
  };
  startAnimation('poses', name, times[times.length - 1], t0);
}

async function loadPosesFrom(url, name) {
  try {
    const response = await fetch(url, { cache: 'no-store' });
    if (!response.ok) throw new Error(`HTTP ${response.status}`);
    loadPoses(await response.text(), name);
  } catch (e) {
    state.error = `could not play ${name}: ${e.message ?? e}`;
    showMessage(state.error);
  }
}

// The video beside the avatar: fetched whole into a blob (the server answers no Range
// requests; a blob seeks anywhere).
async function loadVideo(url, name) {
  state.video = 'loading';
  state.videoName = name;
  try {
    const response = await fetch(url);
    if (!response.ok) throw new Error(`HTTP ${response.status}`);
    videoElement.src = URL.createObjectURL(await response.blob());
    videoElement.style.display = 'block';
    layout();
    await new Promise((resolve, reject) => {
      videoElement.onloadeddata = resolve;
      videoElement.onerror = () => reject(new Error('the browser cannot decode it'));
    });
    state.video = 'ready';
  } catch (e) {
    state.video = 'failed';
    showMessage(`could not show the video ${name}: ${e.message ?? e}`);
  }
}

// Keeps the video at the animation's time: played along at the same speed while playing,
// sought while paused or when it drifts by more than 0.15 s.
function syncVideo() {
  if (state.video !== 'ready') return;
  state.videoTime = videoElement.currentTime;
  if (!player.kind) return;
  const end = Number.isFinite(videoElement.duration) ? videoElement.duration : Infinity;
  const target = Math.min(Math.max(0, player.time + player.offset), end);
  const playing = player.playing && !scrubbing && target < end;
  if (videoElement.playbackRate !== player.speed) videoElement.playbackRate = player.speed;
  if (playing && videoElement.paused) videoElement.play().catch(() => {});
  if (!playing && !videoElement.paused) videoElement.pause();
  const drift = Math.abs(videoElement.currentTime - target);
  if (!videoElement.seeking && drift > (playing ? 0.15 : 0.02)) videoElement.currentTime = target;
}

function updateControls() {
  state.playing = player.playing;
  state.speed = player.speed;
  state.loop = player.loop;
  playButton.textContent = player.playing ? 'Pause' : 'Play';
  if (!player.kind) {
    timeLabel.textContent = '–';
    return;
  }
  if (!scrubbing) timeline.value = String(player.time);
  timeLabel.textContent = `${player.time.toFixed(2)} / ${player.duration.toFixed(2)} s`;
}

// Opens a file the user chose or dropped, by its name.
function openFile(file) {
  const name = file.name;
  const lower = name.toLowerCase();
  const url = URL.createObjectURL(file);
  if (lower.endsWith('.vrm')) return loadAvatar(url, name);
  if (lower.endsWith('.glb')) return loadAvatar(url, name, true);
  if (lower.endsWith('.vrma')) {
    if (!vrm) return showMessage(`open an avatar (.vrm) before the clip ${name}`);
    return loadClip(url, name);
  }
  if (lower.endsWith('.jsonl')) {
    return file.text().then((text) => {
      try {
        loadPoses(text, name);
      } catch (e) {
        showMessage(`could not play ${name}: ${e.message ?? e}`);
      }
    });
  }
  showMessage(`cannot open ${name}: open a .vrm (avatar), .vrma (clip), .glb (avatar with its ` +
              'animation) or .pose.jsonl (poses)');
  return null;
}

if (!renderMode) {
  const rotation = (node) => (node ? node.quaternion.toArray() : null);
  const slotVrm = (slot) => (slot ? bodies[slot]?.vrm : vrm);
  Object.assign(window.avatarmapViewer, {
    boneRotation: (name, slot = 0) => rotation(slotVrm(slot)?.humanoid.getNormalizedBoneNode(name)),
    rawBoneRotation: (name, slot = 0) => rotation(slotVrm(slot)?.humanoid.getRawBoneNode(name)),
    people: () => bodies.map((b, slot) => personOf(slot)).filter((p) => p),
  });
  document.getElementById('open').addEventListener('click', (e) => {
    e.currentTarget.blur();
    fileInput.click();
  });
  fileInput.addEventListener('change', () => {
    if (fileInput.files[0]) openFile(fileInput.files[0]);
    fileInput.value = '';
  });
  playButton.addEventListener('click', () => {
    playButton.blur();
    setPlaying(!player.playing);
  });
  timeline.addEventListener('pointerdown', () => { scrubbing = true; });
  timeline.addEventListener('pointerup', () => { scrubbing = false; });
  timeline.addEventListener('input', () => seek(timeline.value));
  timeline.addEventListener('change', () => { scrubbing = false; });
  speedSelect.addEventListener('change', () => {
    player.speed = Number(speedSelect.value) || 1;
    speedSelect.blur();
  });
  loopBox.addEventListener('change', () => {
    player.loop = loopBox.checked;
    loopBox.blur();
  });
  window.addEventListener('keydown', (e) => {
    if (e.code !== 'Space' && e.key !== ' ') return;
    e.preventDefault();
    setPlaying(!player.playing);
  });
}

// ---- ARKit's blendshapes (Perfect Sync) -----------------------------------------------------
// ARKit's 52 names (Apple's; the proxy pose's "blendshapes"), in ARKit's order.
const ARKIT_SHAPES = [
  'browDownLeft', 'browDownRight', 'browInnerUp', 'browOuterUpLeft', 'browOuterUpRight',
  'cheekPuff', 'cheekSquintLeft', 'cheekSquintRight', 'eyeBlinkLeft', 'eyeBlinkRight',
  'eyeLookDownLeft', 'eyeLookDownRight', 'eyeLookInLeft', 'eyeLookInRight', 'eyeLookOutLeft',
  'eyeLookOutRight', 'eyeLookUpLeft', 'eyeLookUpRight', 'eyeSquintLeft', 'eyeSquintRight',
  'eyeWideLeft', 'eyeWideRight', 'jawForward', 'jawLeft', 'jawOpen', 'jawRight', 'mouthClose',
  'mouthDimpleLeft', 'mouthDimpleRight', 'mouthFrownLeft', 'mouthFrownRight', 'mouthFunnel',
  'mouthLeft', 'mouthLowerDownLeft', 'mouthLowerDownRight', 'mouthPressLeft', 'mouthPressRight',
  'mouthPucker', 'mouthRight', 'mouthRollLower', 'mouthRollUpper', 'mouthShrugLower',
  'mouthShrugUpper', 'mouthSmileLeft', 'mouthSmileRight', 'mouthStretchLeft',
  'mouthStretchRight', 'mouthUpperUpLeft', 'mouthUpperUpRight', 'noseSneerLeft',
  'noseSneerRight', 'tongueOut'];
const ARKIT_BY_LOWER = new Map(ARKIT_SHAPES.map((n) => [n.toLowerCase(), n]));

// ARKit's shape a clip or morph target name stands for, as the .glb writer reads names
// (docs/export.md): any case, after a prefix up to the last '.' and then "ARKit_".
function arkitShapeOf(name) {
  let n = String(name).split('.').pop();
  if (n.length > 6 && n.toLowerCase().startsWith('arkit_')) n = n.slice(6);
  return ARKIT_BY_LOWER.get(n.toLowerCase()) ?? null;
}

// The avatar's ARKit shapes: its expressions named after one (Perfect Sync clips, set through
// three-vrm) and, for the shapes no expression claims, its morph targets named after one (the
// built-in avatar's 52; set directly after vrm.update(), so that they win over the expressions
// bound to the same targets, as in the .glb writer).
// Each avatar has its face: {expressions: shape -> expression name, targets: [{mesh, index,
// shape}], weights: the last pose's blendshapes while any is non-zero}.
function findArkitTargets(v) {
  const face = { expressions: new Map(), targets: [], weights: null };
  for (const e of v.expressionManager?.expressions ?? []) {
    const shape = arkitShapeOf(e.expressionName);
    if (shape && !face.expressions.has(shape)) face.expressions.set(shape, e.expressionName);
  }
  v.scene.traverse((o) => {
    if (!o.morphTargetDictionary || !o.morphTargetInfluences) return;
    for (const [name, index] of Object.entries(o.morphTargetDictionary)) {
      const shape = arkitShapeOf(name);
      if (shape && !face.expressions.has(shape)) face.targets.push({ mesh: o, index, shape });
    }
  });
  return face;
}

// Takes a pose's blendshapes: Perfect Sync expressions get their values now (before
// vrm.update()); the named targets in applyShapeTargets() after it. A pose without blendshapes,
// or with all of them 0, leaves the face to the expressions (and clears the targets once).
function takeBlendshapes(pose, v, face) {
  const b = pose.blendshapes;
  const active = b && typeof b === 'object' && Object.values(b).some((x) => Number(x) > 0);
  const expressions = v.expressionManager;
  if (!active) {
    if (face.weights) {
      for (const t of face.targets) t.mesh.morphTargetInfluences[t.index] = 0;
      // An ARKit-named expression that is also the proxy's (browDownLeft) keeps the pose's value.
      if (expressions)
        for (const name of face.expressions.values())
          expressions.setValue(name, clamp01(pose.expressions?.[name]));
    }
    face.weights = null;
    return;
  }
  face.weights = b;
  if (expressions)
    for (const [shape, name] of face.expressions) expressions.setValue(name, clamp01(b[shape]));
}

function clamp01(x) {
  const v = Number(x);
  return Number.isFinite(v) ? Math.min(1, Math.max(0, v)) : 0;
}

function applyShapeTargets(face = mainBody.face) {
  // A .vrma or .glb animation drives the face itself.
  if (!face.weights || player.kind === 'glb' || player.kind === 'vrma') return;
  for (const t of face.targets) t.mesh.morphTargetInfluences[t.index] = clamp01(face.weights[t.shape]);
}

// ---- poses ----------------------------------------------------------------------------------
let standingHipsY = 0;     // the highest hips height seen: the performer standing
let firstHips = null;      // the first pose's hips: horizontal motion is shown relative to it

// The page's own avatar (slot 0) as applyPose() takes it; other slots' avatars are makeBody()'s.
const mainBody = {
  get vrm() { return vrm; },
  get restHips() { return restHips; },
  get restHipsY() { return restHipsY; },
  get standingHipsY() { return standingHipsY; },
  set standingHipsY(y) { standingHipsY = y; },
  face: { expressions: new Map(), targets: [], weights: null },
  rooted: false,           // its poses carry a root translation (hips X or Z not 0)
  person: null,
  lastSeen: 0,
  posesApplied: 0,
};

// Poses `body`'s avatar (mainBody: the page's own, slot 0; else another slot's, makeBody()).
function applyPose(pose, body = mainBody) {
  const v = body.vrm;
  // VRM 0.x models keep their own axes under three-vrm's normalised bones: X and Z flip (as
  // three-vrm-animation does for VRMA clips).
  const flip = v.meta?.metaVersion === '0' ? -1 : 1;
  const bones = pose.bones ?? {};
  for (const name in bones) {
    const q = bones[name];
    const node = v.humanoid.getNormalizedBoneNode(name);
    if (!node || !Array.isArray(q) || q.length !== 4) continue;
    node.quaternion.set(flip * q[0], q[1], flip * q[2], q[3]);
  }
  const h = pose.hips_position;
  const hips = v.humanoid.getNormalizedBoneNode('hips');
  if (renderMode && hips && Array.isArray(h) && h.length === 3 && h.every(Number.isFinite)) {
    // Absolute placement: the performer's metres times the avatar's over the performer's hips.
    const s = render.performerHips > 0 ? body.restHipsY / render.performerHips : 1;
    state.hipsScale = s;
    hips.position.set(flip * h[0] * s, h[1] * s, flip * h[2] * s);
  } else if (hips && Array.isArray(h) && h.length === 3 && h.every(Number.isFinite)) {
    // Every slot's horizontal motion is relative to the same origin (the first pose's hips), so
    // that people keep their places relative to each other.
    if (!firstHips) firstHips = h;
    body.standingHipsY = Math.min(2.5, Math.max(body.standingHipsY, h[1], 0.3));
    const s = body.restHipsY / body.standingHipsY;  // performer metres -> avatar metres
    const rest = body.restHips;
    hips.position.set(rest[0] + flip * (h[0] - firstHips[0]) * s, h[1] * s,
                      rest[2] + flip * (h[2] - firstHips[2]) * s);
    if (h[0] !== 0 || h[2] !== 0) body.rooted = true;
  }
  const weights = pose.expressions ?? {};
  const expressions = v.expressionManager;
  if (expressions) {
    for (const name in weights) {
      if (expressions.getExpression(name)) expressions.setValue(name, Number(weights[name]) || 0);
    }
  }
  takeBlendshapes(pose, v, body.face);
  state.lastPoseT = typeof pose.t === 'number' ? pose.t : null;
  state.posesApplied++;
}

// ---- people: one avatar per slot ------------------------------------------------------------
const MAX_SLOTS = 8;          // the server's k_pose_server_slots
const HIDE_AFTER_MS = 1500;   // a slot without a pose for this long is hidden
const SLOT_SPACING = 1.0;     // metres between people whose poses carry no root translation
const newestMessages = new Array(MAX_SLOTS).fill(null);  // each slot's newest, parsed once a frame
const bodies = new Array(MAX_SLOTS).fill(null);  // slot -> its avatar's body (slot 0: mainBody)
bodies[0] = mainBody;
let avatarUrl = '';           // the page's avatar file: every slot's avatar is loaded from it
let avatarBytes = null;       // a promise of its bytes, fetched once for all the slots
let avatarGeneration = 0;     // counts the page's avatars: a slot loading an older one drops it
let peopleSeen = false;       // a pose carried a "slot": several people, slot 0 included, hide

// The slot a message is for, found without parsing it (only each slot's newest message is
// parsed): the "slot" key the server writes last; none = slot 0; -1 = out of range.
function slotOf(text) {
  const at = text.lastIndexOf('"slot":');
  if (at < 0) return 0;
  const slot = parseInt(text.slice(at + 7, at + 12), 10);
  return Number.isInteger(slot) && slot >= 0 && slot < MAX_SLOTS ? slot : -1;
}

function makeBody(v) {
  const rest = v.humanoid.normalizedRestPose.hips?.position ?? [0, 1, 0];
  return {
    vrm: v, restHips: rest, restHipsY: Math.max(0.1, rest[1]), standingHipsY: 0,
    face: findArkitTargets(v), rooted: false, person: null, lastSeen: 0,
    posesApplied: 0,
  };
}

// The page's avatar changed (or is loading): the other slots' avatars go, to be loaded again
// from `url` when their slots next get a pose.
function forgetPeople(url) {
  avatarGeneration++;
  avatarUrl = url;
  avatarBytes = null;
  for (let slot = 1; slot < MAX_SLOTS; slot++) {
    const body = bodies[slot];
    if (body?.vrm) {
      scene.remove(body.vrm.scene);
      VRMUtils.deepDispose(body.vrm.scene);
    }
    bodies[slot] = null;
  }
  Object.assign(mainBody, { rooted: false, person: null });
}

// Loads slot's avatar: the page's avatar file parsed again (the bytes fetched once).
async function loadBody(slot) {
  const generation = avatarGeneration;
  bodies[slot] = { loading: true };
  try {
    avatarBytes ??= fetch(avatarUrl).then((r) => {
      if (!r.ok) throw new Error(`HTTP ${r.status}`);
      return r.arrayBuffer();
    });
    const gltf = await gltfLoader().parseAsync(await avatarBytes, '');
    const loaded = gltf.userData.vrm;
    if (!loaded) throw new Error('not a VRM avatar');
    if (generation !== avatarGeneration) {  // the page's avatar changed meanwhile
      VRMUtils.deepDispose(gltf.scene);
      return;
    }
    VRMUtils.removeUnnecessaryVertices(gltf.scene);
    VRMUtils.rotateVRM0(loaded);
    // Skinned meshes are culled by a bounding sphere three.js computes once, at the first
    // frame drawn: a person whose first pose stood elsewhere (off screen) kept a face culled
    // wherever it went. Several avatars are few: draw them all.
    gltf.scene.traverse((o) => {
      if (o.isMesh) o.frustumCulled = false;
    });
    bodies[slot] = makeBody(loaded);
    loaded.scene.visible = false;  // until its first pose
    scene.add(loaded.scene);
  } catch (e) {
    if (generation !== avatarGeneration) return;
    bodies[slot] = { failed: true };
    state.error = `could not load an avatar for person slot ${slot}: ${e.message ?? e}`;
    console.error('avatarmap-viewer:', state.error);
  }
}

// Applies slot's newest message, if any, to its avatar (loading the avatar first for a slot
// other than 0); true when a pose was applied.
function poseSlot(slot, now) {
  const text = newestMessages[slot];
  if (text === null) return false;
  // The person left the slot (the server's {"gone":true,"person":ID,"slot":K}): its avatar
  // hides now rather than after HIDE_AFTER_MS.
  if (text.startsWith('{"gone":true')) {
    newestMessages[slot] = null;
    if (bodies[slot]) bodies[slot].lastSeen = -Infinity;
    return false;
  }
  let body = bodies[slot];
  if (!body) loadBody(slot);
  if (!body || body.loading || body.failed) return false;  // the newest message waits
  newestMessages[slot] = null;
  let pose;
  try {
    pose = JSON.parse(text);
  } catch (e) {
    state.badMessages++;
    return false;
  }
  if (slot === 0) stopAnimation();
  state.mode = 'live';
  applyPose(pose, body);
  if (typeof pose.slot === 'number') peopleSeen = true;
  body.person = typeof pose.person === 'number' ? pose.person : null;
  body.lastSeen = now;
  body.posesApplied++;
  // Without a root translation people stand side by side, slot 0 where one person stands.
  body.vrm.scene.position.x = body.rooted ? 0 : slot * SLOT_SPACING;
  return true;
}

let framedPeople = 1;  // the most people the camera was framed for

// Frames every shown avatar from the front: the box of their hips (each person about 1.2 m
// wide and 1.9 m tall; skinned meshes' own boxes are of the rest pose, not where a person
// stands).
function framePeople() {
  const box = new THREE.Box3();
  const p = new THREE.Vector3();
  for (const body of bodies) {
    if (!body?.vrm || !body.vrm.scene.visible) continue;
    const hips = body.vrm.humanoid.getNormalizedBoneNode('hips');
    if (!hips) continue;
    body.vrm.scene.updateMatrixWorld(true);
    hips.getWorldPosition(p);
    box.expandByPoint(new THREE.Vector3(p.x - 0.6, 0, p.z));
    box.expandByPoint(new THREE.Vector3(p.x + 0.6, 1.9, p.z));
  }
  if (box.isEmpty()) return;
  const centre = box.getCenter(new THREE.Vector3());
  const width = box.max.x - box.min.x, height = box.max.y - box.min.y;
  const fov = THREE.MathUtils.degToRad(camera.fov);
  const fitHeight = (1.3 * height) / 2 / Math.tan(fov / 2);
  const fitWidth = (1.15 * width) / 2 / Math.tan(fov / 2) / Math.max(0.2, camera.aspect);
  const distance = Math.max(fitHeight, fitWidth);
  camera.position.set(centre.x, 0.55 * height, box.max.z + distance);
  controls.target.set(centre.x, 0.55 * height, centre.z);
  controls.update();
}

// Poses, steps and shows or hides every slot's avatar; true when any pose was applied.
function updatePeople(now, delta) {
  let posed = false;
  let shown = 0;
  for (let slot = 0; slot < MAX_SLOTS; slot++) {
    if (poseSlot(slot, now)) {
      posed = true;
      if (slot !== 0) stopAnimation();  // live poses win over the animation, whoever they are
    }
    const body = bodies[slot];
    if (!body?.vrm) continue;
    // The page's avatar is never hidden for one person (messages without "slot"), as before
    // several people were, nor while it plays an animation.
    const kept = slot === 0 && (!peopleSeen || player.kind !== '');
    const visible = kept || now - body.lastSeen < HIDE_AFTER_MS;
    body.vrm.scene.visible = visible;
    if (visible) shown++;
    if (slot !== 0 && visible) {
      body.vrm.update(delta);
      applyShapeTargets(body.face);
    }
  }
  state.people = shown;
  // More people than the view was framed for: frame them all (once per new count, so that the
  // user's own camera moves are not undone every frame).
  if (shown > framedPeople && shown > 1 && !renderMode) framePeople();
  framedPeople = Math.max(framedPeople, shown);
  return posed;
}

function personOf(slot) {
  const body = bodies[slot];
  if (!body) return null;
  const hips = body.vrm?.humanoid.getNormalizedBoneNode('hips');
  const where = new THREE.Vector3();
  if (hips) {
    body.vrm.scene.updateMatrixWorld(true);
    hips.getWorldPosition(where);
  }
  return {
    slot, person: body.person ?? null, visible: !!body.vrm?.scene.visible,
    loading: !!body.loading, failed: !!body.failed, posesApplied: body.posesApplied ?? 0,
    x: hips ? where.x : null,
  };
}

let socket = null;
function connect(url) {
  state.socket = 'connecting';
  state.socketUrl = url;
  socket = new WebSocket(url, config.protocol || 'avatarmap.pose');
  socket.onopen = () => {
    state.socket = 'open';
    if (state.firstPosedMs !== null) report();
  };
  socket.onmessage = (event) => {
    state.posesReceived++;
    // The server's stream of the pose file this page plays itself is not applied.
    if (config.poses && !config.pose_socket) return;
    const slot = slotOf(event.data);
    if (slot < 0) state.badMessages++;
    else newestMessages[slot] = event.data;
  };
  socket.onclose = () => {
    state.socket = 'closed';
    setTimeout(() => connect(url), 1000);  // the sender may come (back) later
  };
}

function report() {
  if (socket && socket.readyState === WebSocket.OPEN)
    socket.send(JSON.stringify({ first_posed_ms: state.firstPosedMs }));
}

// ---- drop a file ----------------------------------------------------------------------------
document.body.addEventListener('dragover', (e) => {
  e.preventDefault();
  document.body.classList.add('dragging');
});
document.body.addEventListener('dragleave', () => document.body.classList.remove('dragging'));
document.body.addEventListener('drop', (e) => {
  e.preventDefault();
  document.body.classList.remove('dragging');
  const file = e.dataTransfer.files[0];
  if (file && !renderMode) openFile(file);
});

// ---- loop -----------------------------------------------------------------------------------
const clock = new THREE.Clock();
let rate = { count: 0, since: performance.now(), perSecond: 0 };

function hudText() {
  const lines = [];
  if (state.avatar === 'none')
    lines.push('No avatar: open or drop a .vrm file on this page, or run\n' +
               'avatarmap view --avatar FILE.vrm --connect PORT');
  else if (state.avatarName === 'built-in avatar') lines.push(`built-in avatar (${state.avatar})`);
  else lines.push(`avatar ${state.avatarName} (${state.avatar})`);
  if (state.mode === 'clip' && state.clipTime !== null)
    lines.push(`${state.clipKind === 'poses' ? 'poses' : 'clip'} ${state.clipName}: ` +
               `${state.clipTime.toFixed(1)} / ${state.clipDuration.toFixed(1)} s`);
  if (state.videoName) lines.push(`video ${state.videoName} (${state.video})`);
  lines.push(`poses: ${state.socketUrl} ${state.socket}` +
             (state.mode === 'live' ? `, ${rate.perSecond.toFixed(0)}/s, t ${(state.lastPoseT ?? 0).toFixed(2)} s` : '') +
             (state.people > 1 ? `, ${state.people} people` : ''));
  return lines.join('\n');
}

function frame() {
  requestAnimationFrame(frame);
  const delta = Math.min(clock.getDelta(), 0.1);
  let posed = false;
  if (vrm) {
    if (updatePeople(performance.now(), delta)) {
      posed = true;
      rate.count++;
    } else if (player.kind) {
      advance(delta);
      posed = true;
    }
    vrm.update(delta);
    applyShapeTargets();
  }
  updateControls();
  syncVideo();
  controls.update();
  renderer.render(scene, camera);
  state.frames++;
  if (posed && state.firstPosedMs === null) {
    state.firstPosedMs = performance.now();
    console.log(`avatarmap-viewer: first posed frame ${state.firstPosedMs.toFixed(0)} ms`);
    report();
  }
  const now = performance.now();
  if (now - rate.since >= 1000) {
    rate.perSecond = (rate.count * 1000) / (now - rate.since);
    rate = { count: 0, since: now, perSecond: rate.perSecond };
  }
  if (hudElement.style.display !== 'none' && state.frames % 10 === 0) {
    hudElement.textContent = hudText();
    if (state.error) {
      const error = document.createElement('div');
      error.className = 'error';
      error.textContent = state.error;
      hudElement.appendChild(error);
    }
  }
}

// ---- render mode: one frame on request ------------------------------------------------------
let renderChain = Promise.resolve();
let lastRenderT = null;

// Draws one frame after pose(vrm) has posed the avatar; resolves once it has been presented
// (two animation frames later), with the page's state.
function drawRequested(t, pose) {
  const job = renderChain.then(async () => {
    if (!vrm) throw new Error(state.error || 'the avatar is not loaded');
    const dt = lastRenderT === null ? 0 : Math.min(0.1, Math.max(0, t - lastRenderT));
    lastRenderT = t;
    pose();
    vrm.update(dt);
    applyShapeTargets();
    renderer.render(scene, camera);
    state.frames++;
    await new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve)));
    return { ...state };
  });
  renderChain = job.catch(() => {});
  return job;
}

function renderAt(t) {
  return drawRequested(t, () => {
    if (!mixer) throw new Error('no clip to step: open the page of `avatarmap view CLIP.vrma`');
    clipAction.paused = false;
    mixer.setTime(t);
    clipAction.paused = true;
    state.mode = 'clip';
    state.clipTime = clipAction.time;
  });
}

function renderPose(pose) {
  const p = typeof pose === 'string' ? JSON.parse(pose) : pose;
  return drawRequested(typeof p.t === 'number' ? p.t : 0, () => {
    state.mode = 'live';
    applyPose(p);
  });
}

// Resolves once the avatar (and the clip, if any) has loaded, or rejects with the page's error.
async function ready(timeoutMs = 30000) {
  if (renderErrors.length) throw new Error(renderErrors.join('; '));
  const start = performance.now();
  while (state.avatar !== 'ready' || (config.clip && !mixer && !state.error)) {
    if (state.avatar === 'failed' || performance.now() - start > timeoutMs)
      throw new Error(state.error || 'the avatar did not load');
    await new Promise((resolve) => setTimeout(resolve, 20));
  }
  return { ...state };
}

// For `avatarmap render` (docs/render.md): what framing the avatar needs (its rest hips height;
// flip -1 for a VRM 0.x model, whose X and Z poses flip), the camera set after loading (any of
// cam, look, yaw, pitch, roll, hfov, vfov as the URL gives them), and an avatar .glb's own glTF
// animation (`convert -o x.glb`) stepped to time t: it drives the raw bones, so the normalised
// ones are no longer copied onto them.
function avatarInfo() {
  if (!vrm) throw new Error(state.error || 'the avatar is not loaded');
  return { restHips: [...restHips], restHipsY, flip: vrm.meta?.metaVersion === '0' ? -1 : 1 };
}

function setCamera(settings) {
  Object.assign(render, settings);
  placeRenderCamera();
  return { ...state };
}

let glbMixer = null;
let glbDuration = 0;
// The clip loops: its end time would wrap to its start, so the last instant is held instead.
function glbTime(t) {
  return Math.min(Math.max(0, t), Math.max(0, glbDuration - 1e-6));
}
async function loadGlbAnimation(samples = 24) {
  if (!vrm) throw new Error(state.error || 'the avatar is not loaded');
  const gltf = await new GLTFLoader().loadAsync(config.avatar);
  const clip = gltf.animations[0];
  if (!clip) throw new Error(`${config.avatar_name || 'the avatar'} holds no glTF animation`);
  vrm.humanoid.autoUpdateHumanBones = false;
  glbOwnsTheFace(vrm);
  glbMixer = new THREE.AnimationMixer(vrm.scene);
  glbMixer.clipAction(clip).play();
  glbDuration = clip.duration;
  const hips = vrm.humanoid.getRawBoneNode('hips');
  const where = new THREE.Vector3();
  const positions = [];
  for (let i = 0; i <= samples; i++) {
    glbMixer.setTime(glbTime((clip.duration * i) / samples));
    vrm.scene.updateMatrixWorld(true);
    if (hips) positions.push(hips.getWorldPosition(where).toArray());
  }
  glbMixer.setTime(0);
  state.mode = 'clip';
  state.clipDuration = clip.duration;
  return { duration: clip.duration, hips: positions };
}

function renderGlbAt(t) {
  return drawRequested(t, () => {
    if (!glbMixer) throw new Error('no glTF animation loaded: call loadGlbAnimation() first');
    glbMixer.setTime(glbTime(t));
    state.clipTime = t;
  });
}

if (renderMode) {
  Object.assign(window.avatarmapViewer, {
    renderAt, renderPose, ready, avatarInfo, setCamera, loadGlbAnimation, renderGlbAt,
  });
}

// ---- start ----------------------------------------------------------------------------------
let config = {};
try {
  const response = await fetch('/config.json', { cache: 'no-store' });
  config = await response.json();
} catch (e) {
  state.error = `could not read /config.json: ${e.message ?? e}`;
}
const scheme = location.protocol === 'https:' ? 'wss' : 'ws';
if (!renderMode) {
  connect(config.pose_socket || `${scheme}://${location.host}/pose`);
  requestAnimationFrame(frame);
}
if (!renderMode && config.clip) clipSource = { url: config.clip, name: config.clip_name || 'clip' };
if (!renderMode && config.poses) loadPosesFrom(config.poses, config.poses_name || 'poses');
if (!renderMode && config.video) loadVideo(config.video, config.video_name || 'video');
if (config.avatar) {
  loadAvatar(config.avatar, config.avatar_name || 'avatar.vrm',
             !renderMode && config.avatar_animated === true);
}
