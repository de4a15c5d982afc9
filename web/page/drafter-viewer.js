// <drafter-viewer>: a baked drafter file (.glb) drawn in the browser by drafter's own renderer,
// compiled to WebAssembly (drafter_web.js and drafter_web_bg.wasm, beside this file; built by
// scripts/web). WebGPU where the browser gives an adapter, WebGL2 otherwise; a WebGPU device that
// is lost is replaced by WebGL2, and the page says so.
//
//   <script type="module" src="drafter-viewer.js"></script>
//   <drafter-viewer src="model.glb" style="width: 640px; height: 480px"></drafter-viewer>
//
// Attributes (all optional but src): shading (gradient, phong, cel, gooch, goochel, metal, hatch),
// edges, lines (present or true/1/on: on; false/0/off: off; default: on when the file carries baked
// lines), shadow (none, hard, penumbra, soft), view ("AZ,EL" degrees, as `drafter render --view`),
// size ("WxH": a fixed canvas size in pixels instead of the element's), backend ("webgpu",
// "webgl2"; default: either), max-triangles (default 5,000,000), controls ("none" hides the
// toolbar), offscreen (present: nothing is drawn into the canvas, frames come from
// viewer.capture(); for tests). A value the element does not know is an error on the page.
// Changed later, src loads the new file, shading, edges, lines, shadow and view apply to the model
// shown, size and controls to the layout; backend, offscreen and max-triangles are read when the
// element starts (and max-triangles at each load). Taken off the page, the element frees its
// viewer and GPU device; put back, it starts again.
// A file dropped on the element replaces the model: a .glb, or a .gltf together with its .bin and
// images (selected and dropped at once). Style, edges, lines and shadow stay as they are.
//
// Mouse and keys as in `drafter view`: left drag turns the object, right or middle drag pans, the
// wheel zooms; 1-7 styles, S next style, E edges, L lines, H next shadow, O orthographic, R reset,
// P screenshot; ? shows them. Editing (selection, gradients, saving) is the desktop window's alone.
// Line widths are in CSS pixels, whatever the screen's pixel density.
//
// For scripts and tests the element reports `state` ("starting", "loading", "ready", "error",
// "empty"), `message` (the error shown), `notice` (the note shown under the model, e.g. an unbaked
// file or a WebGPU device that was lost), `summary` (what was loaded), `timings` (ms since the
// page's start: wasmReady, viewerCreated, fileFetched, modelLoaded, firstFrame), `startup` (ms of the viewer's creation steps) and fires "drafter-ready" /
// "drafter-error".

import init, { KeyEffect, Viewer } from './drafter_web.js';

let module;
function loadModule() {
  module ??= init({ module_or_path: new URL('drafter_web_bg.wasm', import.meta.url) });
  return module;
}

/**
 * Resolves once the GPU has run every command the page gave it so far: a WebGL2 fence, polled
 * every few milliseconds (its status changes only between tasks); on WebGPU at once. Only the
 * first frame's timing waits for it: requestAnimationFrame alone fires before a CPU rasteriser
 * has finished a large frame.
 */
function gpuFinished(viewer, canvas) {
  // Asked only of a viewer on WebGL2, so that the call finds wgpu's context, never makes one.
  const gl = /Gl\b/.test(viewer.backend()) ? canvas.getContext('webgl2') : null;
  if (!gl || gl.isContextLost()) return Promise.resolve();
  const sync = gl.fenceSync(gl.SYNC_GPU_COMMANDS_COMPLETE, 0);
  if (!sync) return Promise.resolve();
  gl.flush();
  return new Promise((resolve) => {
    const poll = () => {
      if (gl.isContextLost() || gl.getSyncParameter(sync, gl.SYNC_STATUS) === gl.SIGNALED) {
        gl.deleteSync(sync);
        resolve();
      } else setTimeout(poll, 4);
    };
    setTimeout(poll, 0);
  });
}

/** A module object's fields (its getters) as a plain object, which scripts and tests can copy; frees it. */
function fields(object) {
  const out = {};
  for (const [key, d] of Object.entries(Object.getOwnPropertyDescriptors(Object.getPrototypeOf(object)))) {
    if (d.get) out[key] = object[key];
  }
  object.free();
  return out;
}

