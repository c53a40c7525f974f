// Runs the Khronos glTF validator (npm package gltf-validator) on each file given and prints
// one line per file; exits 1 when any file has an error. Usage:
//   NODE_PATH=<folder with node_modules> node validate_gltf.js FILE...
const fs = require('fs');
const validator = require('gltf-validator');
(async () => {
  let failed = false;
  for (const file of process.argv.slice(2)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)));
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos`);
    for (const m of i.messages.filter((m) => m.severity === 0).slice(0, 10))
      console.log(`  ${m.code} ${m.pointer || ''} ${m.message}`);
    if (i.numErrors > 0) failed = true;
  }
  process.exit(failed ? 1 : 0);
})().catch((e) => { console.error(e); process.exit(2); });
