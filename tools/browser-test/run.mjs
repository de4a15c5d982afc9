#!/usr/bin/env node
// Loads drafter's glTF output in real clients and checks screenshots.
//
// Set-up: sh tools/browser-test/setup.sh  (Chromium, f3d, Xvfb from apt; npm ci here)
//
// Usage: node tools/browser-test/run.mjs COMMAND ...
//   three FILE [--screenshot OUT.png] [--view AZ,EL] [--ortho] [--background R,G,B] [--timeout S]
//       three.js GLTFLoader (with MeshoptDecoder). Prints {file, ok, triangles, meshes, ms, consoleErrors}:
//       triangles and meshes as drawn (a mesh used by N nodes or instances counts N times), ms the load time
//       in the page. Without --screenshot nothing is rendered.
//   cesium FILE [--screenshot OUT.png] [--edges-only | --no-edges] [--edge-color R,G,B] [--view AZ,EL]
//              [--ortho] [--background R,G,B] [--frames N] [--timeout S] [--no-edge-cull]
//       CesiumJS Model with EXT_mesh_primitive_edge_visibility edges on (surfaces and edges by default),
//       rendered until ready plus N frames (default 3). --edge-color gives the edges a material of that
//       colour (otherwise they take the primitive's own, lit like the faces). Prints {file, ok, ms,
//       consoleErrors, edgePrimitives}: ms from load start to "ready", edgePrimitives the primitives that
//       carry the extension. Note: with --ortho, CesiumJS 1.145 hides most edges behind their own faces
//       (its edge depth test assumes a perspective projection); --edges-only is not affected.
//       --no-edge-cull serves CesiumJS with the one-line change docs/clients.md proposes: its edge draw command
//       without the primitive's back-face culling (1.145 culls the quad of every edge whose stored direction runs
//       rightwards on screen, so a cylinder keeps one of its two outlines). Fits CesiumJS 1.145's build only;
//       fails if the bundle does not hold the expected code.
//   For both: ok is false if the page failed, timed out, or logged a console error.
//   pixels IMG.png [--background R,G,B] [--color R,G,B] [--tol N] [--region X0,Y0,X1,Y1]
//       Prints {differ: {count, bbox}} for pixels farther than N (per channel, default 40) from the
//       background (default: the top-left pixel) and, with --color, {match: {count, bbox}} for pixels within
//       N of that colour; only inside the region (inclusive pixel coordinates) if given. bbox is
//       [xmin, ymin, xmax, ymax] or null.
//   f3d FILE OUT.png [--timeout S]
//       Renders FILE with f3d under xvfb-run (f3d ignores our extensions). Prints {file, ok, ms, screenshot}.
//
// Every command prints one JSON line on stdout and exits 0 on success, 1 on failure, 2 on wrong usage.
// --view: azimuth and elevation in degrees in the model's glTF axes (+Y up): 0,0 looks from +Z, 90,0 from +X;
// default 30,20. Screenshots are 800x600; the default background is white. Pages time out after --timeout
// seconds (default 60; f3d too); a watchdog kills whatever is left 20 s later.

import { spawn } from 'node:child_process';
import { existsSync, readFileSync, statSync } from 'node:fs';
import path from 'node:path';
import process from 'node:process';
import { fileURLToPath } from 'node:url';

import { startServer } from './lib/server.mjs';
import { runPage, killBrowser } from './lib/browser.mjs';
import { readGltfJson, sceneBox, withEdgeColor } from './lib/glb.mjs';
import { readPng, matchPixels, pixelAt } from './lib/png.mjs';

const TOOL_ROOT = path.dirname(fileURLToPath(import.meta.url));
const EDGE_EXT = 'EXT_mesh_primitive_edge_visibility';

class UsageError extends Error {}

/** Splits argv into positionals and --options (flags get `true`). */
function parseArgs(argv, { flags = [], values = [] }) {
  const positional = [];
  const options = {};
  for (let i = 0; i < argv.length; i++) {
    const arg = argv[i];
    if (!arg.startsWith('--')) {
      positional.push(arg);
      continue;
    }
    const [name, inline] = arg.slice(2).split(/=(.*)/s, 2);
    if (flags.includes(name)) options[name] = true;
    else if (values.includes(name)) {
      const value = inline ?? argv[++i];
      if (value === undefined) throw new UsageError(`--${name} needs a value`);
      options[name] = value;
    } else throw new UsageError(`unknown option --${name}`);
  }
  return { positional, options };
}

/** Parses "a,b,c" into `count` finite numbers. */
function numbers(text, count, what) {
  const list = String(text).split(',').map(Number);
  if (list.length !== count || !list.every(Number.isFinite)) {
    throw new UsageError(`${what} must be ${count} comma-separated numbers, got "${text}"`);
  }
  return list;
}

function rgb(text, what) {
  const color = numbers(text, 3, what);
  if (!color.every((c) => c >= 0 && c <= 255)) throw new UsageError(`${what} must be in 0..255`);
  return color;
}

function seconds(text, fallback) {
  const s = text === undefined ? fallback : Number(text);
  if (!(s > 0)) throw new UsageError(`--timeout must be a positive number of seconds`);
  return s;
}