const STYLES = ['gradient', 'cel', 'gooch', 'goochel', 'phong', 'metal', 'hatch'];
const SHADOWS = ['none', 'hard', 'penumbra', 'soft'];
const BACKENDS = ['webgpu', 'webgl2'];
const DEFAULT_MAX_TRIANGLES = 5_000_000;
/** The settings a new file keeps (the viewer's state names). */
const KEPT = ['style', 'edges', 'lines', 'shadow', 'orthographic'];
const MODEL_EXTENSIONS = ['glb', 'gltf', 'obj', 'stl', 'ply', 'off'];

const HELP = `
<h2>drafter viewer</h2>
<table>
  <tr><th>left drag</th><td>turn the object</td></tr>
  <tr><th>right or middle drag</th><td>pan</td></tr>
  <tr><th>wheel</th><td>zoom</td></tr>
  <tr><th>1 – 7</th><td>gradient, cel, gooch, goochel, phong, metal, hatch</td></tr>
  <tr><th>S</th><td>next style</td></tr>
  <tr><th>E</th><td>image-space edges on or off</td></tr>
  <tr><th>L</th><td>baked lines and silhouettes on or off</td></tr>
  <tr><th>H</th><td>next drop shadow</td></tr>
  <tr><th>O</th><td>orthographic on or off</td></tr>
  <tr><th>R</th><td>reset the view</td></tr>
  <tr><th>P</th><td>save a PNG of the view</td></tr>
  <tr><th>?</th><td>this help (Esc closes it)</td></tr>
</table>
<p>Drop a baked .glb on the page to show it, or a .gltf together with its .bin and images.</p>
<p class="note">Viewing only: editing (selection, gradients, saving) is in the desktop window, <code>drafter view</code>.</p>
<button name="close-help" aria-label="close the help">close</button>
`;

const TEMPLATE = `
<style>
  :host { display: flex; flex-direction: column; position: relative; min-width: 64px; min-height: 64px;
          background: #fff; font: 13px/1.4 system-ui, sans-serif; color: #222; outline: none; }
  .bar { flex: none; display: flex; flex-wrap: wrap; gap: 6px 10px; align-items: center; padding: 4px 6px;
         background: #f4f4f4; border-bottom: 1px solid #ddd; }
  .bar[hidden] { display: none; }
  .bar label { white-space: nowrap; }
  .bar label.off { color: #999; }
  .stage { flex: 1 1 0; position: relative; min-height: 0; overflow: hidden; }
  canvas { position: absolute; left: 0; top: 0; display: block; width: 100%; height: 100%; touch-action: none; }
  .message { position: absolute; inset: 0; display: flex; align-items: center; justify-content: center;
             padding: 24px; text-align: center; background: #fff; white-space: pre-wrap; }
  .message[hidden] { display: none; }
  .message.error { color: #a00; }
  .notice { position: absolute; left: 6px; bottom: 6px; max-width: calc(100% - 12px); box-sizing: border-box;
            padding: 4px 28px 4px 8px; background: #fff8d8; border: 1px solid #e0c860; border-radius: 3px;
            font-size: 12px; }
  .notice[hidden] { display: none; }
  .notice button { position: absolute; right: 2px; top: 1px; border: none; background: none; cursor: pointer; }
  .help { position: absolute; inset: 0; overflow: auto; padding: 12px 18px; background: rgba(255,255,255,0.96); }
  .help[hidden] { display: none; }
  .help h2 { font-size: 15px; margin: 0 0 8px; }
  .help th { text-align: left; padding-right: 16px; font-weight: 600; white-space: nowrap; }
  .help .note { color: #555; }
  :host(.dropping) { box-shadow: inset 0 0 0 3px #36c; }
</style>
<div class="bar" part="toolbar" role="toolbar" aria-label="view settings">
  <label title="style (keys 1-7, S)">style <select name="style"></select></label>
  <label title="image-space edges (E)"><input type="checkbox" name="edges"> edges</label>
  <label title="baked lines and silhouettes (L)"><input type="checkbox" name="lines"> lines</label>
  <label title="drop shadow (H)">shadow <select name="shadow"></select></label>
  <label title="orthographic (O)"><input type="checkbox" name="ortho"> ortho</label>
  <button name="reset" title="reset the view (R)">reset</button>
  <button name="shot" title="save a PNG of the view (P)">screenshot</button>
  <button name="help" title="mouse and keys (?)" aria-label="help: mouse and keys">? help</button>
</div>
<div class="stage">
  <canvas></canvas>
  <div class="notice" part="notice" role="status" hidden><span></span><button name="close-notice" aria-label="close the note">×</button></div>
  <div class="message" part="message" role="alert">starting...</div>
  <div class="help" part="help" role="dialog" aria-label="mouse and keys" hidden>${HELP}</div>
</div>
`;

