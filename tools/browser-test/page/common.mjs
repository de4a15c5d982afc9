// Helpers shared by the two client modules.

/** The query parameters run.mjs passes, parsed. */
export function params() {
  const q = new URLSearchParams(location.search);
  const numbers = (name, fallback) => (q.get(name) ?? fallback).split(',').map(Number);
  const [azimuth, elevation] = numbers('view', '30,20');
  return {
    model: q.get('model'), // URL of the file under test
    render: q.get('render') === '1', // draw a frame (for a screenshot) or only load
    background: numbers('bg', '255,255,255'), // 0..255 RGB
    azimuth,
    elevation,
    ortho: q.get('ortho') === '1',
    edges: q.get('edges') ?? 'both', // Cesium: off | both | only
    frames: Number(q.get('frames') ?? 3), // Cesium: frames to render once the model is ready
    box: q.get('box') ? q.get('box').split(',').map(Number) : null, // Cesium: the scene's box in glTF axes
  };
}

/**
 * The unit vector from the model's centre towards the camera, in glTF axes (+Y up, +Z front):
 * azimuth 0 looks from the front (+Z), 90 from the right (+X); elevation is above the horizon, in degrees.
 */
export function viewDirection(azimuth, elevation) {
  const az = (azimuth * Math.PI) / 180;
  const el = (elevation * Math.PI) / 180;
  return [Math.sin(az) * Math.cos(el), Math.sin(el), Math.cos(az) * Math.cos(el)];
}

/** Vertical field of view of the perspective cameras, in degrees; the model's sphere fills it with a margin. */
export const FOV_DEGREES = 35;
export const MARGIN = 1.08;

/** Reports the outcome to run.mjs (which polls window.__result). */
export function finish(result) {
  window.__result = result;
}

/** Turns a thrown value into a failure result: the message, without the nested stacks Cesium appends. */
export function failure(err) {
  let message = err instanceof Error ? `${err.name}: ${err.message}` : String(err?.message ?? err);
  message = message.split(/\n(?:Original|Handler) stack:/)[0].trim();
  return { ok: false, error: message.slice(0, 2000) };
}