function requireFile(file) {
  if (!file) throw new UsageError('missing FILE');
  if (!existsSync(file) || !statSync(file).isFile()) throw new UsageError(`no such file: ${file}`);
}

/** Kills everything left after `s` seconds and exits 124, so that no run can hang. */
function watchdog(s) {
  setTimeout(() => {
    killBrowser();
    process.stdout.write(JSON.stringify({ ok: false, error: `watchdog: gave up after ${s} s` }) + '\n');
    process.exit(124);
  }, s * 1000).unref();
}

/** The primitives that carry the edge extension (0 if the file cannot be parsed here). */
function edgePrimitives(bytes) {
  try {
    const json = readGltfJson(bytes);
    return (json.meshes ?? []).flatMap((m) => m.primitives ?? []).filter((p) => p.extensions?.[EDGE_EXT]).length;
  } catch {
    return 0;
  }
}

/** Serves the model (bytes possibly rewritten), runs one client page, returns { result, consoleErrors }. */
async function runClient(client, file, query, { timeoutS, screenshot, bytes, toolOverrides }) {
  const name = path.basename(file);
  const overrides = bytes ? new Map([[name, bytes]]) : new Map();
  const modelDir = path.dirname(path.resolve(file));
  const server = await startServer({ toolRoot: TOOL_ROOT, modelDir, overrides, toolOverrides });
  try {
    const search = new URLSearchParams({ client, model: `/model/${encodeURIComponent(name)}`, ...query });
    return await runPage({ url: `${server.url}/page/index.html?${search}`, timeoutMs: timeoutS * 1000, screenshot });
  } finally {
    await server.close();
  }
}

const CESIUM_JS = 'node_modules/cesium/Build/Cesium/Cesium.js';

/**
 * CesiumJS 1.145's bundle with its edge draw command (`deriveEdgeCommand` in ModelDrawCommand.js) given a copy
 * of the primitive's render state with face culling off. The command is a shallow clone of the primitive's, so
 * it keeps `cull: BACK` of a single-sided material, and the quad it builds per edge winds one way or the other
 * with the edge's direction on screen (EdgeVisibilityStageVS.glsl makes the direction point right before
 * taking its perpendicular): edges running rightwards are culled. The source change this makes:
 *   const rs = clone(command.renderState, true); rs.cull.enabled = false;
 *   edgeCommand.renderState = RenderState.fromCache(rs);
 */
function cesiumWithoutEdgeCull() {
  const text = readFileSync(path.join(TOOL_ROOT, CESIUM_JS), 'utf8');
  // The end of deriveEdgeCommand and the start of derivePlanarFillIdCommand, whose clone (qe) and
  // RenderState (ze) names the change borrows.
  const end = ',o.castShadows=!1,o.receiveShadows=!1,o}function dst(e){let t=lt.shallowClone(e);';
  const planarFill = 'let n=qe(e.renderState,!0);n.blending.enabled=!1,t.renderState=ze.fromCache(n);';
  if (text.split(end).length !== 2 || !text.includes(planarFill)) {
    throw new Error(`--no-edge-cull: ${CESIUM_JS} is not the CesiumJS 1.145 build it was written for`);
  }
  const patched = end.replace(
    ',o}',
    ',o.renderState=(function(s){s.cull.enabled=!1;return ze.fromCache(s)})(qe(e.renderState,!0)),o}',
  );
  return Buffer.from(text.replace(end, patched));
}

/** Options shared by the two browser clients, as page query parameters. */
function viewQuery(options) {
  const query = {};
  if (options.view !== undefined) query.view = numbers(options.view, 2, '--view').join(',');
  if (options.ortho) query.ortho = '1';
  if (options.background !== undefined) query.bg = rgb(options.background, '--background').join(',');
  if (options.screenshot) query.render = '1';
  return query;
}

async function commandThree(argv) {
  const { positional, options } = parseArgs(argv, {
    flags: ['ortho'],
    values: ['screenshot', 'view', 'background', 'timeout'],
  });
  const [file] = positional;
  requireFile(file);
  const timeoutS = seconds(options.timeout, 60);
  watchdog(timeoutS + 20);
  const { result, consoleErrors } = await runClient('three', file, viewQuery(options), {
    timeoutS,
    screenshot: options.screenshot,
  });
  const out = {
    file,
    ok: result.ok && consoleErrors.length === 0,
    triangles: result.triangles,
    meshes: result.meshes,
    ms: result.ms,
    consoleErrors,
  };
  if (options.screenshot && result.ok) out.screenshot = options.screenshot;
  if (!result.ok) out.error = result.error;
  return out;
}

