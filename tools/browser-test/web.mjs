#!/usr/bin/env node
// Drives drafter's own browser page (web/page, built by scripts/web) in headless Chromium with
// software WebGL 2 (SwiftShader), for cli/tests/web.rs and the figures of docs/web.md.
//
// Usage: node tools/browser-test/web.mjs COMMAND PAGE_DIR FILE [options]
//   PAGE_DIR: the built page (index.html, drafter-viewer.js, drafter_web.js, drafter_web_bg.wasm).
//   FILE: the model, served from its folder.
//   shots --out DIR --styles a,b,... [--size WxH] [--view AZ,EL] [--edges] [--lines] [--shadow S]
//         [--frames N] [--no-src] [--capture] [--idle-browser]
//       Loads the page with FILE, then draws each style and saves the canvas as DIR/STYLE.png
//       (with --capture, and always on WebGPU: the pixels of viewer.capture(), the same frame
//       drawn offscreen). --idle-browser: opens the page only once the freshly started browser's
//       own start-up work is done (lib/browser.mjs, waitUntilBrowserIdle; idleWaitMs says how long).
//       Prints {ok, backend, summary, timings, startup, shots, frameMs, consoleErrors}: timings in ms from
//       the navigation's start (wasmReady, fileFetched, modelLoaded, firstFrame); with --frames,
//       frameMs holds N full frames of the first style, each timed from recording until the GPU
//       finished it (a one-pixel readPixels waits for it, as `drafter bench render` waits).
//   interact [--size WxH]
//       A scripted left drag over the canvas, then the key 3 (gooch). Prints {ok, before, after,
//       keyStyle, pixelsChanged, consoleErrors}.
//   bad [--max-triangles N]
//       Loads FILE, which should be refused (or the page's parameters, --param). Prints {ok, state,
//       message, ms, consoleErrors}; ok when the page shows an error message within the timeout.
//   probe [--controls] [--keys K] [--reload] [--drop F1,F2,...] [--lose-device] [--set NAME=VALUE]
//         [--reattach] [--help-key]
//       Loads FILE, then, in this order: types the keys K (one character each); sets the element's
//       src again (a new load of FILE); drops the files F1,F2,... on the element at once (as a user
//       selecting them); destroys the GPU device (viewer.lose_device()); sets the element's
//       attributes (--set, repeatable; an empty VALUE removes it) and waits two frames; takes the
//       element off the page (reporting `detached`: its viewer freed, its state) and puts it back;
//       presses ?. Waits for the page to settle after each. Prints {ok, state, message, notice, backend, viewerState,
//       summary, layout, labels, help, consoleErrors}: layout holds the toolbar's, the canvas's and
//       the notice's rectangles (CSS pixels) and modelTop, the first canvas row that is not
//       background in CSS pixels from the page's top; labels the accessible name of each control;
//       help whether the help is shown and its text. ok when the page settled (ready or error).
// Common: --backend webgpu|webgl2 (default webgl2; webgpu starts Chromium with WebGPU on SwiftShader's
// Vulkan, or with DRAFTER_WEBGPU_ARGS), --timeout S (default 120, or DRAFTER_WEB_TIMEOUT), --param NAME=VALUE (a page
// parameter, repeatable; replaces the one this script sets; --param NAME alone removes it), --dpr N (devicePixelRatio, default 1),
// --no-size (no size parameter: the canvas fills the page, in device pixels), --controls (show the
// toolbar). Without --edges / --lines the page is told edges=0 / lines=0 (its default is on for a
// file that carries baked lines).
// Every command prints one JSON line and exits 0 when ok, 1 otherwise, 2 on wrong usage.

import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import process from 'node:process';

import { launchBrowser, killBrowser, waitUntilBrowserIdle } from './lib/browser.mjs';

// WebGPU without a GPU: Dawn on Chromium's bundled SwiftShader Vulkan.
const WEBGPU_ARGS = (process.env.DRAFTER_WEBGPU_ARGS ?? '--enable-unsafe-webgpu --enable-features=Vulkan --use-webgpu-adapter=swiftshader').split(' ');
import { startServer } from './lib/server.mjs';

