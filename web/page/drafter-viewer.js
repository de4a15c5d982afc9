// <drafter-viewer>: a baked drafter file (.glb) drawn in the browser by drafter's own renderer,
// compiled to WebAssembly (drafter_web.js and drafter_web_bg.wasm, beside this file; built by
// scripts/web). WebGPU where the browser gives an adapter, WebGL2 otherwise.
//
//   <script type="module" src="drafter-viewer.js"></script>
//   <drafter-viewer src="model.glb" style="width: 640px; height: 480px"></drafter-viewer>
//
// Attributes (all optional but src): shading (gradient, phong, cel, gooch, goochel, metal, hatch),
// edges, lines (present: on), shadow (none, hard, penumbra, soft), view ("AZ,EL" degrees, as
// `drafter render --view`), size ("WxH": a fixed canvas size in pixels instead of the element's),
// backend ("webgpu", "webgl2"; default: either), max-triangles (default 5,000,000), controls
// ("none" hides the toolbar), offscreen (present: nothing is drawn into the canvas, frames come
// from viewer.capture(); for tests). A file dropped on the element replaces the model.
//
// Mouse and keys as in `drafter view`: left drag turns the object, right or middle drag pans, the
// wheel zooms; 1-7 styles, S next style, E edges, L lines, H next shadow, O orthographic, R reset,
// P screenshot. Editing (selection, gradients, saving) is the desktop window's alone.
//
// For scripts and tests the element reports `state` ("starting", "loading", "ready", "error"),
// `message` (the error shown), `summary` (what was loaded), `timings` (ms since the page's start:
// wasmReady, fileFetched, modelLoaded, firstFrame) and fires "drafter-ready" / "drafter-error".

import init, { Viewer } from './drafter_web.js';

let module;
function loadModule() {
  module ??= init({ module_or_path: new URL('drafter_web_bg.wasm', import.meta.url) });
  return module;
}

const STYLES = ['gradient', 'cel', 'gooch', 'goochel', 'phong', 'metal', 'hatch'];
const SHADOWS = ['none', 'hard', 'penumbra', 'soft'];
const DEFAULT_MAX_TRIANGLES = 5_000_000;

const TEMPLATE = `
<style>
  :host { display: block; position: relative; min-width: 64px; min-height: 64px; background: #fff;
          font: 13px/1.4 system-ui, sans-serif; color: #222; outline: none; }
  canvas { display: block; width: 100%; height: 100%; touch-action: none; }
  .bar { position: absolute; left: 0; top: 0; right: 0; display: flex; flex-wrap: wrap; gap: 6px;
         align-items: center; padding: 4px 6px; background: rgba(255,255,255,0.85); }
  .bar[hidden] { display: none; }
  .bar label { white-space: nowrap; }
  .message { position: absolute; inset: 0; display: flex; align-items: center; justify-content: center;
             padding: 24px; text-align: center; background: #fff; white-space: pre-wrap; }
  .message[hidden] { display: none; }
  .message.error { color: #a00; }
  .note { position: absolute; right: 6px; bottom: 4px; color: #777; font-size: 11px; pointer-events: none; }
  :host(.dropping) { box-shadow: inset 0 0 0 3px #36c; }
</style>
<canvas></canvas>
<div class="bar" part="toolbar">
  <select name="style" title="style (1-7, S)"></select>
  <label title="image-space edges (E)"><input type="checkbox" name="edges"> edges</label>
  <label title="baked lines and silhouettes (L)"><input type="checkbox" name="lines"> lines</label>
  <select name="shadow" title="drop shadow (H)"></select>
  <label title="orthographic (O)"><input type="checkbox" name="ortho"> ortho</label>
  <button name="reset" title="reset the view (R)">reset</button>
  <button name="shot" title="save a PNG of the view (P)">screenshot</button>
</div>
<div class="message" part="message">starting...</div>
<div class="note">viewing only: editing is in the desktop window (drafter view)</div>
`;

function parseView(text) {
  const [az, el] = String(text ?? '').split(',').map(Number);
  return Number.isFinite(az) && Number.isFinite(el) ? [az, el] : null;
}

export class DrafterViewer extends HTMLElement {
  static observedAttributes = ['src'];

  constructor() {
    super();
    this.state = 'starting';
    this.message = '';
    this.summary = null;
    this.timings = {};
    this.viewer = null;
    this.name = 'model';
    this.queued = false;
    this.drag = null;
    const root = this.attachShadow({ mode: 'open' });
    root.innerHTML = TEMPLATE;
    this.canvas = root.querySelector('canvas');
    this.bar = root.querySelector('.bar');
    this.messageBox = root.querySelector('.message');
    this.controls = Object.fromEntries([...root.querySelectorAll('[name]')].map((e) => [e.name, e]));
    this.controls.style.innerHTML = STYLES.map((s) => `<option>${s}</option>`).join('');
    this.controls.shadow.innerHTML = SHADOWS.map((s) => `<option>${s}</option>`).join('');
  }

  connectedCallback() {
    if (!this.hasAttribute('tabindex')) this.tabIndex = 0;
    this.started ??= this.start();
  }