/** A boolean attribute: absent is `undefined`; present with no value, true/1/on/yes or false/0/off/no. */
function parseBool(name, value) {
  if (value === null || value === undefined) return undefined;
  const v = value.trim().toLowerCase();
  if (['', 'true', '1', 'on', 'yes'].includes(v)) return true;
  if (['false', '0', 'off', 'no'].includes(v)) return false;
  throw new Error(`${name}="${value}" is not on or off: use true/false, 1/0 or on/off`);
}

function parseChoice(name, value, choices) {
  if (value === null) return undefined;
  if (!choices.includes(value)) throw new Error(`${name}="${value}" is not one of ${choices.join(', ')}`);
  return value;
}

function parseView(text) {
  if (text === null) return undefined;
  const [az, el, extra] = String(text).split(',').map((s) => (s.trim() === '' ? NaN : Number(s)));
  if (!Number.isFinite(az) || !Number.isFinite(el) || extra !== undefined || el <= -90 || el >= 90) {
    throw new Error(`view="${text}" is not AZ,EL in degrees (elevation between -90 and 90)`);
  }
  return [az, el];
}

/** The element's attributes, checked: an unknown value throws, with a message for the page. */
function readAttributes(element) {
  const get = (name) => element.getAttribute(name);
  const size = get('size');
  if (size !== null && !/^[1-9]\d*x[1-9]\d*$/.test(size)) throw new Error(`size="${size}" is not WxH in pixels`);
  const maxTriangles = get('max-triangles');
  if (maxTriangles !== null && !/^\d+$/.test(maxTriangles.trim())) {
    throw new Error(`max-triangles="${maxTriangles}" is not a whole number`);
  }
  return {
    style: parseChoice('style', get('shading'), STYLES),
    edges: parseBool('edges', get('edges')),
    lines: parseBool('lines', get('lines')),
    shadow: parseChoice('shadow', get('shadow'), SHADOWS),
    view: parseView(get('view')),
    backend: parseChoice('backend', get('backend'), BACKENDS),
    maxTriangles: maxTriangles === null ? DEFAULT_MAX_TRIANGLES : Number(maxTriangles),
    offscreen: parseBool('offscreen', get('offscreen')) ?? false,
  };
}

function extension(name) {
  const m = /\.([^./]+)$/.exec(name);
  return m ? m[1].toLowerCase() : '';
}

function base64(bytes) {
  let text = '';
  for (let i = 0; i < bytes.length; i += 0x8000) text += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
  return btoa(text);
}

const IMAGE_TYPES = { png: 'image/png', jpg: 'image/jpeg', jpeg: 'image/jpeg', webp: 'image/webp', ktx2: 'image/ktx2' };

/**
 * A .gltf whose buffers and images are files beside it, made self-contained: each relative URI
 * becomes a data: URI of the bytes `read(uri)` gives (a dropped file of that name, or a fetch next
 * to the .gltf's URL). Throws naming the files that are missing.
 */
async function inlineGltf(bytes, name, read, dropped) {
  let json;
  try {
    json = JSON.parse(new TextDecoder().decode(bytes));
  } catch {
    return bytes; // not JSON: the reader says what is wrong
  }
  const refs = [...(json.buffers ?? []), ...(json.images ?? [])].filter((r) => typeof r.uri === 'string' && !r.uri.startsWith('data:'));
  if (refs.length === 0) return bytes;
  const missing = [];
  for (const ref of refs) {
    const file = await read(ref.uri);
    if (!file) {
      missing.push(decodeURIComponent(ref.uri));
      continue;
    }
    const type = IMAGE_TYPES[extension(ref.uri)] ?? 'application/octet-stream';
    ref.uri = `data:${type};base64,${base64(file)}`;
  }
  if (missing.length > 0) {
    const what = missing.join(', ');
    throw new Error(
      dropped
        ? `${name} refers to ${what}, which ${missing.length > 1 ? 'were' : 'was'} not dropped: select the .gltf together with ${what} and drop them at once`
        : `${name} refers to ${what}, which cannot be fetched beside it`,
    );
  }
  return new TextEncoder().encode(JSON.stringify(json));
}

