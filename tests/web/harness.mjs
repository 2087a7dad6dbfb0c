// What the page's browser tests share: where things are, the render-server on an ephemeral
// loopback port with a temp data dir, Debian's Chromium driven by playwright-core, and the steps
// a user takes on the page (fill the form, submit, wait for the viewer).
//
//   RENDER_SERVER   the render-server binary (default: <source>/build/render-server)
//   PT_SOURCE_DIR   the source tree; the page is served from its web/ (default: ../.. from here)
//   PT_WEB_ARTIFACTS  where the screenshots go (default: <source>/build/tests)
//   CHROMIUM        the browser (default: /usr/bin/chromium)
//
// Importing it exits 77 (ctest: skipped) when the browser, playwright-core or the server binary
// is missing; under CI=true those are failures (exit 1): missing.mjs.
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { skip } from './missing.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
export const sourceDir = path.resolve(process.env.PT_SOURCE_DIR || path.join(here, '..', '..'));
export const serverBin = process.env.RENDER_SERVER || path.join(sourceDir, 'build', 'render-server');
export const artifacts = process.env.PT_WEB_ARTIFACTS || path.join(sourceDir, 'build', 'tests');
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';

if (!fs.existsSync(serverBin)) skip(`no render-server at ${serverBin}`);
if (!fs.existsSync(chromiumPath)) skip(`no browser at ${chromiumPath} (apt-get install chromium)`);
let chromium;
try {
  ({ chromium } = await import('playwright-core'));
} catch (e) {
  skip(`playwright-core is not installed (run npm ci in ${here}): ${e.message}`);
}

// Generous: ctest may run the heavy image tests beside these on 2 cores.
export const WAIT = Number(process.env.PT_WEB_WAIT_MS) || 90_000;

// A render-server on `port` (0: any) serving web/, with more `args` and environment variables
// `env` (say PT_OIDN_LIB, to leave it without a denoiser); resolves {proc, url, port} once it listens.
export function startServer(dataDir, port = 0, args = [], env = {}) {
  return new Promise((resolve, reject) => {
    const proc = spawn(serverBin, ['--port', String(port), '--data', dataDir, '--web', path.join(sourceDir, 'web'), ...args],
      { stdio: ['ignore', 'pipe', 'pipe'], env: { ...process.env, ...env } });
    let out = '', err = '';
    const timer = setTimeout(() => { proc.kill('SIGKILL'); reject(new Error(`render-server did not start: ${out}${err}`)); }, 20_000);
    proc.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/listening on (http:\/\/127\.0\.0\.1:(\d+)\/)/);
      if (m) {
        clearTimeout(timer);
        resolve({ proc, url: m[1], port: Number(m[2]) });
      }
    });
    proc.stderr.on('data', (d) => { err += d; });
    proc.on('exit', (code) => {
      clearTimeout(timer);
      reject(new Error(`render-server exited (${code}) before listening: ${out}${err}`));
    });
  });
}

export function stopServer(proc) {
  return new Promise((resolve) => {
    if (proc.exitCode !== null || proc.signalCode !== null) return resolve();
    const t = setTimeout(() => proc.kill('SIGKILL'), 10_000);
    proc.once('exit', () => { clearTimeout(t); resolve(); });
    proc.kill('SIGTERM');
  });
}

export function makeDataDir(name) {
  return fs.mkdtempSync(path.join(os.tmpdir(), `${name}-`));
}

// Headless Chromium (no sandbox as root, which Chromium refuses otherwise).
export async function launchBrowser() {
  const args = ['--disable-dev-shm-usage'];
  if (process.getuid && process.getuid() === 0) args.push('--no-sandbox');
  return chromium.launch({ executablePath: chromiumPath, headless: true, args });
}

// Headless Chromium and one page on `url`, the server's connection live and its scenes listed;
// uncaught page errors are pushed onto `errors`.
export async function openBrowser(url, errors) {
  const browser = await launchBrowser();
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  page.setDefaultTimeout(WAIT);
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(url);
  await waitReady(page);
  return { browser, page };
}

export async function waitReady(page) {
  await page.waitForSelector('#conn[data-state="live"]');
  await page.waitForSelector('#f-scene option[value="cornell"]', { state: 'attached' });
}

// A client of the server's API at `url`: GET as bytes or JSON, POST JSON.
export function apiClient(url) {
  return {
    async get(p) {
      const r = await fetch(new URL(p, url));
      return { status: r.status, type: r.headers.get('content-type'), body: Buffer.from(await r.arrayBuffer()) };
    },
    async json(p) {
      return (await fetch(new URL(p, url))).json();
    },
    async post(p, body) {
      const r = await fetch(new URL(p, url), { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) });
      return { status: r.status, data: await r.json() };
    },
  };
}

// The steps a user takes on `page`.
export function pageSteps(page) {
  // Sets form fields (by job-field name) the way a user types them.
  async function fill(values) {
    for (const [name, v] of Object.entries(values)) {
      await page.$eval(`#f-${name}`, (el) => { const d = el.closest('details'); if (d) d.open = true; });
      if (name === 'scene') await page.selectOption('#f-scene', v);
      else if (typeof v === 'boolean') await page.setChecked(`#f-${name}`, v);
      else await page.fill(`#f-${name}`, String(v));
    }
  }

  async function viewedJobId() {
    return page.evaluate(() => (location.hash.match(/job=([0-9a-f]+)/) || [])[1]);
  }

  // Fills the form, submits it and resolves the new job's id once the viewer shows it.
  async function submit(values) {
    const before = await viewedJobId();
    await fill(values);
    await page.click('#submit');
    await page.waitForFunction((prev) => {
      const m = location.hash.match(/job=([0-9a-f]+)/);
      return m && m[1] !== prev;
    }, before);
    return viewedJobId();
  }

  async function waitViewerEnded(state) {
    await page.waitForSelector(`#viewer[data-ended="true"][data-state="${state}"]`);
  }

  return { fill, viewedJobId, submit, waitViewerEnded };
}

// Asserts that nothing on the page reaches past the window's right edge (no sideways scrolling).
export async function assertFitsWidth(page, assert) {
  const widths = await page.evaluate(() => [document.documentElement.scrollWidth, window.innerWidth]);
  const wide = await page.evaluate(() => [...document.querySelectorAll('body *')]
    .filter((el) => el.getBoundingClientRect().right > window.innerWidth + 0.5)
    .map((el) => `${el.tagName.toLowerCase()}${el.id ? `#${el.id}` : ''}${el.className ? `.${el.className}` : ''}`));
  assert.ok(widths[0] <= widths[1] && wide.length === 0,
    `page is ${widths[0]} px wide in a ${widths[1]} px window: ${wide.slice(0, 8).join(', ')}`);
}
