// End-to-end test of the web page (web/) in a real browser: Debian's Chromium driven by
// playwright-core, against a real render-server on an ephemeral loopback port with a temp data dir
// (harness.mjs: the environment it reads, and exit 77 when something it needs is missing). The job
// list, pause, render more and reloading a job's link: jobs.test.mjs.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { artifacts, startServer, stopServer, makeDataDir, openBrowser, apiClient, pageSteps, assertFitsWidth } from './harness.mjs';

let dataDir, server, baseUrl, port, browser, page, api;
let fill, viewedJobId, submit, waitViewerEnded;
const pageErrors = [];
const apiGet = (p) => api.get(p);
const apiJson = (p) => api.json(p);

before(async () => {
  dataDir = makeDataDir('web-test');
  ({ proc: server, url: baseUrl, port } = await startServer(dataDir));
  api = apiClient(baseUrl);
  ({ browser, page } = await openBrowser(baseUrl, pageErrors));
  ({ fill, viewedJobId, submit, waitViewerEnded } = pageSteps(page));
});

after(async () => {
  if (browser) await browser.close();
  if (server) await stopServer(server);
  if (dataDir) fs.rmSync(dataDir, { recursive: true, force: true });
});

// Compares a canvas on the page with the job's final image.png, decoded by the browser the same
// way the page decodes tiles. Values are in 0..255 units.
async function compareWithFinal(canvasSelector, id) {
  return page.evaluate(async ({ sel, id }) => {
    const canvas = document.querySelector(sel);
    const a = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
    const res = await fetch(`/api/jobs/${id}/image.png`, { cache: 'no-store' });
    const bmp = await createImageBitmap(await res.blob(), { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
    const off = new OffscreenCanvas(bmp.width, bmp.height);
    const ctx = off.getContext('2d');
    ctx.drawImage(bmp, 0, 0);
    const b = ctx.getImageData(0, 0, bmp.width, bmp.height).data;
    const out = { canvas: [canvas.width, canvas.height], png: [bmp.width, bmp.height], mean: NaN, max: NaN, brightness: 0 };
    if (a.length !== b.length) return out;
    let sum = 0, max = 0, bright = 0, n = 0;
    for (let i = 0; i < a.length; i += 4) {
      for (let c = 0; c < 3; ++c) {
        const d = Math.abs(a[i + c] - b[i + c]);
        sum += d;
        if (d > max) max = d;
        bright += b[i + c];
        ++n;
      }
    }
    return { ...out, mean: sum / n, max, brightness: bright / n };
  }, { sel: canvasSelector, id });
}

function assertMatches(cmp, what) {
  assert.deepEqual(cmp.canvas, cmp.png, `${what}: canvas and image.png differ in size`);
  assert.ok(cmp.mean < 2, `${what}: mean absolute difference ${cmp.mean} (0..255) is not below 2`);
  assert.ok(cmp.max <= 8, `${what}: largest difference ${cmp.max} (0..255) exceeds 8`);
  assert.ok(cmp.brightness > 10, `${what}: the image is black (mean ${cmp.brightness})`);
}

// ---------- the tests (they run in order, on one page) ----------

let smallJob;

test('the page lists the scenes and fills the form with the API defaults', async () => {
  const { defaults, scenes } = await apiJson('/api/scenes');
  const options = await page.$$eval('#f-scene option', (os) => os.map((o) => o.value));
  assert.deepEqual(options, scenes.map((s) => s.name));
  assert.equal(await page.inputValue('#f-scene'), 'cornell');
  for (const f of ['max_depth', 'aperture', 'focal_distance', 'spp', 'light_samples', 'width', 'height'])
    assert.equal(Number(await page.inputValue(`#f-${f}`)), defaults[f], `field ${f}`);
  assert.match(await page.textContent('#scene-summary'), /triangles/);
});

test('a bad value is explained next to its field, in the words of its label', async () => {
  await fill({ spp: 0 });
  await page.waitForFunction(() => /^Samples per pixel must be between 1 and \d+$/.test(document.querySelector('#err-spp').textContent));
  assert.equal(await page.getAttribute('#f-spp', 'aria-invalid'), 'true');
  await fill({ spp: 8 });
  await page.waitForFunction(() => document.querySelector('#err-spp').textContent === '');
  await fill({ width: 100000 });
  await page.waitForFunction(() => /^Width must be at most 4096/.test(document.querySelector('#err-width').textContent));
  // Submitting anyway creates nothing and keeps the explanation beside the field.
  await page.click('#submit');
  await page.waitForTimeout(300);
  assert.match(await page.textContent('#err-width'), /4096/);
  assert.equal(await page.textContent('#err-spp'), '');
  assert.equal((await apiJson('/api/jobs')).jobs.length, 0);
  await fill({ width: 96 });
  await page.waitForFunction(() => document.querySelector('#err-width').textContent === '');
});

// The API may list every invalid field (error.errors) or name the first (error.field): the form
// marks each field named, whichever shape the answer has.
test('every invalid field an error answer lists is marked at once', async () => {
  const answers = [
    { status: 400, message: "'spp' must be at least 1", field: 'spp',
      errors: [{ field: 'spp', message: "'spp' must be at least 1" }, { field: 'width', message: 'width x height x spp is too many' }] },
    { status: 400, message: 'height must be at least 1', field: 'height' },
  ];
  // The page speaks of each field by its label.
  const spoken = { "'spp' must be at least 1": 'Samples per pixel must be at least 1',
    'width x height x spp is too many': 'Width x height x samples per pixel is too many', 'height must be at least 1': 'Height must be at least 1' };
  for (const error of answers) {
    await page.route('**/api/jobs/check', (route) =>
      route.fulfill({ status: 400, contentType: 'application/json', body: JSON.stringify({ error }) }));
    await page.evaluate(() => checkForm());
    const listed = error.errors || [error];
    await page.waitForFunction((fields) => fields.every((f) => document.querySelector(`#f-${f}`).getAttribute('aria-invalid') === 'true'),
      listed.map((e) => e.field));
    for (const e of listed) assert.equal(await page.textContent(`#err-${e.field}`), spoken[e.message]);
    assert.equal(await page.$$eval('#job-form [aria-invalid="true"]', (els) => els.length), listed.length);
    await page.unroute('**/api/jobs/check');
  }
  // The server's own answer names both fields at once.
  await fill({ spp: 0, width: 100000 });
  await page.waitForFunction(() => ['spp', 'width'].every((f) => document.querySelector(`#f-${f}`).getAttribute('aria-invalid') === 'true'));
  await fill({ spp: 8, width: 96 });
  await page.waitForFunction(() => !document.querySelector('#job-form [aria-invalid]'));
});

test('tiles stream into the canvas and match the final image; cancel stops a job', async () => {
  // A long job holds the (one-at-a-time) renderer, so the small job's stream is open before it renders.
  const longJob = await submit({ scene: 'cornell', width: 320, height: 240, spp: 4096 });
  await page.waitForSelector('#viewer[data-state="running"]');
  await page.waitForFunction(() => Number(document.querySelector('#viewer').dataset.tiles) > 0);
  smallJob = await submit({ width: 96, height: 72, spp: 8 });
  assert.notEqual(smallJob, longJob);
  await page.waitForSelector('#viewer[data-state="queued"]');

  await page.click(`#job-rows tr[data-id="${longJob}"] [data-action="cancel"]`);
  await page.waitForSelector(`#job-rows tr[data-id="${longJob}"][data-state="cancelled"]`);
  assert.equal((await page.textContent(`#job-rows tr[data-id="${longJob}"] .badge`)).trim(), 'cancelled');
  assert.equal((await apiJson(`/api/jobs/${longJob}`)).state, 'cancelled');

  await waitViewerEnded('done');
  const tiles = Number(await page.getAttribute('#viewer', 'data-tiles'));
  // The stream sends squares of whole render tiles, at least 64 pixels a side.
  const side = (await apiJson(`/api/jobs/${smallJob}`)).stream_tile_size;
  const expected = Math.ceil(96 / side) * Math.ceil(72 / side);
  assert.ok(tiles >= expected, `only ${tiles} tile events painted (a 96x72 image has ${expected} of ${side} pixels)`);
  assert.equal((await page.textContent('#v-state')).trim(), 'done');
  assert.match(await page.textContent('#v-progress-text'), /100%/);
  assertMatches(await compareWithFinal('#v-canvas', smallJob), 'streamed tiles');
  // The chart has points and the stats are filled in.
  assert.match(await page.textContent('#v-spp'), /^8 \/ 8$/);
  assert.notEqual(await page.textContent('#v-error'), '–');
  // The chart's dashed guide is Monte Carlo's rate for a relative MSE, 1/time, through the latest
  // point (against an RMSE's 1/sqrt(time), half as steep, the render looked faster than Monte Carlo allows).
  const guide = await page.evaluate(() => errorGuide([{ seconds: 0.5, error: 0.4 }, { seconds: 2, error: 0.05 }]));
  assert.deepEqual(guide, { slope: -1, seconds: 2, error: 0.05 });
  assert.match(await page.textContent('.chart-box figcaption'), /relative MSE.*1\/t through the latest point/);
});

test('clicking the image sets the focal distance from the focus endpoint', async () => {
  await page.locator('#v-canvas').scrollIntoViewIfNeeded();
  const box = await page.locator('#v-canvas').boundingBox();
  await page.locator('#v-canvas').click({ position: { x: box.width * 0.5, y: box.height * 0.6 } });
  await page.waitForSelector('#v-note[data-kind="ok"]').catch(async (e) => {
    throw new Error(`${e.message}\nnote: ${await page.textContent('#v-note')} ${JSON.stringify(box)}`);
  });
  assert.match(await page.textContent('#v-note'), /Focal distance set to/);
  const x = await page.getAttribute('#v-note', 'data-x'), y = await page.getAttribute('#v-note', 'data-y');
  assert.ok(Math.abs(Number(x) - 48.5) <= 1 && Math.abs(Number(y) - 43.5) <= 1, `clicked pixel ${x},${y}`);
  const { distance } = await apiJson(`/api/jobs/${smallJob}/focus?x=${x}&y=${y}`);
  assert.ok(distance > 0);
  assert.equal(Number(await page.inputValue('#f-focal_distance')), Number(distance.toFixed(3)));
});

test('a focus stack renders four jobs side by side, each from its own stream', async () => {
  const focal = Number(await page.inputValue('#f-focal_distance'));
  await page.check('#sweep-half');
  await page.click('#focus-stack');
  await page.waitForFunction(() => document.querySelectorAll('#sweep-grid .cell').length === 4);
  await page.waitForFunction(() => document.querySelectorAll('#sweep-grid .cell[data-ended="true"][data-state="done"]').length === 4);
  const ids = await page.$$eval('#sweep-grid .cell', (cs) => cs.map((c) => c.dataset.id));
  const specs = await Promise.all(ids.map(async (id) => (await apiJson(`/api/jobs/${id}`)).spec));
  const distances = specs.map((s) => s.focal_distance);
  assert.equal(new Set(distances).size, 4, `focal distances ${distances}`);
  assert.ok(Math.min(...distances) < focal && Math.max(...distances) > focal, `${distances} around ${focal}`);
  for (const s of specs) {
    assert.equal(s.aperture, 0.1);  // the form's aperture is 0: the stack opens the lens
    assert.deepEqual([s.width, s.height, s.spp], [48, 36, 8]);  // half size
  }
  for (let i = 0; i < 4; ++i)
    assertMatches(await compareWithFinal(`#sweep-grid .cell[data-id="${ids[i]}"] canvas`, ids[i]), `sweep cell ${i}`);
});

test('opening a finished job shows its image; PNG and EXR download', async () => {
  await page.click(`#job-rows tr[data-id="${smallJob}"] [data-action="open"]`);
  await page.waitForFunction((id) => location.hash === `#job=${id}`, smallJob);
  await waitViewerEnded('done');
  assertMatches(await compareWithFinal('#v-canvas', smallJob), 'opened job');
  const png = await apiGet(await page.getAttribute('#v-png', 'href'));
  assert.equal(png.status, 200);
  assert.equal(png.type, 'image/png');
  assert.deepEqual([...png.body.subarray(0, 4)], [0x89, 0x50, 0x4e, 0x47]);
  const exr = await apiGet(await page.getAttribute(`#job-rows tr[data-id="${smallJob}"] [data-action="exr"]`, 'href'));
  assert.equal(exr.status, 200);
  assert.deepEqual([...exr.body.subarray(0, 4)], [0x76, 0x2f, 0x31, 0x01]);
  assert.ok(await page.getAttribute('#v-png', 'download'));
});

test("the viewer's Cancel button stops the running job and keeps its picture", async () => {
  await submit({ width: 480, height: 360, spp: 4096 });
  await page.waitForSelector('#viewer[data-state="running"]');
  await page.waitForFunction(() => Number(document.querySelector('#viewer').dataset.tiles) > 0);
  await page.click('#v-cancel');
  await waitViewerEnded('cancelled');
  assert.equal((await page.textContent('#v-state')).trim(), 'cancelled');
  assert.ok(await page.isDisabled('#v-cancel'));
  assert.ok(await page.isHidden('#v-placeholder'));
});

test('the page reconnects by itself when the server restarts mid-render', async () => {
  const job = await submit({ width: 480, height: 360, spp: 32 });
  await page.waitForSelector('#viewer[data-state="running"]');
  await page.waitForFunction(() => Number(document.querySelector('#viewer').dataset.tiles) > 0);
  await stopServer(server);
  await page.waitForSelector('#conn[data-state="reconnecting"]');
  // Same port, same data: the interrupted job was put back in the queue and runs again.
  for (let attempt = 0; ; ++attempt) {
    try {
      ({ proc: server } = await startServer(dataDir, port));
      break;
    } catch (e) {
      if (attempt >= 10) throw e;
      await new Promise((r) => setTimeout(r, 500));
    }
  }
  await page.waitForSelector('#conn[data-state="live"]');
  await waitViewerEnded('done');
  assert.equal(await viewedJobId(), job);
  assertMatches(await compareWithFinal('#v-canvas', job), 'after the restart');
  await page.waitForSelector(`#job-rows tr[data-id="${smallJob}"][data-state="done"]`);
  await page.waitForSelector(`#job-rows tr[data-id="${job}"][data-state="done"]`);
  await page.waitForTimeout(500);  // let the progress bar's transition finish
  fs.mkdirSync(artifacts, { recursive: true });
  await page.screenshot({ path: path.join(artifacts, 'web-screenshot.png'), fullPage: true });
});

test('a narrow window needs no sideways scrolling', async () => {
  await page.setViewportSize({ width: 390, height: 844 });
  await page.waitForTimeout(300);
  await assertFitsWidth(page, assert);
  const canvasBox = await page.locator('#v-canvas').boundingBox();
  assert.ok(canvasBox.width <= 390 && canvasBox.width > 200, `canvas ${canvasBox.width} px wide`);
  await page.screenshot({ path: path.join(artifacts, 'web-screenshot-narrow.png'), fullPage: true });
  await page.setViewportSize({ width: 1280, height: 900 });
});

// A server that goes away mid-answer leaves a JSON body cut short: the page shows a lost
// connection and polls again, instead of failing on the missing data (seen once in CI).
test('a JSON answer cut short counts as a lost connection, not an error', async () => {
  const errors = pageErrors.length;
  let cut = 0;
  await page.route('**/api/jobs', (route) => {
    if (cut++ === 0) return route.fulfill({ status: 200, contentType: 'application/json', body: '{"jobs": [{"id": ' });
    return route.continue();
  });
  await page.evaluate(() => refreshJobs());
  await page.waitForSelector('#conn[data-state="reconnecting"]');
  await page.waitForSelector('#conn[data-state="live"]');
  await page.unroute('**/api/jobs');
  assert.ok(cut >= 2, 'the page polled again after the cut answer');
  assert.deepEqual(pageErrors.slice(errors), []);
});

test('no uncaught errors on the page', () => {
  assert.deepEqual(pageErrors, []);
});
