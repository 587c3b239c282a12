#!/usr/bin/env node
// Runs the Khronos glTF-Validator (pinned in package.json beside this file) on one .gltf or .glb.
//   node validate.js FILE [--json | --brief]
// Resolves external buffers and images next to FILE. Prints a one-line summary and every error
// and warning (with --json: the validator's whole report; with --brief: the summary alone, the
// warnings it raises only because it does not know KHR_texture_basisu counted apart). Exit 0 with
// no errors, 1 with errors, 2 when the file cannot be read or the validator cannot run.
'use strict';
const fs = require('fs');
const path = require('path');

let validator;
try {
  validator = require('gltf-validator');
} catch (e) {
  console.error('gltf-validator is not installed: run scripts/install-gltf-validator.sh');
  process.exit(2);
}

const args = process.argv.slice(2);
const json = args.includes('--json');
const brief = args.includes('--brief');
const file = args.find((a) => a !== '--json' && a !== '--brief');
if (!file) {
  console.error('usage: node validate.js FILE.gltf|FILE.glb [--json]');
  process.exit(2);
}
const full = path.resolve(file);
let bytes;
try {
  bytes = new Uint8Array(fs.readFileSync(full));
} catch (e) {
  console.error(`${file}: ${e.message}`);
  process.exit(2);
}

const severities = ['error', 'warning', 'info', 'hint'];

// The validator (2.0.0-dev.3.10) does not know KHR_texture_basisu (its issue #177): each KTX2 image
// gets a warning that 'image/ktx2' is not a mimeType it knows and one that its format is not
// recognised. Those are counted apart.
function briefSummary(report) {
  const messages = report.issues.messages;
  const ktx2Images = new Set(messages
    .filter((m) => m.code === 'VALUE_NOT_IN_LIST' && /'image\/ktx2'/.test(m.message) && /^\/images\/\d+\/mimeType$/.test(m.pointer || ''))
    .map((m) => m.pointer.split('/')[2]));
  const onKtx2 = (m) => m.severity === 1 && ktx2Images.has((/^\/images\/(\d+)(\/mimeType)?$/.exec(m.pointer || '') || [])[1]) &&
                        (m.code === 'VALUE_NOT_IN_LIST' || m.code === 'IMAGE_UNRECOGNIZED_FORMAT');
  const ktx2 = messages.filter(onKtx2).length;
  let text = `${report.issues.numErrors} errors, ${report.issues.numWarnings - ktx2} warnings`;
  if (ktx2 > 0) text += ` (and ${ktx2} on KTX2 images only because the validator does not know KHR_texture_basisu yet, its issue #177)`;
  return text;
}
validator
  .validateBytes(bytes, {
    uri: path.basename(full),
    maxIssues: 0,  // no limit
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.resolve(path.dirname(full), decodeURIComponent(uri)), (err, data) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(data)));
      }),
  })
  .then(
    (report) => {
      const issues = report.issues;
      if (json) {
        console.log(JSON.stringify(report, null, 1));
      } else if (brief) {
        console.log(briefSummary(report));
      } else {
        console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
                    `${issues.numInfos} infos, ${issues.numHints} hints (validator ${report.validatorVersion})`);
        for (const m of issues.messages.filter((m) => m.severity <= 1)) {
          console.log(`  ${severities[m.severity]} ${m.code} ${m.pointer || ''}: ${m.message}`);
        }
      }
      process.exit(issues.numErrors > 0 ? 1 : 0);
    },
    (err) => {
      console.error(`${file}: the validator could not run: ${err}`);
      process.exit(2);
    });