export class DrafterViewer extends HTMLElement {
  static observedAttributes = ['src', 'shading', 'edges', 'lines', 'shadow', 'view', 'size', 'controls'];

  constructor() {
    super();
    this.state = 'starting';
    this.message = '';
    this.notice = '';
    this.summary = null;
    this.timings = {};
    this.viewer = null;
    /** Counts the times the element left the page: a start or load under way stops at its next step when it changes. */
    this.generation = 0;
    this.onDeviceLost = (e) => e.detail && this.deviceLost(e.detail);
    this.name = 'model';
    this.queued = false;
    this.drag = null;
    /** Settings the user changed (keys, toolbar, a lost device's): kept for the next file. */
    this.choices = {};
    this.loads = 0;
    this.model = null; // { bytes, name } of the model shown, to show it again on a new device
    const root = this.attachShadow({ mode: 'open' });
    root.innerHTML = TEMPLATE;
    this.canvas = root.querySelector('canvas');
    this.stage = root.querySelector('.stage');
    this.bar = root.querySelector('.bar');
    this.messageBox = root.querySelector('.message');
    this.noticeBox = root.querySelector('.notice');
    this.helpBox = root.querySelector('.help');
    this.controls = Object.fromEntries([...root.querySelectorAll('[name]')].map((e) => [e.name, e]));
    this.controls.style.innerHTML = STYLES.map((s) => `<option>${s}</option>`).join('');
    this.controls.shadow.innerHTML = SHADOWS.map((s) => `<option>${s}</option>`).join('');
  }

  connectedCallback() {
    if (!this.hasAttribute('tabindex')) this.tabIndex = 0;
    addEventListener('drafter-device-lost', this.onDeviceLost);
    this.started ??= this.start();
  }

  /** Taken off the page: the viewer and its GPU device are freed. Put back, the element starts again. */
  disconnectedCallback() {
    removeEventListener('drafter-device-lost', this.onDeviceLost);
    this.generation += 1;
    this.viewer?.free();
    this.viewer = null;
    this.started = null;
    this.state = 'starting';
  }

  /**
   * An attribute changed after the element started: a new `src` loads; the settings (shading,
   * edges, lines, shadow, view) apply to the model shown, over what the user chose; `size` and
   * `controls` change the layout. A value the element does not know is an error on the page, as
   * at the start. (`backend`, `offscreen` and `max-triangles` are read when the element starts and
   * when a file loads.)
   */
  attributeChangedCallback(name, old, value) {
    if (old === value || !this.viewer) return;
    if (name === 'src') {
      if (value) this.loadUrl(value);
      return;
    }
    if (name === 'controls') {
      this.bar.hidden = value === 'none';
      return;
    }
    let attributes;
    try {
      attributes = readAttributes(this);
    } catch (err) {
      this.fail(`Cannot show the model: ${err.message}`);
      return;
    }
    if (this.state !== 'ready') return;
    const v = this.viewer;
    const key = { shading: 'style', edges: 'edges', lines: 'lines', shadow: 'shadow' }[name];
    if (key) {
      delete this.choices[key];
      const carries = Boolean(this.summary?.lines);
      const fallback = { style: STYLES[0], edges: carries, lines: carries, shadow: SHADOWS[0] }[key]; // the defaults
      const chosen = attributes[key] ?? fallback;
      if (key === 'style') v.set_style(chosen);
      else if (key === 'edges') v.set_edges(chosen);
      else if (key === 'lines') v.set_lines(chosen);
      else v.set_shadow(chosen);
      this.syncControls();
    } else if (name === 'view' && attributes.view) v.set_view(attributes.view[0], attributes.view[1], 1);
    this.redraw();
  }

  /** Shows `text` over the canvas (an error in red) and records it. */
  fail(text) {
    this.state = 'error';
    this.message = text;
    this.messageBox.textContent = text;
    this.messageBox.className = 'message error';
    this.messageBox.hidden = false;
    this.dispatchEvent(new CustomEvent('drafter-error', { detail: text }));
  }

  say(text) {
    this.messageBox.textContent = text;
    this.messageBox.className = 'message';
    this.messageBox.hidden = false;
  }

  /** Shows a note under the model (empty: none). */
  note(text) {
    this.notice = text;
    this.noticeBox.querySelector('span').textContent = text;
    this.noticeBox.hidden = !text;
  }

