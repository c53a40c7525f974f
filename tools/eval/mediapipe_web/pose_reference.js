// Driven by reference.py (docs/closeups.md). GET /job gives
//   {"modelComplexity": 1, "images": [{"url": "/img/0", "name": "..."}, ...], "fresh": bool}
// Each image goes through Pose.send once on a graph that has seen no earlier frame (a new
// Pose object, or reset() of the previous one), smoothLandmarks off, selfieMode off: the
// legacy solution's static-image use. The result of each image is POSTed to /result as
//   {"index": i, "w": naturalWidth, "h": naturalHeight, "landmarks": [[x,y,z,v]...] (normalised),
//    "world": [[x,y,z,v]...]}; errors go to /error, the end to /done.
'use strict';

function post(path, body) {
  return fetch(path, {method: 'POST', headers: {'Content-Type': 'application/json'},
                      body: JSON.stringify(body)});
}

window.addEventListener('error', (e) => post('/error', {message: String(e.message)}));
window.addEventListener('unhandledrejection', (e) => post('/error', {message: String(e.reason)}));

function loadImage(url) {
  return new Promise((resolve, reject) => {
    const img = new Image();
    img.onload = () => resolve(img);
    img.onerror = () => reject(new Error('cannot load ' + url));
    img.src = url;
  });
}

function makePose(job) {
  const pose = new Pose({locateFile: (file) => '/mp/pose/' + file});
  pose.setOptions({
    modelComplexity: job.modelComplexity,
    selfieMode: false,
    smoothLandmarks: false,
    enableSegmentation: false,
    smoothSegmentation: false,
    minDetectionConfidence: job.minDetectionConfidence,
    minTrackingConfidence: job.minTrackingConfidence,
  });
  return pose;
}

async function run() {
  const job = await (await fetch('/job')).json();
  let pose = null;
  for (let i = 0; i < job.images.length; ++i) {
    const img = await loadImage(job.images[i].url);
    if (pose && job.fresh) {
      await pose.close();
      pose = null;
    }
    if (!pose) {
      pose = makePose(job);
      await pose.initialize();
    } else {
      pose.reset();
    }
    let results = null;
    pose.onResults((r) => { results = r; });
    await pose.send({image: img});
    const pack = (list) => (list || []).map((p) => [p.x, p.y, p.z, p.visibility === undefined ? 0 : p.visibility]);
    await post('/result', {
      index: i,
      w: img.naturalWidth,
      h: img.naturalHeight,
      landmarks: pack(results && results.poseLandmarks),
      world: pack(results && results.poseWorldLandmarks),
    });
  }
  await post('/done', {});
}

run().catch((e) => post('/error', {message: String(e && e.stack || e)}));