function parse(argv) {
  const [command, pageDir, file, ...rest] = argv;
  const options = { backend: 'webgl2', timeout: process.env.DRAFTER_WEB_TIMEOUT ?? '120', size: '800x600', view: '35,25', shadow: 'none', param: [], set: [] };
  const flags = ['edges', 'lines', 'no-src', 'capture', 'idle-browser', 'no-size', 'controls', 'reload', 'lose-device', 'help-key', 'reattach'];
  for (let i = 0; i < rest.length; i++) {
    const name = rest[i].replace(/^--/, '');
    if (flags.includes(name)) options[name] = true;
    else if (name === 'param') options.param.push(rest[++i]);
    else if (name === 'set') options.set.push(rest[++i]);
    else options[name] = rest[++i];
  }
  if (!command || !pageDir || !file) throw new Error('usage: web.mjs shots|interact|bad|probe PAGE_DIR FILE [options]');
  return { command, pageDir: path.resolve(pageDir), file: path.resolve(file), options };
}

/** Waits until the viewer settles (ready, error or empty) after an action started at load `loads`. */
async function settle(page, timeoutMs, loads) {
  return page
    .waitForFunction(
      (loads) => {
        const v = document.getElementById('viewer');
        // (A page without `loads`, an older build, settles on its state alone.)
        const newer = loads === undefined || v.loads === undefined || v.loads > loads || v.state === 'error';
        return ['ready', 'error', 'empty'].includes(v?.state) && newer;
      },
      { timeout: timeoutMs, polling: 100 },
      loads,
    )
    .then(() => true)
    .catch(() => false);
}

/** The probe command: actions, then what the page shows. */
async function probe(page, options, file, settled, timeoutMs) {
  const loads = () => page.evaluate(() => document.getElementById('viewer').loads);
  if (settled && options.keys) {
    await page.focus('#viewer');
    for (const key of options.keys) await page.keyboard.press(key);
  }
  if (settled && options.reload) {
    const before = await loads();
    await page.evaluate((name) => {
      document.getElementById('viewer').setAttribute('src', `/model/${encodeURIComponent(name)}?again`);
    }, path.basename(file));
    settled = await settle(page, timeoutMs, before);
  }
  if (settled && options.drop) {
    const files = options.drop.split(',').map((f) => ({ name: path.basename(f), data: readFileSync(f).toString('base64') }));
    const before = await loads();
    await page.evaluate((files) => {
      const transfer = new DataTransfer();
      for (const f of files) {
        const bytes = Uint8Array.from(atob(f.data), (c) => c.charCodeAt(0));
        transfer.items.add(new File([bytes], f.name));
      }
      const v = document.getElementById('viewer');
      v.dispatchEvent(new DragEvent('drop', { dataTransfer: transfer, bubbles: true, cancelable: true }));
    }, files);
    settled = await settle(page, timeoutMs, before);
  }
  if (settled && options['lose-device']) {
    const before = await loads();
    await page.evaluate(() => document.getElementById('viewer').viewer.lose_device());
    settled = await settle(page, timeoutMs, before);
  }
  if (settled && options.set.length) {
    await page.evaluate(async (pairs) => {
      const v = document.getElementById('viewer');
      for (const pair of pairs) {
        const [name, ...value] = pair.split('=');
        if (value.join('=') === '') v.removeAttribute(name);
        else v.setAttribute(name, value.join('='));
      }
      await new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve)));
    }, options.set);
  }
  let detached = null;
  if (settled && options.reattach) {
    const before = await loads();
    detached = await page.evaluate(() => {
      const v = document.getElementById('viewer');
      const parent = v.parentNode;
      const next = v.nextSibling;
      v.remove();
      const report = { viewer: v.viewer === null ? null : 'kept', state: v.state };
      parent.insertBefore(v, next);
      return report;
    });
    settled = await settle(page, timeoutMs, before);
  }
  if (settled && options['help-key']) {
    await page.focus('#viewer');
    await page.keyboard.press('?');
  }
  const report = await page.evaluate(async () => {
    const v = document.getElementById('viewer');
    const root = v.shadowRoot;
    const rect = (e) => {
      if (!e || e.hidden || e.offsetParent === null) return null;
      const r = e.getBoundingClientRect();
      return { left: r.left, top: r.top, right: r.right, bottom: r.bottom };
    };
    let modelTop = null;
    if (v.state === 'ready' && !v.hasAttribute('offscreen')) {
      // The canvas as drawn, read in the task of its draw, then the first row that is not background.
      v.draw(false);
      const url = v.canvas.toDataURL('image/png');
      const img = new Image();
      img.src = url;
      await img.decode();
      const c = document.createElement('canvas');
      [c.width, c.height] = [img.width, img.height];
      const g = c.getContext('2d');
      g.drawImage(img, 0, 0);
      const { data } = g.getImageData(0, 0, c.width, c.height);
      const [r0, g0, b0] = [data[0], data[1], data[2]];
      find: for (let y = 0; y < c.height; y++) {
        for (let x = 0; x < c.width; x++) {
          const i = 4 * (y * c.width + x);
          if (Math.abs(data[i] - r0) + Math.abs(data[i + 1] - g0) + Math.abs(data[i + 2] - b0) > 30) {
            modelTop = v.canvas.getBoundingClientRect().top + y * (v.canvas.clientHeight / c.height);
            break find;
          }
        }
      }
    }
    const labels = [...root.querySelectorAll('.bar select, .bar input, .bar button')].map((e) => ({
      name: e.name,
      label: e.getAttribute('aria-label') || [...(e.labels ?? [])].map((l) => l.textContent.trim()).join(' ') || e.textContent.trim(),
      disabled: e.disabled,
    }));
    const help = root.querySelector('.help');
    return {
      state: v.state,
      message: v.message,
      notice: !root.querySelector('.notice') || root.querySelector('.notice').hidden ? '' : v.notice,
      backend: v.viewer?.backend() ?? null,
      viewerState: v.viewer ? v.viewState() : null,
      summary: v.summary,
      layout: {
        toolbar: rect(root.querySelector('.bar')),
        canvas: rect(v.canvas),
        notice: rect(root.querySelector('.notice')),
        modelTop,
      },
      labels,
      help: { shown: Boolean(help && !help.hidden), text: help && !help.hidden ? help.textContent : '' },
    };
  });
  return { ok: settled, detached, ...report };
}