  showHelp(show = this.helpBox.hidden) {
    const shown = !this.helpBox.hidden;
    this.helpBox.hidden = !show;
    if (show) this.controls['close-help'].focus();
    else if (shown) this.focus();
  }

  async start() {
    const generation = this.generation;
    const loading = loadModule();
    loading.catch(() => {}); // reported below
    // Attributes a page sets right after the element is defined (index.html) are there on the next task.
    await new Promise((resolve) => setTimeout(resolve, 0));
    // The file downloads while the module compiles and the device is requested.
    let src = this.getAttribute('src');
    let pending = src ? this.fetchModel(src) : null;
    pending?.catch(() => {}); // reported by loadUrl
    try {
      await loading;
    } catch (err) {
      this.fail(`This browser cannot run the viewer: ${err.message ?? err}`);
      return;
    }
    this.timings.wasmReady = performance.now();
    if (generation !== this.generation) return;
    let attributes;
    try {
      this.bar.hidden = this.getAttribute('controls') === 'none';
      attributes = readAttributes(this);
    } catch (err) {
      this.fail(`Cannot show the model: ${err.message}`);
      return;
    }
    this.bindEvents();
    if (this.getAttribute('src') !== src) {
      src = this.getAttribute('src');
      pending = src ? this.fetchModel(src) : null;
      pending?.catch(() => {});
    }
    try {
      this.sizeCanvas();
      const viewer = await Viewer.create(this.canvas, attributes.backend ?? '');
      if (generation !== this.generation) {
        viewer.free();
        return;
      }
      this.viewer = viewer;
      this.timings.viewerCreated = performance.now();
      this.startup = fields(this.viewer.startup());
    } catch (err) {
      this.fail(`This browser cannot run the viewer: ${err.message ?? err}`);
      return;
    }
    if (src) {
      this.warmPipelines(attributes);
      await this.loadUrl(src, pending);
    } else {
      this.state = 'empty';
      this.say('Drop a baked .glb file here');
    }
  }

  /** The drawing area's size in canvas pixels, and the canvas's pixels per CSS pixel. */
  sizeCanvas() {
    const fixed = /^(\d+)x(\d+)$/.exec(this.getAttribute('size') ?? '');
    let w, h;
    if (fixed) {
      [w, h] = [Number(fixed[1]), Number(fixed[2])];
      this.canvas.style.width = `${w}px`;
      this.canvas.style.height = `${h}px`;
    } else {
      const dpr = window.devicePixelRatio || 1;
      w = Math.max(1, Math.round(this.stage.clientWidth * dpr));
      h = Math.max(1, Math.round(this.stage.clientHeight * dpr));
    }
    if (this.canvas.width !== w || this.canvas.height !== h) {
      this.canvas.width = w;
      this.canvas.height = h;
    }
    if (this.viewer) {
      this.viewer.resize(w, h);
      // Line widths in CSS pixels: a canvas of devicePixelRatio pixels per CSS pixel draws them wider.
      const shown = this.canvas.clientWidth;
      this.viewer.set_line_scale(shown > 0 ? w / shown : window.devicePixelRatio || 1);
    }
  }

  /** Fetches `url` (and a .gltf's files beside it): { bytes, name }. */
  async fetchModel(url) {
    const name = decodeURIComponent(new URL(url, location.href).pathname.split('/').pop() || 'model.glb');
    const fetchBytes = async (u) => {
      const response = await fetch(u);
      if (!response.ok) throw new Error(`${response.status} ${response.statusText}`);
      return new Uint8Array(await response.arrayBuffer());
    };
    let bytes = await fetchBytes(url);
    if (extension(name) === 'gltf') {
      const base = new URL(url, location.href);
      bytes = await inlineGltf(bytes, name, (uri) => fetchBytes(new URL(uri, base)).catch(() => null), false);
    }
    return { bytes, name };
  }

  /** Loads the model at `url`; `pending`: its fetch, if already started. */
  async loadUrl(url, pending) {
    this.state = 'loading';
    this.say(`loading ${url}...`);
    let model;
    try {
      model = await (pending ?? this.fetchModel(url));
    } catch (err) {
      this.fail(`Cannot fetch ${url}: ${err.message ?? err}`);
      return;
    }
    this.timings.fileFetched = performance.now();
    await this.loadBytes(model.bytes, model.name);
  }

