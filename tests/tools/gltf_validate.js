// Validates glTF files with Khronos' glTF-Validator (npm "gltf-validator", installed by the tests into
// the build tree and found through NODE_PATH). Prints one summary line per file and every error;
// exits 1 when any file has an error, 0 otherwise. Usage: node gltf_validate.js FILE...
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

async function validate(file) {
  const dir = path.dirname(file);
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: path.basename(file),
    // Buffers and images beside the file, as a viewer would load them.
    externalResourceFunction: (uri) => new Promise((resolve, reject) => {
      fs.readFile(path.join(dir, decodeURIComponent(uri)), (err, data) => (err ? reject(err.toString()) : resolve(new Uint8Array(data))));
    }),
  });
  const issues = report.issues;
  console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos`);
  for (const m of issues.messages) if (m.severity === 0) console.log(`  error ${m.code} ${m.pointer || ''}: ${m.message}`);
  return issues.numErrors === 0;
}

(async () => {
  let ok = true;
  for (const file of process.argv.slice(2)) ok = (await validate(file)) && ok;
  process.exit(ok ? 0 : 1);
})().catch((e) => {
  console.log(`gltf_validate: ${e}`);
  process.exit(2);
});
