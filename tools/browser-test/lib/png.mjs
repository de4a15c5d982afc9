// Minimal PNG reader and pixel statistics (no dependencies beyond node:zlib).
//
// Reads what browsers and f3d write: 8-bit greyscale, RGB, palette, grey+alpha or RGBA, not interlaced.
// Anything else throws, so a test fails loudly instead of counting garbage.

import { readFileSync } from 'node:fs';
import { inflateSync } from 'node:zlib';

const SIGNATURE = Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]);
const CHANNELS = { 0: 1, 2: 3, 3: 1, 4: 2, 6: 4 }; // PNG colour type -> samples per pixel

/** Decodes a PNG file into { width, height, rgba: Uint8Array (4 bytes per pixel) }. */
export function readPng(file) {
  const bytes = readFileSync(file);
  if (bytes.length < 8 || !bytes.subarray(0, 8).equals(SIGNATURE)) {
    throw new Error(`${file}: not a PNG file`);
  }
  let header;
  let palette;
  let transparency;
  const idat = [];
  for (let pos = 8; pos + 8 <= bytes.length; ) {
    const length = bytes.readUInt32BE(pos);
    const type = bytes.toString('latin1', pos + 4, pos + 8);
    const data = bytes.subarray(pos + 8, pos + 8 + length);
    pos += 12 + length; // length, type, data, CRC
    if (type === 'IHDR') {
      header = {
        width: data.readUInt32BE(0),
        height: data.readUInt32BE(4),
        depth: data[8],
        colorType: data[9],
        interlace: data[12],
      };
    } else if (type === 'PLTE') {
      palette = data;
    } else if (type === 'tRNS') {
      transparency = data;
    } else if (type === 'IDAT') {
      idat.push(data);
    } else if (type === 'IEND') {
      break;
    }
  }
  if (!header) throw new Error(`${file}: PNG without IHDR`);
  const { width, height, depth, colorType, interlace } = header;
  const channels = CHANNELS[colorType];
  if (depth !== 8 || channels === undefined || interlace !== 0) {
    throw new Error(`${file}: unsupported PNG (bit depth ${depth}, colour type ${colorType}, interlace ${interlace})`);
  }

  // Undo the per-row filters (PNG spec, section 9).
  const raw = inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const pixels = new Uint8Array(stride * height);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)];
    const src = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    const row = pixels.subarray(y * stride, (y + 1) * stride);
    const prev = y > 0 ? pixels.subarray((y - 1) * stride, y * stride) : new Uint8Array(stride);
    for (let i = 0; i < stride; i++) {
      const a = i >= channels ? row[i - channels] : 0;
      const b = prev[i];
      const c = i >= channels ? prev[i - channels] : 0;
      let predictor = 0;
      if (filter === 1) predictor = a;
      else if (filter === 2) predictor = b;
      else if (filter === 3) predictor = (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c;
        const pa = Math.abs(p - a);
        const pb = Math.abs(p - b);
        const pc = Math.abs(p - c);
        predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      } else if (filter !== 0) throw new Error(`${file}: bad PNG filter ${filter} in row ${y}`);
      row[i] = (src[i] + predictor) & 0xff;
    }
  }

  // Expand to RGBA.
  const rgba = new Uint8Array(width * height * 4);
  for (let p = 0; p < width * height; p++) {
    const s = p * channels;
    let r, g, b, a = 255;
    if (colorType === 0 || colorType === 4) {
      r = g = b = pixels[s];
      if (colorType === 4) a = pixels[s + 1];
    } else if (colorType === 3) {
      const index = pixels[s];
      [r, g, b] = [palette[index * 3], palette[index * 3 + 1], palette[index * 3 + 2]];
      if (transparency && index < transparency.length) a = transparency[index];
    } else {
      [r, g, b] = [pixels[s], pixels[s + 1], pixels[s + 2]];
      if (colorType === 6) a = pixels[s + 3];
    }
    rgba.set([r, g, b, a], p * 4);
  }
  return { width, height, rgba };
}

/**
 * Counts the pixels whose RGB lies within `tol` of `color` (largest per-channel difference, alpha ignored),
 * or, with `invert`, the pixels that do not; only inside `region` ([x0, y0, x1, y1], inclusive) if given.
 * Returns { count, bbox: [xmin, ymin, xmax, ymax] | null }.
 */
export function matchPixels(image, color, tol, invert = false, region = null) {
  const { width, height, rgba } = image;
  const [x0, y0, x1, y1] = region ?? [0, 0, width - 1, height - 1];
  let count = 0;
  let [xmin, ymin, xmax, ymax] = [Infinity, Infinity, -1, -1];
  for (let y = Math.max(0, y0); y <= Math.min(height - 1, y1); y++) {
    for (let x = Math.max(0, x0); x <= Math.min(width - 1, x1); x++) {
      const i = (y * width + x) * 4;
      const diff = Math.max(
        Math.abs(rgba[i] - color[0]),
        Math.abs(rgba[i + 1] - color[1]),
        Math.abs(rgba[i + 2] - color[2]),
      );
      if (diff <= tol !== invert) {
        count++;
        if (x < xmin) xmin = x;
        if (x > xmax) xmax = x;
        if (y < ymin) ymin = y;
        if (y > ymax) ymax = y;
      }
    }
  }
  return { count, bbox: count > 0 ? [xmin, ymin, xmax, ymax] : null };
}

/** The RGB of pixel (x, y). */
export function pixelAt(image, x, y) {
  const i = (y * image.width + x) * 4;
  return [image.rgba[i], image.rgba[i + 1], image.rgba[i + 2]];
}
