// Runs one test page in headless Chromium (Debian's build, software WebGL 2 through SwiftShader) and
// collects what the page reports, its console errors and, if asked, an 800x600 screenshot.

import { readdirSync, readFileSync } from 'node:fs';
import puppeteer from 'puppeteer-core';

export const CHROMIUM = process.env.CHROMIUM ?? '/usr/bin/chromium';
export const WIDTH = 800;
export const HEIGHT = 600;

export const ARGS = [
  '--use-angle=swiftshader', // WebGL on the CPU: these machines have no GPU
  '--enable-unsafe-swiftshader',
  '--ignore-gpu-blocklist',
  '--no-sandbox', // needed when running as root
  '--disable-dev-shm-usage',
  '--no-first-run',
  '--no-default-browser-check',
  '--mute-audio',
  '--hide-scrollbars',
];

/** The running browser, if any, so that a watchdog can kill it. */
let current = null;

/**
 * Kills the browser's whole process group (puppeteer starts it in a group of its own): the main process if
 * it is still there, and any renderer or GPU process that outlived it (a page stuck in a loop does).
 */
export function killBrowser() {
  const child = current?.process();
  if (child?.pid) {
    try {
      process.kill(-child.pid, 'SIGKILL');
    } catch {
      // already gone
    }
  }
  current = null;
}

/**
 * Starts headless Chromium with the flags above (software WebGL 2) and registers it for
 * killBrowser(). `timeoutMs` bounds any single DevTools call.
 */
export async function launchBrowser(timeoutMs, extraArgs = []) {
  const browser = await puppeteer.launch({
    executablePath: CHROMIUM,
    headless: true,
    args: [...ARGS, ...extraArgs],
    timeout: 30_000, // to start the browser
    protocolTimeout: timeoutMs + 10_000,
  });
  current = browser;
  return browser;
}

/**
 * Waits until the browser's own start-up work is done: its processes (the launched one's process
 * group) together use under a tenth of a core for `quietMs`, or `maxMs` passed. Returns the ms waited.
 * A freshly started Chromium spends about a second of CPU after launch on work of its own (the
 * omnibox popup's WebUI page, among others), which on two cores a page opened at once competes
 * with; the first-frame benchmark waits for it (docs/web.md, "First frame"). Linux only: reads /proc.
 */
export async function waitUntilBrowserIdle(browser, { quietMs = 500, maxMs = 15_000 } = {}) {
  const group = browser.process()?.pid;
  if (!group) return 0;
  // CPU seconds of every process in the group (utime + stime, in clock ticks of 1/100 s).
  const cpuTicks = () => {
    let ticks = 0;
    for (const pid of readdirSync('/proc')) {
      if (!/^\d+$/.test(pid)) continue;
      let stat;
      try {
        stat = readFileSync(`/proc/${pid}/stat`, 'utf8');
      } catch {
        continue; // gone meanwhile
      }
      const fields = stat.slice(stat.lastIndexOf(')') + 2).split(' ');
      if (Number(fields[2]) === group) ticks += Number(fields[11]) + Number(fields[12]);
    }
    return ticks;
  };
  const start = Date.now();
  const step = 100;
  let quiet = 0;
  let before = cpuTicks();
  while (quiet < quietMs && Date.now() - start < maxMs) {
    await new Promise((resolve) => setTimeout(resolve, step));
    const now = cpuTicks();
    // A tenth of a core over the step: at most one tick (1/100 s) per 100 ms.
    quiet = now - before <= step / 100 ? quiet + step : 0;
    before = now;
  }
  return Date.now() - start;
}

/**
 * Opens `url`, waits (at most `timeoutMs`) until the page sets window.__result, and returns
 * { result, consoleErrors }. With `screenshot` (a path) and a successful result, saves the view as PNG.
 */
export async function runPage({ url, timeoutMs, screenshot }) {
  const deadline = Date.now() + timeoutMs;
  const left = () => Math.max(1000, deadline - Date.now());
  const consoleErrors = [];
  const browser = await launchBrowser(timeoutMs);
  try {
    const page = await browser.newPage();
    await page.setViewport({ width: WIDTH, height: HEIGHT, deviceScaleFactor: 1 });
    page.on('console', (msg) => {
      if (msg.type() === 'error') consoleErrors.push(msg.text());
    });
    page.on('pageerror', (err) => consoleErrors.push(`page error: ${err.message ?? err}`));
    page.on('requestfailed', (req) => {
      // ERR_ABORTED is a request the page (or closing it) cancelled; a body that arrived only partly fails
      // the loader, and a missing file shows as a 404 console error.
      const reason = req.failure()?.errorText;
      if (reason !== 'net::ERR_ABORTED') consoleErrors.push(`request failed: ${req.url()} (${reason})`);
    });

    await page.goto(url, { waitUntil: 'domcontentloaded', timeout: left() });
    let result;
    try {
      // Poll on a timer: requestAnimationFrame polling can starve while SwiftShader draws.
      await page.waitForFunction(() => window.__result !== undefined, { timeout: left(), polling: 250 });
      result = await page.evaluate(() => window.__result);
    } catch (err) {
      result = { ok: false, error: `page did not finish within ${Math.round(timeoutMs / 1000)} s: ${err.message}` };
    }
    // Let requests still reported as in flight settle, so that closing does not abort them.
    await page.waitForNetworkIdle({ idleTime: 100, timeout: 3000 }).catch(() => {});
    if (screenshot && result.ok) {
      await page.screenshot({ path: screenshot, type: 'png', clip: { x: 0, y: 0, width: WIDTH, height: HEIGHT } });
    }
    return { result, consoleErrors };
  } finally {
    // close() asks politely; the timer makes sure nothing outlives us.
    const timer = setTimeout(killBrowser, 5000);
    await browser.close().catch(() => {});
    clearTimeout(timer);
    killBrowser();
  }
}
