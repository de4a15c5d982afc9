// A tiny static HTTP server bound to 127.0.0.1 on an ephemeral port.
//
// Serves two trees: "/" is this tool's folder (the pages and node_modules), "/model/" is the folder of the
// model under test (so a .gltf finds its .bin and images). A model whose bytes were rewritten in memory is
// served from `overrides` instead of the disk, and a file of the tool's tree from `toolOverrides`.

import { createServer } from 'node:http';
import { readFile } from 'node:fs/promises';
import path from 'node:path';

const MIME = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.cjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.json': 'application/json',
  '.wasm': 'application/wasm',
  '.glb': 'model/gltf-binary',
  '.gltf': 'model/gltf+json',
  '.bin': 'application/octet-stream',
  '.png': 'image/png',
  '.jpg': 'image/jpeg',
  '.jpeg': 'image/jpeg',
  '.webp': 'image/webp',
  '.ktx2': 'image/ktx2',
  '.svg': 'image/svg+xml',
  '.xml': 'application/xml',
};

/** Resolves `rel` inside `root`, or returns null if it would escape it. */
function inside(root, rel) {
  const resolved = path.resolve(root, '.' + path.posix.normalize('/' + rel));
  return resolved === root || resolved.startsWith(root + path.sep) ? resolved : null;
}

/**
 * Starts the server. `toolRoot`: folder served at "/"; `modelDir`: folder served at "/model/";
 * `overrides`: Map from a name under /model/ to the bytes to serve for it; `toolOverrides`: the same for a
 * path under "/" (relative to `toolRoot`, e.g. "node_modules/cesium/Build/Cesium/Cesium.js").
 * Resolves to { url, close() }.
 */
export async function startServer({ toolRoot, modelDir, overrides = new Map(), toolOverrides = new Map() }) {
  const server = createServer(async (req, res) => {
    try {
      const urlPath = decodeURIComponent(new URL(req.url, 'http://x').pathname);
      let body;
      let file;
      if (urlPath.startsWith('/model/')) {
        const rel = urlPath.slice('/model/'.length);
        body = overrides.get(rel);
        file = inside(modelDir, rel);
      } else {
        const rel = urlPath === '/' ? 'page/index.html' : urlPath.slice(1);
        body = toolOverrides.get(rel);
        file = inside(toolRoot, rel);
      }
      if (!file) throw Object.assign(new Error('outside the served folders'), { code: 'ENOENT' });
      body ??= await readFile(file);
      res.writeHead(200, {
        'Content-Type': MIME[path.extname(file).toLowerCase()] ?? 'application/octet-stream',
        'Cache-Control': 'no-store',
      });
      res.end(body);
    } catch (err) {
      const missing = err.code === 'ENOENT' || err.code === 'EISDIR';
      res.writeHead(missing ? 404 : 500, { 'Content-Type': 'text/plain' });
      res.end(missing ? 'not found' : String(err));
    }
  });
  // Keep-alive sockets would hold close() open; drop them when closing.
  const sockets = new Set();
  server.on('connection', (socket) => {
    sockets.add(socket);
    socket.on('close', () => sockets.delete(socket));
  });
  await new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(0, '127.0.0.1', resolve);
  });
  const { port } = server.address();
  return {
    url: `http://127.0.0.1:${port}`,
    close: () =>
      new Promise((resolve) => {
        for (const socket of sockets) socket.destroy();
        server.close(() => resolve());
      }),
  };
}
