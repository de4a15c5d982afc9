#!/usr/bin/env node
// Validates glTF / GLB files with the Khronos glTF validator (npm package `gltf-validator`).
//
// Usage: node tools/validate-gltf/validate.mjs FILE...
// Set-up: npm ci --prefix tools/validate-gltf
//
// Prints one summary line per file ("FILE: N errors, M warnings, I infos, H hints"), then every error and
// warning with its JSON pointer. Exits 1 if any file has an error or a warning (or cannot be read or
// validated), 2 on wrong usage, 0 otherwise. Infos and hints are counted but do not fail the run.

import { readFile } from 'node:fs/promises';
import path from 'node:path';
import process from 'node:process';
import validator from 'gltf-validator';

const SEVERITY_NAMES = ['error', 'warning', 'info', 'hint'];
const SEVERITY_ERROR = 0;
const SEVERITY_WARNING = 1;

/** Validates one file; returns true when it has neither errors nor warnings. */
async function validateFile(file) {
  const folder = path.dirname(path.resolve(file));
  const bytes = await readFile(file);
  const report = await validator.validateBytes(new Uint8Array(bytes), {
    uri: path.basename(file),
    maxIssues: 0,
    writeTimestamp: false,
    externalResourceFunction: async (uri) => {
      const resolved = path.resolve(folder, decodeURIComponent(uri));
      return new Uint8Array(await readFile(resolved));
    },
  });
  const issues = report.issues;
  // A fixed format (always plural) so CI logs can be grepped.
  console.log(
    `${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
      `${issues.numInfos} infos, ${issues.numHints} hints`,
  );
  for (const message of issues.messages) {
    if (message.severity === SEVERITY_ERROR || message.severity === SEVERITY_WARNING) {
      const where = message.pointer ?? (message.offset !== undefined ? `byte ${message.offset}` : '');
      console.log(`  ${SEVERITY_NAMES[message.severity]} ${message.code}: ${message.message} (${where})`);
    }
  }
  return issues.numErrors === 0 && issues.numWarnings === 0;
}

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error('usage: node tools/validate-gltf/validate.mjs FILE...');
  process.exit(2);
}

let clean = true;
for (const file of files) {
  try {
    clean = (await validateFile(file)) && clean;
  } catch (error) {
    console.log(`${file}: could not be validated: ${error}`);
    clean = false;
  }
}
process.exit(clean ? 0 : 1);
