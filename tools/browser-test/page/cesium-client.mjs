// CesiumJS client: a CesiumWidget without globe, imagery or Ion; loads the model with Model.fromGltfAsync
// (edges from EXT_mesh_primitive_edge_visibility on or off), aims the camera at its bounding sphere and
// reports once the model is ready and a few frames have been drawn.

import { params, viewDirection, FOV_DEGREES, MARGIN, finish, failure } from './common.mjs';

// Cesium fetches its workers, assets and third-party wasm relative to this URL.
const CESIUM_BASE = '/node_modules/cesium/Build/Cesium/';
window.CESIUM_BASE_URL = CESIUM_BASE;

function loadScript(src) {
  return new Promise((resolve, reject) => {
    const script = document.createElement('script');
    script.src = src;
    script.onload = resolve;
    script.onerror = () => reject(new Error(`cannot load ${src}`));
    document.head.appendChild(script);
  });
}

function loadCss(href) {
  const link = document.createElement('link');
  link.rel = 'stylesheet';
  link.href = href;
  document.head.appendChild(link);
}

/** Resolves after `count` frames have been rendered. */
function frames(scene, count) {
  return new Promise((resolve) => {
    let seen = 0;
    const remove = scene.postRender.addEventListener(() => {
      if (++seen >= count) {
        remove();
        resolve();
      }
    });
  });
}

/** Resolves when the model is ready to draw; rejects on its first error. */
function ready(model) {
  return new Promise((resolve, reject) => {
    if (model.ready) return resolve();
    model.readyEvent.addEventListener(() => resolve());
    model.errorEvent.addEventListener((err) => reject(err instanceof Error ? err : new Error(String(err?.message ?? err))));
  });
}

/**
 * Places the camera on the model's bounding sphere, looking from (azimuth, elevation) given in the model's
 * own glTF axes. Cesium turns glTF's +Y-up / +Z-forward into its +Z-up / +X-forward with two fixed axis
 * matrices, applied before the model matrix; the same matrices carry our view direction into the world.
 */