async function commandCesium(argv) {
  const { positional, options } = parseArgs(argv, {
    flags: ['ortho', 'edges-only', 'no-edges', 'no-edge-cull'],
    values: ['screenshot', 'view', 'background', 'edge-color', 'frames', 'timeout'],
  });
  const [file] = positional;
  requireFile(file);
  if (options['edges-only'] && options['no-edges']) throw new UsageError('--edges-only and --no-edges exclude each other');
  const timeoutS = seconds(options.timeout, 60);
  watchdog(timeoutS + 20);

  const query = viewQuery(options);
  query.render = '1'; // Cesium always draws: the check is that frames render without errors
  query.edges = options['edges-only'] ? 'only' : options['no-edges'] ? 'off' : 'both';
  if (options.frames !== undefined) query.frames = String(Math.max(1, Math.round(numbers(options.frames, 1, '--frames')[0])));

  let bytes = readFileSync(file);
  const edges = edgePrimitives(bytes);
  // The camera frames the scene's box computed here (see sceneBox), not CesiumJS's bounding sphere.
  let box = null;
  try {
    box = sceneBox(readGltfJson(bytes));
  } catch {
    // an unreadable file: CesiumJS reports it
  }
  if (box) query.box = box.join(',');
  if (options['edge-color'] !== undefined) bytes = withEdgeColor(bytes, rgb(options['edge-color'], '--edge-color')).bytes;

  const { result, consoleErrors } = await runClient('cesium', file, query, {
    timeoutS,
    screenshot: options.screenshot,
    bytes: options['edge-color'] !== undefined ? bytes : undefined,
    toolOverrides: options['no-edge-cull'] ? new Map([[CESIUM_JS, cesiumWithoutEdgeCull()]]) : undefined,
  });
  const out = { file, ok: result.ok && consoleErrors.length === 0, ms: result.ms, consoleErrors, edgePrimitives: edges };
  if (options.screenshot && result.ok) out.screenshot = options.screenshot;
  if (!result.ok) out.error = result.error;
  return out;
}

function commandPixels(argv) {
  const { positional, options } = parseArgs(argv, { values: ['background', 'color', 'tol', 'region'] });
  const [file] = positional;
  requireFile(file);
  const tol = options.tol === undefined ? 40 : Number(options.tol);
  if (!(tol >= 0)) throw new UsageError('--tol must be a number >= 0');
  const image = readPng(file);
  const background = options.background === undefined ? pixelAt(image, 0, 0) : rgb(options.background, '--background');
  const region = options.region === undefined ? null : numbers(options.region, 4, '--region');
  const out = { file, ok: true, width: image.width, height: image.height, tol, background };
  if (region) out.region = region;
  out.differ = matchPixels(image, background, tol, true, region);
  if (options.color !== undefined) {
    out.color = rgb(options.color, '--color');
    out.match = matchPixels(image, out.color, tol, false, region);
  }
  return out;
}

async function commandF3d(argv) {
  const { positional, options } = parseArgs(argv, { values: ['timeout'] });
  const [file, output] = positional;
  requireFile(file);
  if (!output) throw new UsageError('missing OUT.png');
  const timeoutS = seconds(options.timeout, 60);
  const start = Date.now();
  // Own process group, so that a timeout takes xvfb-run, Xvfb and f3d down together.
  const child = spawn('xvfb-run', ['-a', 'f3d', `--output=${output}`, '--resolution=800,600', file], {
    detached: true,
    stdio: ['ignore', 'ignore', 'pipe'],
  });
  let stderr = '';
  child.stderr.on('data', (chunk) => (stderr = (stderr + chunk).slice(-2000)));
  let timedOut = false;
  const timer = setTimeout(() => {
    timedOut = true;
    try {
      process.kill(-child.pid, 'SIGKILL');
    } catch {
      // already gone
    }
  }, timeoutS * 1000);
  const { code, signal, spawnError } = await new Promise((resolve) => {
    child.on('error', (err) => resolve({ spawnError: err }));
    child.on('close', (code, signal) => resolve({ code, signal }));
  });
  clearTimeout(timer);
  const written = existsSync(output) && statSync(output).size > 0 && statSync(output).mtimeMs >= start - 1000;
  const out = { file, ok: code === 0 && written, ms: Date.now() - start };
  if (out.ok) out.screenshot = output;
  else {
    out.error = spawnError
      ? `cannot run xvfb-run: ${spawnError.message}`
      : timedOut
        ? `timed out after ${timeoutS} s`
        : `f3d exited with ${signal ?? code}${written ? '' : ', no image written'}: ${stderr.trim()}`;
  }
  return out;
}

const COMMANDS = { three: commandThree, cesium: commandCesium, pixels: commandPixels, f3d: commandF3d };

async function main() {
  const [command, ...rest] = process.argv.slice(2);
  const run = COMMANDS[command];
  try {
    if (!run) throw new UsageError(`usage: run.mjs ${Object.keys(COMMANDS).join('|')} ... (see the header of run.mjs)`);
    const out = await run(rest);
    process.stdout.write(JSON.stringify(out) + '\n');
    process.exit(out.ok ? 0 : 1);
  } catch (err) {
    if (err instanceof UsageError) {
      process.stderr.write(`run.mjs: ${err.message}\n`);
      process.exit(2);
    }
    killBrowser();
    process.stdout.write(JSON.stringify({ ok: false, error: String(err?.stack ?? err) }) + '\n');
    process.exit(1);
  }
}

main();