  attributeChangedCallback(name, old, value) {
    if (name === 'src' && value && old !== null && this.viewer) this.loadUrl(value);
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

  async start() {
    try {
      await loadModule();
      // Attributes a page sets right after the element is defined are there by now.
      this.bar.hidden = this.getAttribute('controls') === 'none';
      this.sizeCanvas();
      this.timings.wasmReady = performance.now();
      this.viewer = await Viewer.create(this.canvas, this.getAttribute('backend') ?? '');
    } catch (err) {
      this.fail(`This browser cannot run the viewer: ${err.message ?? err}`);
      return;
    }
    this.bindEvents();
    const src = this.getAttribute('src');
    if (src) await this.loadUrl(src);
    else {
      this.state = 'empty';
      this.say('Drop a baked .glb file here');
    }
  }

  sizeCanvas() {
    const fixed = /^(\d+)x(\d+)$/.exec(this.getAttribute('size') ?? '');
    let w, h;
    if (fixed) {
      [w, h] = [Number(fixed[1]), Number(fixed[2])];
      this.canvas.style.width = `${w}px`;
      this.canvas.style.height = `${h}px`;
    } else {
      const dpr = window.devicePixelRatio || 1;
      w = Math.max(1, Math.round(this.clientWidth * dpr));
      h = Math.max(1, Math.round(this.clientHeight * dpr));
    }
    if (this.canvas.width !== w || this.canvas.height !== h) {
      this.canvas.width = w;
      this.canvas.height = h;
    }
    this.viewer?.resize(w, h);
  }

  /** Fetches `url` and loads it. */
  async loadUrl(url) {
    this.state = 'loading';
    this.say(`loading ${url}...`);
    let bytes;
    try {
      const response = await fetch(url);
      if (!response.ok) throw new Error(`${response.status} ${response.statusText}`);
      bytes = new Uint8Array(await response.arrayBuffer());
    } catch (err) {
      this.fail(`Cannot fetch ${url}: ${err.message ?? err}`);
      return;
    }
    this.timings.fileFetched = performance.now();
    await this.loadBytes(bytes, decodeURIComponent(new URL(url, location.href).pathname.split('/').pop() || 'model.glb'));
  }

  /** Loads a model from its bytes; `name` gives the format (its extension) and the messages. */
  async loadBytes(bytes, name) {
    this.state = 'loading';
    this.say(`reading ${name} (${(bytes.length / 1e6).toFixed(1)} MB)...`);
    // Let the message paint before the (synchronous) load.
    await new Promise((resolve) => requestAnimationFrame(() => setTimeout(resolve, 0)));
    const limit = Number(this.getAttribute('max-triangles') ?? DEFAULT_MAX_TRIANGLES);
    try {
      this.summary = JSON.parse(this.viewer.load(bytes, name, limit));
    } catch (err) {
      this.fail(`Cannot show ${name}: ${err.message ?? err}`);
      return;
    }
    this.name = name.replace(/\.[^.]*$/, '');
    this.timings.modelLoaded = performance.now();
    this.applyAttributes();
    this.messageBox.hidden = true;
    try {
      this.draw(false);
    } catch (err) {
      this.fail(`Cannot draw ${name}: ${err.message ?? err}`);
      return;
    }
    // The frame is on screen once the browser has composited it.
    await new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve)));
    this.timings.firstFrame = performance.now();
    this.state = 'ready';
    this.dispatchEvent(new CustomEvent('drafter-ready', { detail: this.summary }));
  }

  applyAttributes() {
    const v = this.viewer;
    const shading = this.getAttribute('shading');
    if (shading) v.set_style(shading);
    v.set_edges(this.hasAttribute('edges') && this.getAttribute('edges') !== '0');
    v.set_lines(this.hasAttribute('lines') && this.getAttribute('lines') !== '0');
    v.set_shadow(this.getAttribute('shadow') ?? 'none');
    const view = parseView(this.getAttribute('view'));
    if (view) v.set_view(view[0], view[1], 1);
    this.syncControls();
  }

  syncControls() {
    const s = JSON.parse(this.viewer.state());
    this.controls.style.value = s.style;
    this.controls.edges.checked = s.edges;
    this.controls.lines.checked = s.lines;
    this.controls.shadow.value = s.shadow;
    this.controls.ortho.checked = s.orthographic;
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
    if (this.state !== 'ready') return false;
    const what = this.viewer.key(key);
    if (what === 'screenshot') this.screenshot();
    else if (what === 'redraw') {
      this.syncControls();
      this.redraw();
    }
    return what !== '';
  }

  bindEvents() {
    const c = this.controls;
    const v = this.viewer;
    const change = (f) => () => {
      if (this.state !== 'ready') return;
      f();
      this.redraw();
    };
    c.style.addEventListener('change', change(() => v.set_style(c.style.value)));
    c.edges.addEventListener('change', change(() => v.set_edges(c.edges.checked)));
    c.lines.addEventListener('change', change(() => v.set_lines(c.lines.checked)));
    c.shadow.addEventListener('change', change(() => v.set_shadow(c.shadow.value)));
    c.ortho.addEventListener('change', change(() => v.set_orthographic(c.ortho.checked)));
    c.reset.addEventListener('click', () => this.key('r'));
    c.shot.addEventListener('click', () => this.state === 'ready' && this.screenshot());

    this.addEventListener('keydown', (e) => {
      if (e.ctrlKey || e.metaKey || e.altKey || e.target !== this) return;
      if (this.key(e.key)) e.preventDefault();
    });
    const canvas = this.canvas;
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
        v.pan(dx * scale, dy * scale);
      } else v.rotate(dx, dy);
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
        v.zoom(-e.deltaY * (e.deltaMode === 1 ? 40 : 1));
        this.redraw();
      },
      { passive: false },
    );
    new ResizeObserver(() => this.redraw()).observe(this);

    this.addEventListener('dragover', (e) => {
      e.preventDefault();
      this.classList.add('dropping');
    });
    this.addEventListener('dragleave', () => this.classList.remove('dropping'));
    this.addEventListener('drop', async (e) => {
      e.preventDefault();
      this.classList.remove('dropping');
      const file = e.dataTransfer?.files?.[0];
      if (file) await this.loadBytes(new Uint8Array(await file.arrayBuffer()), file.name);
    });
  }
}

customElements.define('drafter-viewer', DrafterViewer);