  /** Loads dropped files: one model, or a .gltf with the files it refers to. */
  async loadFiles(files) {
    const all = [...files];
    const main = all.find((f) => extension(f.name) === 'gltf') ?? all.find((f) => MODEL_EXTENSIONS.includes(extension(f.name))) ?? all[0];
    if (!main) return;
    this.state = 'loading';
    this.say(`reading ${main.name}...`);
    let bytes;
    try {
      bytes = new Uint8Array(await main.arrayBuffer());
      if (extension(main.name) === 'gltf') {
        const byName = new Map(all.map((f) => [f.name, f]));
        const read = async (uri) => {
          const file = byName.get(decodeURIComponent(uri).split(/[\\/]/).pop());
          return file ? new Uint8Array(await file.arrayBuffer()) : null;
        };
        bytes = await inlineGltf(bytes, main.name, read, true);
      }
    } catch (err) {
      this.fail(`Cannot show ${main.name}: ${err.message ?? err}`);
      return;
    }
    await this.loadBytes(bytes, main.name);
  }

  /** Loads a model from its bytes; `name` gives the format (its extension) and the messages. */
  async loadBytes(bytes, name) {
    this.state = 'loading';
    this.showHelp(false);
    this.say(`reading ${name} (${(bytes.length / 1e6).toFixed(1)} MB)...`);
    // Let the message paint before the (synchronous) load.
    await new Promise((resolve) => requestAnimationFrame(() => setTimeout(resolve, 0)));
    if (!this.viewer) return; // taken off the page meanwhile
    try {
      const attributes = readAttributes(this);
      this.summary = fields(this.viewer.load(bytes, name, attributes.maxTriangles));
      this.model = { bytes, name };
      this.name = name.replace(/\.[^.]*$/, '');
      this.timings.modelLoaded = performance.now();
      this.applySettings(attributes);
    } catch (err) {
      this.fail(`Cannot show ${name}: ${err.message ?? err}`);
      return;
    }
    this.messageBox.hidden = true;
    this.loads += 1;
    try {
      this.draw(false);
    } catch (err) {
      this.fail(`Cannot draw ${name}: ${err.message ?? err}`);
      return;
    }
    // The frame is on screen once the GPU has drawn it and the browser has composited it.
    await gpuFinished(this.viewer, this.canvas);
    await new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve)));
    this.timings.firstFrame = performance.now();
    this.state = 'ready';
    this.dispatchEvent(new CustomEvent('drafter-ready', { detail: this.summary }));
    // The silhouette hierarchies were left for after the first frame (brute force answered it):
    // built on a later task, so the frame is on screen first.
    // One mesh a task, so input between them is not held up.
    const viewer = this.viewer;
    const loads = this.loads;
    const step = () => {
      if (this.viewer !== viewer || this.loads !== loads) return;
      try {
        if (viewer.complete_load() > 0) setTimeout(step, 0);
        else this.timings.hierarchiesBuilt = performance.now();
      } catch (err) {
        console.warn(`drafter: silhouette hierarchies not built: ${err.message ?? err}`);
      }
    };
    setTimeout(step, 0);
  }

  /**
   * The settings of a newly loaded file: what the user chose before (kept across files), else the
   * attributes, else the defaults: edges and lines on when the file carries baked lines. The view
   * is the attribute's (or the default) for every file. Notes an unbaked file.
   */
  applySettings(attributes) {
    const v = this.viewer;
    const carries = Boolean(this.summary.lines);
    const pick = (key, fromAttribute, fallback) => this.pick(key, fromAttribute, fallback);
    v.set_style(pick('style', attributes.style, this.viewState().style));
    v.set_edges(pick('edges', attributes.edges, carries));
    v.set_lines(pick('lines', attributes.lines, carries));
    v.set_shadow(pick('shadow', attributes.shadow, 'none'));
    v.set_orthographic(pick('orthographic', undefined, false));
    if (attributes.view) v.set_view(attributes.view[0], attributes.view[1], 1);
    const notes = [];
    if (this.lostNote) notes.push(this.lostNote);
    if (!this.summary.baked) {
      notes.push(
        `${this.summary.name} is not baked: each object is drawn as one part, with no baked lines or gradients. ` +
          'Bake it first (drafter bake FILE -o FILE.glb).',
      );
    } else if (!carries) {
      notes.push(`${this.summary.name} carries no baked lines: "lines" has nothing to draw.`);
    }
    this.note(notes.join(' '));
    this.syncControls();
  }

  /** A setting: what the user chose before, else the attribute's value, else `fallback`. */
  pick(key, fromAttribute, fallback) {
    return this.choices[key] ?? fromAttribute ?? fallback;
  }

  /**
   * Compiles the pipelines the first frame will most likely draw with (a baked file's defaults:
   * edges and lines on) before the file is read: the browser's GPU process then compiles them
   * during the read instead of at the first draw. A file that asks for others compiles those then.
   */
  warmPipelines(attributes) {
    try {
      this.viewer.warm_pipelines(
        this.pick('style', attributes.style, this.viewState().style),
        this.pick('edges', attributes.edges, true),
        this.pick('lines', attributes.lines, true),
        this.pick('shadow', attributes.shadow, 'none'),
      );
    } catch (err) {
      console.warn(`drafter: pipelines not compiled ahead: ${err.message ?? err}`);
    }
  }

  /** The frame's settings: style, edges, lines, shadow, orthographic, azimuth, elevation, zoom, panX, panY, width, height. */
  viewState() {
    return fields(this.viewer.state());
  }

  syncControls() {
    const s = this.viewState();
    this.controls.style.value = s.style;
    this.controls.edges.checked = s.edges;
    this.controls.lines.checked = s.lines;
    this.controls.shadow.value = s.shadow;
    this.controls.ortho.checked = s.orthographic;
    const none = this.summary && !this.summary.lines;
    this.controls.lines.disabled = Boolean(none);
    this.controls.lines.parentElement.classList.toggle('off', Boolean(none));
    this.controls.lines.parentElement.title = none
      ? 'this file carries no baked lines (bake it for lines)'
      : 'baked lines and silhouettes (L)';
  }

  /** Runs `change` (a user's key or control) and remembers the settings it changed for the next file. */
  userChange(change) {
    const before = this.viewState();
    const result = change();
    const after = this.viewState();
    for (const key of KEPT) if (before[key] !== after[key]) this.choices[key] = after[key];
    return result;
  }

  /** Draws now (`interactive`: the reduced frame of a drag). */
  draw(interactive) {
    this.sizeCanvas();
    // `offscreen`: nothing is presented; frames come from viewer.capture() alone (headless
    // Chromium on SwiftShader loses its WebGPU device when a WebGPU canvas is presented).
    if (this.hasAttribute('offscreen')) return 0;
    return this.viewer.render(interactive);
  }

  /** Draws at the next animation frame (once, however many changes come before it). */
  redraw(interactive = false) {
    this.interactive = interactive;
    if (this.queued || this.state !== 'ready') return;
    this.queued = true;
    requestAnimationFrame(() => {
      this.queued = false;
      if (this.state !== 'ready') return;
      try {
        this.draw(this.interactive);
      } catch (err) {
        this.fail(`Cannot draw: ${err.message ?? err}`);
      }
    });
  }

  screenshot() {
    this.draw(false);
    // Read in the same task as the draw, before the browser clears the drawing buffer.
    this.canvas.toBlob((blob) => {
      const a = document.createElement('a');
      a.href = URL.createObjectURL(blob);
      a.download = `${this.name}.png`;
      a.click();
      setTimeout(() => URL.revokeObjectURL(a.href), 10_000);
    }, 'image/png');
  }

  key(key) {
    if (key === '?') {
      this.showHelp();
      return true;
    }
    if (key === 'Escape' && !this.helpBox.hidden) {
      this.showHelp(false);
      return true;
    }
    if (this.state !== 'ready') return false;
    const what = this.userChange(() => this.viewer.key(key));
    if (what === KeyEffect.Screenshot) this.screenshot();
    else if (what === KeyEffect.Redraw) {
      this.syncControls();
      this.redraw();
    }
    return what !== KeyEffect.Nothing;
  }

  /**
   * The GPU device of viewer `id` was lost: on WebGPU, a new viewer on WebGL2 (on a new canvas: a
   * canvas keeps the first context it gave) shows the same model with the same settings.
   */
  async deviceLost(detail) {
    if (!this.viewer || detail.id !== this.viewer.id()) return;
    const old = this.viewer;
    const wasWebGpu = /WebGpu/i.test(old.backend());
    const settings = this.viewState();
    this.viewer = null;
    this.state = 'loading';
    if (!wasWebGpu) {
      this.fail(`The GPU device was lost (${detail.reason}: ${detail.message}): reload the page to draw again`);
      return;
    }
    this.say('The WebGPU device was lost: starting WebGL2...');
    const canvas = document.createElement('canvas');
    for (const a of this.canvas.getAttributeNames()) canvas.setAttribute(a, this.canvas.getAttribute(a));
    this.canvas.replaceWith(canvas);
    this.canvas = canvas;
    this.bindCanvas(canvas);
    try {
      this.sizeCanvas();
      this.viewer = await Viewer.create(canvas, 'webgl2');
    } catch (err) {
      this.fail(`The WebGPU device was lost and WebGL2 cannot start: ${err.message ?? err}`);
      return;
    }
    try {
      old.free();
    } catch {
      // already gone with its device
    }
    for (const key of KEPT) this.choices[key] = settings[key];
    this.lostNote = `The WebGPU device was lost (${detail.reason}); now drawing with WebGL2.`;
    if (this.model) {
      await this.loadBytes(this.model.bytes, this.model.name);
      this.viewer.set_view(settings.azimuth, settings.elevation, settings.zoom);
      this.redraw();
    } else {
      this.state = 'empty';
      this.note(this.lostNote);
      this.say('Drop a baked .glb file here');
    }
  }

  bindEvents() {
    if (this.bound) return;
    this.bound = true;
    const c = this.controls;
    const change = (f) => () => {
      if (this.state !== 'ready') return;
      this.userChange(f);
      this.redraw();
    };
    c.style.addEventListener('change', change(() => this.viewer.set_style(c.style.value)));
    c.edges.addEventListener('change', change(() => this.viewer.set_edges(c.edges.checked)));
    c.lines.addEventListener('change', change(() => this.viewer.set_lines(c.lines.checked)));
    c.shadow.addEventListener('change', change(() => this.viewer.set_shadow(c.shadow.value)));
    c.ortho.addEventListener('change', change(() => this.viewer.set_orthographic(c.ortho.checked)));
    c.reset.addEventListener('click', () => this.key('r'));
    c.shot.addEventListener('click', () => this.state === 'ready' && this.screenshot());
    c.help.addEventListener('click', () => this.showHelp());
    c['close-help'].addEventListener('click', () => this.showHelp(false));
    c['close-notice'].addEventListener('click', () => this.note(''));

    this.addEventListener('keydown', (e) => {
      if (e.ctrlKey || e.metaKey || e.altKey) return;
      // Keys typed in the toolbar's controls are theirs, but ? and Esc.
      const own = e.composedPath()[0] === this || ['?', 'Escape'].includes(e.key);
      if (own && this.key(e.key)) e.preventDefault();
    });
    addEventListener('drafter-device-lost', this.onDeviceLost);
    this.bindCanvas(this.canvas);
    new ResizeObserver(() => this.redraw()).observe(this.stage);

    this.addEventListener('dragover', (e) => {
      e.preventDefault();
      this.classList.add('dropping');
    });
    this.addEventListener('dragleave', () => this.classList.remove('dropping'));
    this.addEventListener('drop', async (e) => {
      e.preventDefault();
      this.classList.remove('dropping');
      const files = e.dataTransfer?.files;
      if (files?.length && this.viewer) await this.loadFiles(files);
    });
  }

  bindCanvas(canvas) {
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('pointerdown', (e) => {
      this.focus();
      this.drag = { x: e.clientX, y: e.clientY, pan: e.button !== 0 };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!this.drag || this.state !== 'ready') return;
      const [dx, dy] = [e.clientX - this.drag.x, e.clientY - this.drag.y];
      [this.drag.x, this.drag.y] = [e.clientX, e.clientY];
      if (this.drag.pan) {
        const scale = canvas.width / Math.max(1, canvas.clientWidth);
        this.viewer.pan(dx * scale, dy * scale);
      } else this.viewer.rotate(dx, dy);
      this.redraw(true);
    });
    const release = () => {
      if (!this.drag) return;
      this.drag = null;
      this.redraw(false);
    };
    canvas.addEventListener('pointerup', release);
    canvas.addEventListener('pointercancel', release);
    canvas.addEventListener(
      'wheel',
      (e) => {
        e.preventDefault();
        if (this.state !== 'ready') return;
        this.viewer.zoom(-e.deltaY * (e.deltaMode === 1 ? 40 : 1));
        this.redraw();
      },
      { passive: false },
    );
  }
}

customElements.define('drafter-viewer', DrafterViewer);
