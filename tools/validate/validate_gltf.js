// Runs the Khronos glTF Validator (npm package gltf-validator) on one file and prints its
// summary as JSON: {"errors", "warnings", "infos", "hints", "messages": [first errors]}.
// Exit code 0 when the file has no errors, 1 when it has some, 2 when it cannot be validated.
//   NODE_PATH=<folder with node_modules> node tools/validate/validate_gltf.js FILE
// It writes no file: the caller captures the output (tests into their own scratch folder, never
// beside FILE, which may be read-only data such as ../shared/data).
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

const file = process.argv[2];
const bytes = new Uint8Array(fs.readFileSync(file));
const folder = path.dirname(file);
validator.validateBytes(bytes, {
  uri: path.basename(file),
  externalResourceFunction: (uri) =>
    new Promise((resolve, reject) => {
      fs.readFile(path.join(folder, decodeURIComponent(uri)), (err, data) => (err ? reject(err.toString()) : resolve(new Uint8Array(data))));
    }),
}).then((report) => {
  const issues = report.issues;
  const errors = issues.messages.filter((m) => m.severity === 0).slice(0, 10);
  console.log(JSON.stringify({ errors: issues.numErrors, warnings: issues.numWarnings, infos: issues.numInfos,
                               hints: issues.numHints, messages: errors }));
  process.exit(issues.numErrors === 0 ? 0 : 1);
}, (error) => {
  console.error('validation failed: ' + error);
  process.exit(2);
});