async function main() {
  let args;
  try {
    args = parse(process.argv.slice(2));
  } catch (err) {
    console.error(err.message);
    process.exit(2);
  }
  const { command, pageDir, file, options } = args;
  const timeoutMs = Number(options.timeout) * 1000;
  const watchdog = setTimeout(() => {
    console.log(JSON.stringify({ ok: false, error: `watchdog: no answer in ${options.timeout} s` }));
    killBrowser();
    process.exit(1);
  }, timeoutMs + 20_000);
  const server = await startServer({ toolRoot: pageDir, modelDir: path.dirname(file) });
  const browser = await launchBrowser(timeoutMs, options.backend === 'webgpu' ? WEBGPU_ARGS : []);
  const consoleErrors = [];
  let result;
  try {
    const idleWaitMs = options['idle-browser'] ? await waitUntilBrowserIdle(browser) : undefined;
    const dpr = Number(options.dpr ?? 1);
    // The page's size in CSS pixels: with --no-size and --dpr N, the canvas is N times larger.
    const [w, h] = options.size.split('x').map((n) => Math.round(Number(n) / (options['no-size'] ? dpr : 1)));
    const page = await browser.newPage();
    await page.setViewport({ width: w, height: h, deviceScaleFactor: dpr });
    page.on('console', (msg) => msg.type() === 'error' && consoleErrors.push(msg.text()));
    page.on('pageerror', (err) => consoleErrors.push(`page error: ${err.message ?? err}`));
    const params = new URLSearchParams({
      src: `/model/${encodeURIComponent(path.basename(file))}`,
      size: options.size,
      view: options.view,
      shadow: options.shadow,
      backend: options.backend,
      controls: 'none',
      edges: options.edges ? '1' : '0',
      lines: options.lines ? '1' : '0',
    });
    // --no-src: the page's own model (what `drafter web` wrote beside it), served from PAGE_DIR.
    if (options['no-src']) params.delete('src');
    if (options['no-size']) params.delete('size');
    if (options.controls) params.delete('controls');
    if (options['max-triangles']) params.set('max-triangles', options['max-triangles']);
    for (const p of options.param) {
      const [name, ...value] = p.split('=');
      if (value.length === 0) params.delete(name);
      else params.set(name, value.join('='));
    }
    // WebGPU here: present nothing (presenting a WebGPU canvas loses the device in this headless
    // Chromium); the shots are viewer.capture()'s.
    if (options.backend === 'webgpu') params.set('offscreen', '1');
    const started = Date.now();
    await page.goto(`${server.url}/index.html?${params}`, { waitUntil: 'domcontentloaded', timeout: timeoutMs });
    const settled = await page
      .waitForFunction(
        () => ['ready', 'error', 'empty'].includes(document.getElementById('viewer')?.state),
        { timeout: timeoutMs, polling: 100 },
      )
      .then(() => true)
      .catch(() => false);
    const status = await page.evaluate(() => {
      const v = document.getElementById('viewer');
      return {
        state: v.state,
        message: v.message,
        summary: v.summary,
        timings: v.timings,
        startup: v.startup ?? null,
        backend: v.viewer?.backend() ?? null,
      };
    });
    const ms = Date.now() - started;
    if (command === 'bad') {
      // A refused file shows its message over the canvas; the canvas itself was never drawn.
      const shown = await page.evaluate(() => {
        const box = document.getElementById('viewer').shadowRoot.querySelector('.message');
        return !box.hidden && box.textContent.length > 0 ? box.textContent : '';
      });
      result = { ok: settled && status.state === 'error' && shown !== '', state: status.state, message: shown, ms };
    } else if (command === 'probe') {
      result = await probe(page, options, file, settled, timeoutMs);
    } else if (!settled || status.state !== 'ready') {
      result = { ok: false, state: status.state, message: status.message || 'page did not finish loading', ms };
    } else if (command === 'shots') {
      mkdirSync(options.out, { recursive: true });
      const shots = {};
      for (const style of options.styles.split(',')) {
        const out = path.join(options.out, `${style}.png`);
        if (options.backend === 'webgpu' || options.capture) {
          // A WebGPU canvas cannot be read back here (its texture is gone once presented, and
          // SwiftShader's WebGPU canvas reads empty even in the frame's task): the page's
          // viewer.capture() renders the same frame offscreen and returns its pixels.
          const url = await page.evaluate(async (style) => {
            const v = document.getElementById('viewer');
            v.viewer.set_style(style);
            const rgba = await v.viewer.capture();
            const c = document.createElement('canvas');
            c.width = v.canvas.width;
            c.height = v.canvas.height;
            c.getContext('2d').putImageData(new ImageData(new Uint8ClampedArray(rgba.buffer), c.width, c.height), 0, 0);
            return c.toDataURL('image/png');
          }, style);
          writeFileSync(out, Buffer.from(url.split(',')[1], 'base64'));
        } else {
          const url = await page.evaluate((style) => {
            const v = document.getElementById('viewer');
            v.viewer.set_style(style);
            v.draw(false);
            return v.canvas.toDataURL('image/png'); // same task as the draw: the buffer is intact
          }, style);
          writeFileSync(out, Buffer.from(url.split(',')[1], 'base64'));
        }
        shots[style] = out;
      }
      let frameMs = [];
      if (options.frames) {
        frameMs = await page.evaluate(
          (style, n) => {
            const v = document.getElementById('viewer');
            v.viewer.set_style(style);
            const gl = v.canvas.getContext('webgl2'); // wgpu's own context on WebGL2, else null
            const pixel = new Uint8Array(4);
            const times = [];
            for (let k = 0; k < n; k++) {
              const t0 = performance.now();
              v.draw(false);
              gl?.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
              times.push(performance.now() - t0);
            }
            return times;
          },
          options.styles.split(',')[0],
          Number(options.frames),
        );
      }
      result = { ok: true, backend: status.backend, summary: status.summary, timings: status.timings, startup: status.startup, shots, frameMs, idleWaitMs };
    } else if (command === 'interact') {
      const pixels = () =>
        page.evaluate(() => {
          const v = document.getElementById('viewer');
          v.draw(false);
          return v.canvas.toDataURL('image/png');
        });
      const state = () => page.evaluate(() => document.getElementById('viewer').viewState());
      const before = await state();
      const firstImage = await pixels();
      // A left drag across the middle of the canvas, in steps, as a user's.
      await page.mouse.move(w / 2, h / 2);
      await page.mouse.down();
      for (let k = 1; k <= 10; k++) await page.mouse.move(w / 2 + 12 * k, h / 2 + 3 * k);
      await page.mouse.up();
      const after = await state();
      const secondImage = await pixels();
      await page.keyboard.press('3');
      const keyStyle = (await state()).style;
      const dragged = after.azimuth !== before.azimuth && after.elevation !== before.elevation;
      result = {
        ok: dragged && firstImage !== secondImage && keyStyle === 'gooch',
        before,
        after,
        keyStyle,
        pixelsChanged: firstImage !== secondImage,
      };
    } else {
      result = { ok: false, error: `unknown command ${command}` };
    }
  } catch (err) {
    result = { ok: false, error: String(err?.stack ?? err), consoleErrors };
  } finally {
    await browser.close().catch(() => {});
    killBrowser();
    await server.close();
    clearTimeout(watchdog);
  }
  result.consoleErrors = consoleErrors;
  // A refused file may log the refusal; any other console error fails the run (the probe reports them).
  if (!['bad', 'probe'].includes(command) && consoleErrors.length > 0) result.ok = false;
  console.log(JSON.stringify(result));
  process.exit(result.ok ? 0 : 1);
}

main();