function aimCamera(Cesium, scene, model, p) {
  const { Cartesian3, Matrix3, Matrix4, Axis } = Cesium;
  const toWorld = Matrix4.multiplyTransformation(
    Matrix4.multiplyTransformation(model.modelMatrix, Axis.Y_UP_TO_Z_UP, new Matrix4()),
    Axis.Z_UP_TO_X_UP,
    new Matrix4(),
  );
  const rotation = Matrix4.getMatrix3(toWorld, new Matrix3());
  const local = (v) => Cartesian3.normalize(Matrix3.multiplyByVector(rotation, Cartesian3.fromArray(v), new Cartesian3()), new Cartesian3());

  const view = viewDirection(p.azimuth, p.elevation); // centre -> camera
  const dir = local(view);
  // Looking straight down or up: "up" must not be parallel to the view direction.
  let up = local(Math.abs(view[1]) > 0.999 ? [0, 0, -Math.sign(view[1])] : [0, 1, 0]);
  // Make "up" perpendicular to the view direction.
  up = Cartesian3.normalize(
    Cartesian3.subtract(up, Cartesian3.multiplyByScalar(dir, Cartesian3.dot(up, dir), new Cartesian3()), new Cartesian3()),
    new Cartesian3(),
  );

  // The sphere around the scene's box that run.mjs computed from the file (CesiumJS's own sphere ignores how
  // each node turns its box); CesiumJS's when the file gave none.
  let sphere = model.boundingSphere;
  if (p.box && p.box.length === 6 && p.box.every(Number.isFinite)) {
    const [x0, y0, z0, x1, y1, z1] = p.box;
    const centre = Matrix4.multiplyByPoint(toWorld, new Cartesian3((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2), new Cartesian3());
    const scale = Matrix4.getMaximumScale(toWorld);
    sphere = { center: centre, radius: (scale * Math.hypot(x1 - x0, y1 - y0, z1 - z0)) / 2 };
  }
  const radius = Math.max(sphere.radius, 1e-6);
  const canvas = scene.canvas;
  const aspect = canvas.clientWidth / canvas.clientHeight;
  const camera = scene.camera;
  const halfFov = (FOV_DEGREES / 2) * (Math.PI / 180);
  const distance = p.ortho ? 3 * radius : (MARGIN * radius) / Math.sin(halfFov);
  if (p.ortho) {
    camera.frustum = new Cesium.OrthographicFrustum({ aspectRatio: aspect });
  } else {
    // Cesium's fov is the horizontal one when the canvas is wider than tall.
    camera.frustum.fov = aspect > 1 ? 2 * Math.atan(Math.tan(halfFov) * aspect) : 2 * halfFov;
    camera.frustum.aspectRatio = aspect;
  }
  const destination = Cartesian3.add(sphere.center, Cartesian3.multiplyByScalar(dir, distance, new Cartesian3()), new Cartesian3());
  camera.setView({
    destination,
    orientation: { direction: Cartesian3.negate(dir, new Cartesian3()), up },
  });
  if (p.ortho) {
    // After setView, which resizes an orthographic frustum to its own idea of the view.
    camera.frustum.width = 2 * MARGIN * radius * aspect;
    // Tight planes: depth is linear in an orthographic view, and the default range (1 m to 500,000 km) leaves
    // little precision. (Even so, Cesium 1.145 composites surface+edge views as if the depth were
    // perspective and drops most edges in ortho; EDGES_ONLY is unaffected.)
    camera.frustum.near = 0.01 * radius;
    camera.frustum.far = 6 * radius;
  }

  // A fixed light from over the camera's shoulder, so that the picture does not depend on the clock.
  const right = Cartesian3.cross(Cartesian3.negate(dir, new Cartesian3()), up, new Cartesian3());
  const from = Cartesian3.add(
    Cartesian3.add(dir, Cartesian3.multiplyByScalar(up, 0.6, new Cartesian3()), new Cartesian3()),
    Cartesian3.multiplyByScalar(right, -0.4, new Cartesian3()),
    new Cartesian3(),
  );
  scene.light = new Cesium.DirectionalLight({
    direction: Cartesian3.normalize(Cartesian3.negate(from, new Cartesian3()), new Cartesian3()),
    intensity: 2.0,
  });
  return { radius: sphere.radius };
}

async function main() {
  const p = params();
  loadCss(`${CESIUM_BASE}Widgets/widgets.css`);
  await loadScript(`${CESIUM_BASE}Cesium.js`);
  const Cesium = window.Cesium;
  Cesium.Ion.defaultAccessToken = '';

  const widget = new Cesium.CesiumWidget(document.getElementById('view'), {
    baseLayer: false,
    globe: false,
    skyBox: false, // also no sun or moon
    skyAtmosphere: false,
    shouldAnimate: false,
    contextOptions: { webgl: { preserveDrawingBuffer: true } },
  });
  const scene = widget.scene;
  scene.backgroundColor = Cesium.Color.fromBytes(...p.background, 255);
  scene.fog.enabled = false;
  // A fixed clock (it drives nothing else visible here, but keeps frames reproducible).
  widget.clock.currentTime = Cesium.JulianDate.fromIso8601('2026-06-21T12:00:00Z');

  const edgeDisplayMode = {
    off: Cesium.EdgeDisplayMode.SURFACES_ONLY,
    both: Cesium.EdgeDisplayMode.SURFACES_AND_EDGES,
    only: Cesium.EdgeDisplayMode.EDGES_ONLY,
  }[p.edges];
  const start = performance.now();
  const model = await Cesium.Model.fromGltfAsync({
    url: p.model,
    modelMatrix: Cesium.Transforms.eastNorthUpToFixedFrame(Cesium.Cartesian3.fromDegrees(0, 0, 0)),
    edgeDisplayMode,
  });
  scene.primitives.add(model);
  await ready(model);
  const ms = performance.now() - start;

  const bounds = aimCamera(Cesium, scene, model, p);
  await frames(scene, p.frames);
  return { ok: true, ms: Math.round(ms), radius: bounds.radius };
}

main().then(finish, (err) => finish(failure(err)));
