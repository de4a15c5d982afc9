#!/usr/bin/env node
// The page's first-frame benchmark (docs/web.md): for each file, N page loads in a freshly started
// headless Chromium each (SwiftShader WebGL2, 800×600), plain (`--styles phong`, edges and lines
// off) and the default view of a baked file (gradient, edges and lines on); prints every run's
// first frame and where it went, then the median of each. A benchmark, not a test: it prints
// figures and judges nothing, since a busy machine makes every step slower. Measure on a quiet one.
// Each run opens the page once the new browser's own start-up work is done (web.mjs
// --idle-browser; the first column after the run says how long that took), as a user's browser
// has done its own before they open a page; --at-launch opens it at once instead.
//
// Usage: node tools/browser-test/first-frame.mjs PAGE_DIR FILE [FILE ...] [--runs N] [--at-launch]

import { execFileSync } from 'node:child_process';
import { mkdtempSync, rmSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import process from 'node:process';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
let runs = 5;
let idle = true;
const files = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--runs') runs = Number(args[++i]);
  else if (args[i] === '--at-launch') idle = false;
  else files.push(args[i]);
}
const pageDir = files.shift();
if (!pageDir || files.length === 0 || !(runs > 0)) {
  console.error('usage: first-frame.mjs PAGE_DIR FILE [FILE ...] [--runs N] [--at-launch]');
  process.exit(2);
}

const views = {
  plain: ['--styles', 'phong'],
  default: ['--styles', 'gradient', '--param', 'edges', '--param', 'lines'],
};
const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};
const ms = (x) => (x === undefined ? '-' : `${Math.round(x)}`);

console.log(`# ${runs} runs each, ms from navigation start; load average at start ${os.loadavg()[0].toFixed(2)}`);
const shots = mkdtempSync(path.join(os.tmpdir(), 'drafter-first-frame-'));
process.on('exit', () => rmSync(shots, { recursive: true, force: true }));
console.log('file\tview\trun\tidleWait\tfirstFrame\twasmReady\tsurface\trenderer\tread\tfirstDraw');
const rows = [];
for (const file of files) {
  for (const [view, flags] of Object.entries(views)) {
    for (let run = 1; run <= runs; run++) {
      // Views interleaved run by run would mix the browser's caches no more than this: each run
      // is a new browser on a new profile.
      let out;
      try {
        out = execFileSync('node', [path.join(here, 'web.mjs'), 'shots', pageDir, file, '--out', shots, ...(idle ? ['--idle-browser'] : []), ...flags], { encoding: 'utf8' });
      } catch (err) {
        out = err.stdout ?? '';
      }
      const json = JSON.parse(out.trim().split('\n').pop() || '{}');
      if (!json.ok) {
        console.log(`${path.basename(file)}\t${view}\t${run}\tfailed: ${JSON.stringify(json).slice(0, 300)}`);
        continue;
      }
      const t = json.timings;
      const s = json.startup ?? {};
      const row = {
        file: path.basename(file),
        view,
        idleWait: json.idleWaitMs,
        firstFrame: t.firstFrame,
        wasmReady: t.wasmReady,
        surface: s.surface,
        renderer: s.renderer,
        read: json.summary?.readMs,
        firstDraw: t.firstFrame - t.modelLoaded,
      };
      rows.push(row);
      console.log([row.file, view, run, ms(row.idleWait), ms(row.firstFrame), ms(row.wasmReady), ms(row.surface), ms(row.renderer), ms(row.read), ms(row.firstDraw)].join('\t'));
    }
  }
}
console.log('# medians');
for (const file of files.map((f) => path.basename(f))) {
  for (const view of Object.keys(views)) {
    const mine = rows.filter((r) => r.file === file && r.view === view);
    if (mine.length === 0) continue;
    const m = (key) => {
      const xs = mine.map((r) => r[key]).filter((x) => x !== undefined);
      return xs.length ? ms(median(xs)) : '-';
    };
    const all = mine.map((r) => Math.round(r.firstFrame)).sort((a, b) => a - b).join(' ');
    console.log([file, view, `median of ${mine.length}`, m('idleWait'), m('firstFrame'), m('wasmReady'), m('surface'), m('renderer'), m('read'), m('firstDraw'), `(all: ${all})`].join('\t'));
  }
}
