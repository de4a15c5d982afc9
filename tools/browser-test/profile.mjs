#!/usr/bin/env node
// Where the page's main thread spends its time until the first frame: one load in a freshly
// started headless Chromium (SwiftShader WebGL2, 800×600) under the DevTools sampling profiler,
// then the page's timings and the functions with the most time, by self time and by inclusive
// time. A page built with `DRAFTER_WEB_NAMES=1 scripts/web` keeps the module's function names
// (the Rust paths); the default build has none. docs/web.md, "First frame", says what it found.
//
// Usage: node tools/browser-test/profile.mjs PAGE_DIR FILE [plain|default] [--focus NAME] [--top N]
//   plain: phong, edges and lines off; default: gradient, edges and lines on.
//   --focus NAME: also the time below each frame whose function name contains NAME, by callee.
//   CHROMIUM_FLAGS="--js-flags=..." adds browser flags (e.g. V8's --no-wasm-lazy-compilation).

import path from 'node:path';
import process from 'node:process';
import { launchBrowser, killBrowser } from './lib/browser.mjs';
import { startServer } from './lib/server.mjs';

const args = process.argv.slice(2);
const positional = [];
let focus = null;
let top = 30;
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--focus') focus = args[++i];
  else if (args[i] === '--top') top = Number(args[++i]);
  else positional.push(args[i]);
}
const [pageDir, file, view = 'plain'] = positional;
if (!pageDir || !file || !['plain', 'default'].includes(view) || !(top > 0)) {
  console.error('usage: profile.mjs PAGE_DIR FILE [plain|default] [--focus NAME] [--top N]');
  process.exit(2);
}

const server = await startServer({ toolRoot: pageDir, modelDir: path.dirname(file) });
const flags = process.env.CHROMIUM_FLAGS ? process.env.CHROMIUM_FLAGS.split(' ') : [];
const browser = await launchBrowser(120_000, flags);
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 800, height: 600 });
  const cdp = await page.createCDPSession();
  await cdp.send('Profiler.enable');
  await cdp.send('Profiler.setSamplingInterval', { interval: 200 }); // µs
  await cdp.send('Profiler.start');
  const on = view === 'default' ? '1' : '0';
  const params = new URLSearchParams({
    src: `/model/${encodeURIComponent(path.basename(file))}`,
    size: '800x600',
    controls: 'none',
    backend: 'webgl2',
    shadow: 'none',
    view: '35,25',
    style: view === 'default' ? 'gradient' : 'phong',
    edges: on,
    lines: on,
  });
  await page.goto(`${server.url}/index.html?${params}`, { waitUntil: 'domcontentloaded' });
  await page.waitForFunction(() => ['ready', 'error'].includes(document.getElementById('viewer')?.state), {
    polling: 50,
    timeout: 120_000,
  });
  const { profile } = await cdp.send('Profiler.stop');
  const status = await page.evaluate(() => {
    const v = document.getElementById('viewer');
    return { state: v.state, message: v.message, timings: v.timings, startup: v.startup };
  });
  console.log(JSON.stringify(status));

  const nodes = new Map(profile.nodes.map((n) => [n.id, n]));
  const parent = new Map();
  for (const n of profile.nodes) for (const c of n.children ?? []) parent.set(c, n.id);
  const name = (id) => nodes.get(id).callFrame.functionName || '(anonymous)';
  const self = new Map();
  const inclusive = new Map();
  const below = new Map();
  const add = (map, key, ms) => map.set(key, (map.get(key) ?? 0) + ms);
  profile.samples.forEach((id, i) => {
    const ms = (profile.timeDeltas[i] ?? 0) / 1000;
    add(self, name(id), ms);
    const chain = [];
    for (let at = id; at !== undefined; at = parent.get(at)) chain.push(name(at));
    for (const f of new Set(chain)) add(inclusive, f, ms);
    const k = focus === null ? -1 : chain.findIndex((f) => f.includes(focus));
    if (k >= 0) add(below, k > 0 ? chain[k - 1] : '(itself)', ms);
  });
  const print = (title, map) => {
    console.log(`# ${title}`);
    for (const [f, ms] of [...map].sort((a, b) => b[1] - a[1]).slice(0, top)) console.log(`${ms.toFixed(1)}\t${f.slice(0, 160)}`);
  };
  print('self ms', self);
  print('inclusive ms', inclusive);
  if (focus !== null) print(`ms below frames named *${focus}*, by callee`, below);
} finally {
  await browser.close().catch(() => {});
  killBrowser();
  server.close?.();
}
