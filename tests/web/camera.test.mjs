// Moving the camera on the image (camera.js), in a real browser against a real render-server
// (harness.mjs): a drag orbits around the view's target, shift- and right-drag pan, the wheel
// dollies by 1/20 of the starting distance a step within [1/20, 10] of it, Reset view goes back to
// the scene's framing, a click still focuses; while the view moves one preview job at a time
// streams (the stale one deleted first), and at rest the form's job with the camera is shown. The
// job list, the viewer and compare show a job's camera; a half-size sweep renders the same view.
// Every wait is on a state the page or the server shows.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { artifacts, startServer, stopServer, makeDataDir, openBrowser, apiClient, pageSteps } from './harness.mjs';

let dataDir, server, baseUrl, browser, page, api;
let submit, waitViewerEnded, viewedJobId;
const pageErrors = [];

// What the page asked of the server, in order: preview submissions and preview deletions.
const events = [];
const previewIds = new Set();

before(async () => {
  dataDir = makeDataDir('web-camera-test');
  ({ proc: server, url: baseUrl } = await startServer(dataDir));
  api = apiClient(baseUrl);
  const checked = await api.post('/api/jobs/check', { scene: 'cornell' });
  if (!checked.data.view) {
    await stopServer(server);
    fs.rmSync(dataDir, { recursive: true, force: true });
    throw new Error('/api/jobs/check answered no view: the camera field is broken');
  }
  ({ browser, page } = await openBrowser(baseUrl, pageErrors));
  ({ submit, waitViewerEnded, viewedJobId } = pageSteps(page));
  // Routed, so that each is recorded before the page can act on its answer.
  const isPreview = (body) => body.spp === 4 && body.adaptive === false && body.width === 21;
  await page.route('**/api/jobs', async (route) => {
    const req = route.request();
    if (req.method() !== 'POST' || !isPreview(JSON.parse(req.postData()))) return route.continue();
    events.push({ kind: 'post', body: JSON.parse(req.postData()) });
    const res = await route.fetch();
    const data = await res.json();
    if (res.status() === 201) previewIds.add(data.id);
    return route.fulfill({ response: res, json: data });
  });
  await page.route('**/api/jobs/*', async (route) => {
    const req = route.request();
    if (req.method() !== 'DELETE') return route.continue();
    const res = await route.fetch();
    const data = await res.json().catch(() => null);
    if (res.status() === 404 || (data && data.state === 'deleted')) events.push({ kind: 'deleted', id: new URL(req.url()).pathname.split('/').pop() });
    return route.fulfill(data ? { response: res, json: data } : { response: res });
  });
});

after(async () => {
  if (browser) await browser.close();
  if (server) await stopServer(server);
  if (dataDir) fs.rmSync(dataDir, { recursive: true, force: true });
});

// ---------- vectors, as camera.js has them ----------

const sub = (a, b) => a.map((x, i) => x - b[i]);
const add = (a, b) => a.map((x, i) => x + b[i]);
const scale = (a, k) => a.map((x) => x * k);
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const len = (a) => Math.hypot(...a);
const norm = (a) => scale(a, 1 / len(a));
const dist = (v) => len(sub(v.position, v.target));
const azimuth = (v) => { const o = sub(v.position, v.target); return Math.atan2(o[0], o[2]); };
const polar = (v) => { const o = sub(v.position, v.target); return Math.acos(o[1] / len(o)); };
const angleDiff = (a, b) => Math.atan2(Math.sin(a - b), Math.cos(a - b));

function assertNear(a, b, tol, what) {
  const d = Array.isArray(a) ? len(sub(a, b)) : Math.abs(a - b);
  assert.ok(d <= tol, `${what}: ${JSON.stringify(a)} is ${d} from ${JSON.stringify(b)} (tolerance ${tol})`);
}

// ---------- steps ----------

let original, originalId;  // the first job's view and id
const job = (id) => api.json(`/api/jobs/${id}`);

// The preview jobs on the server that are not finished.
async function livePreviews() {
  const { jobs } = await api.json('/api/jobs?limit=1000');
  return jobs.filter((j) => previewIds.has(j.id) && !['done', 'failed', 'cancelled'].includes(j.state));
}

// Samples the live previews on the server, and the page's job rows, while `fn` runs; resolves
// the most previews live at once and those the job list showed.
async function watchPreviews(fn) {
  let most = 0, running = true;
  const listed = new Set();
  const poll = (async () => {
    while (running) {
      most = Math.max(most, (await livePreviews()).length);
      for (const id of await page.$$eval('#job-rows tr', (rs) => rs.map((r) => r.dataset.id))) if (previewIds.has(id)) listed.add(id);
      await new Promise((r) => setTimeout(r, 30));
    }
  })();
  try { await fn(); } finally { running = false; await poll; }
  return { most, listed: [...listed] };
}

// A drag on the image from (fx0, fy0) to (fx1, fy1), fractions of the picture, slow enough for
// previews to come and go; resolves the canvas box it was measured on.
async function dragOnImage([fx0, fy0], [fx1, fy1], { button = 'left', shift = false, steps = 12 } = {}) {
  const box = await page.locator('#v-canvas').boundingBox();
  const at = (fx, fy) => [box.x + fx * box.width, box.y + fy * box.height];
  await page.mouse.move(...at(fx0, fy0));
  if (shift) await page.keyboard.down('Shift');
  await page.mouse.down({ button });
  for (let i = 1; i <= steps; ++i) {
    await page.mouse.move(...at(fx0 + ((fx1 - fx0) * i) / steps, fy0 + ((fy1 - fy0) * i) / steps));
    await page.waitForTimeout(80);
  }
  await page.mouse.up({ button });
  if (shift) await page.keyboard.up('Shift');
  return box;
}

// The job the moves came to rest in: shown (its address), done; resolves its status.
async function restedJob(before) {
  await page.waitForFunction((prev) => {
    const m = location.hash.match(/job=([0-9a-f]+)/);
    const v = document.querySelector('#viewer');
    return m && m[1] !== prev && v.dataset.nav === 'rest' && v.dataset.preview === 'false';
  }, before);
  await waitViewerEnded('done');
  return job(await viewedJobId());
}

// ---------- the tests (in order, on one page) ----------

test('a horizontal drag of half the width turns the azimuth by pi/2 around the target; one preview at a time', async () => {
  originalId = await submit({ scene: 'cornell', width: 64, height: 48, spp: 4, max_depth: 2 });
  await waitViewerEnded('done');
  original = (await job(originalId)).view;
  assert.ok(original && original.vfov > 0, `the job's view: ${JSON.stringify(original)}`);
  await page.waitForSelector('#v-mouse-camera[aria-pressed="true"]:not([disabled])');
  assert.match(await page.textContent('#v-mouse-hint'), /Drag to orbit/);
  assert.match(await page.textContent('#v-view'), /scene's own framing/);
  let moved;
  const { most, listed } = await watchPreviews(async () => {
    await dragOnImage([0.25, 0.5], [0.75, 0.5]);
    moved = await restedJob(originalId);
  });
  assert.ok(most <= 1, `${most} previews were live at once`);
  assert.deepEqual(listed, [], 'the job list showed previews');
  const cam = moved.spec.camera;
  assert.ok(cam, 'the job at rest has no camera field');
  assertNear(cam.target, original.target, 1e-4, 'the target');
  assertNear(dist(cam), dist(original), 1e-3 * dist(original), 'the distance');
  assertNear(angleDiff(azimuth(cam), azimuth(original)), -Math.PI / 2, 0.03, 'the azimuth turned');
  assertNear(polar(cam), polar(original), 0.01, 'the polar angle');
  assertNear(cam.vfov, original.vfov, 1e-3, 'the field of view');
  // The form's settings, at the form's size.
  assert.deepEqual([moved.width, moved.height, moved.spec.spp, moved.spec.max_depth], [64, 48, 4, 2]);
  assertNear(moved.view.position, cam.position, 1e-4, 'the view it renders from');
  // Previews were small and quick, one at a time: each submitted only once the one before was gone.
  const posts = events.filter((e) => e.kind === 'post');
  assert.ok(posts.length >= 1, 'no preview streamed while the view moved');
  for (const { body } of posts) {
    assert.deepEqual([body.width, body.height, body.spp, body.adaptive, body.scene], [21, 16, 4, false, 'cornell']);
    assert.ok(body.camera && body.camera.position.length === 3);
  }
  let live = 0;
  for (const e of events) {
    live += e.kind === 'post' ? 1 : previewIds.has(e.id) ? -1 : 0;
    assert.ok(live <= 1, `a preview was submitted while another was live: ${JSON.stringify(events.map((x) => x.kind))}`);
  }
  // None is left, on the server or in the list.
  await page.waitForFunction(() => document.querySelector('#viewer').dataset.nav === 'rest');
  for (const id of previewIds) {
    for (let i = 0; i < 100 && (await api.get(`/api/jobs/${id}`)).status !== 404; ++i) await new Promise((r) => setTimeout(r, 100));
    assert.equal((await api.get(`/api/jobs/${id}`)).status, 404, `preview ${id} was not deleted`);
    assert.equal(await page.$(`#job-rows tr[data-id="${id}"]`), null);
  }
  await page.screenshot({ path: path.join(artifacts, 'web-camera-orbit.png') });
});

test('shift-drag and right-drag pan camera and target together in the view plane', async () => {
  const from = await job(await viewedJobId());
  const v = from.view;
  const box = await dragOnImage([0.5, 0.5], [0.75, 0.5], { shift: true });
  const panned = await restedJob(from.id);
  // A pixel moves distance / screen_distance, screen_distance = (height / 2) / tan(vfov / 2).
  const back = norm(sub(v.position, v.target));
  const right = norm(cross(v.up, back)), up = cross(back, right);
  const perPixel = (2 * dist(v) * Math.tan((v.vfov * Math.PI) / 360)) / box.height;
  const want = add(v.target, scale(right, -0.25 * box.width * perPixel));
  const cam = panned.spec.camera;
  assertNear(cam.target, want, 0.02 * 0.25 * box.width * perPixel, 'the panned target');
  assertNear(sub(cam.position, cam.target), sub(v.position, v.target), 1e-3, 'the camera kept its offset');
  // A right-drag pans too (down: the camera goes up, the scene follows the pointer).
  const v2 = panned.view;
  const box2 = await dragOnImage([0.5, 0.4], [0.5, 0.6], { button: 'right' });
  const down = await restedJob(panned.id);
  const want2 = add(v2.target, scale(up, 0.2 * box2.height * perPixel));
  assertNear(down.spec.camera.target, want2, 0.02 * 0.2 * box2.height * perPixel, 'the right-dragged target');
});

test('a vertical drag turns the polar angle and stops short of the pole', async () => {
  const from = await job(await viewedJobId());
  await dragOnImage([0.5, 0.02], [0.5, 0.98]);  // almost a whole height down: almost pi up
  const top = await restedJob(from.id);
  const p = polar(top.spec.camera);
  assert.ok(p > 0 && p < 0.01 + Math.max(0, polar(from.view) - 0.96 * Math.PI), `polar angle ${p}`);
  assertNear(top.spec.camera.target, from.view.target, 1e-4, 'the target');
});

test('the wheel dollies by 1/20 of the starting distance a step, within [1/20, 10] of it', async () => {
  const d0 = dist(original);
  const from = await job(await viewedJobId());
  const box = await page.locator('#v-canvas').boundingBox();
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  for (let i = 0; i < 3; ++i) {
    await page.mouse.wheel(0, -100);
    await page.waitForTimeout(60);
  }
  const closer = await restedJob(from.id);
  assertNear(dist(closer.spec.camera), dist(from.view) - (3 * d0) / 20, 1e-3 * d0, 'three steps in');
  assertNear(closer.spec.camera.target, from.view.target, 1e-4, 'the target');
  await page.mouse.wheel(0, 100 * 400);
  const far = await restedJob(closer.id);
  assertNear(dist(far.spec.camera), 10 * d0, 1e-3 * d0, 'as far as it goes');
  await page.mouse.wheel(0, -100 * 400);
  const near = await restedJob(far.id);
  assertNear(dist(near.spec.camera), d0 / 20, 1e-3 * d0, 'as near as it goes');
});

test('a click without a drag still focuses there', async () => {
  await page.locator('#v-canvas').click({ position: { x: 20, y: 20 } });
  await page.waitForFunction(() => /^(Focal distance set to|Nothing to focus on)/.test(document.querySelector('#v-note').textContent));
  assert.equal(await page.getAttribute('#viewer', 'data-nav'), 'rest');
});

test("the job list, the viewer and compare show a moved job's camera", async () => {
  const id = await viewedJobId();
  const cam = (await job(id)).spec.camera;
  await page.waitForSelector(`#job-rows tr[data-id="${id}"]`);
  const other = await page.textContent(`#job-rows tr[data-id="${id}"] td.other`);
  assert.match(other, /camera from \(.*\) at \(.*\)/);
  const short = (x) => (Math.abs(x) < 1e-9 ? 0 : Number(x.toPrecision(3)));  // rounding noise reads 0
  assert.ok(other.includes(`(${cam.target.map(short).join(', ')})`), other);
  assert.match(await page.textContent('#v-view'), /^Camera from \(/);
  assert.ok(await page.isVisible('#form-view'), 'the form does not say its camera was moved');
  await page.check(`#job-rows tr[data-id="${originalId}"] input[data-action="compare"]`);
  await page.check(`#job-rows tr[data-id="${id}"] input[data-action="compare"]`);
  await page.waitForSelector('#compare-diff tr[data-field="camera"]');
  const cells = await page.$$eval('#compare-diff tr[data-field="camera"] td', (t) => t.map((x) => x.textContent));
  assert.equal(cells[1], "the scene's own framing");
  assert.match(cells[2], /^from \(/);
  await page.click('#compare-close');
});

test("Reset view goes back to the scene's own framing", async () => {
  const from = await viewedJobId();
  await page.click('#v-reset-view');
  const reset = await restedJob(from);
  assert.equal(reset.spec.camera, null);
  assertNear(reset.view.position, original.position, 1e-4, 'the position');
  assertNear(reset.view.target, original.target, 1e-4, 'the target');
  assertNear(reset.view.vfov, original.vfov, 1e-4, 'the field of view');
  assert.ok(await page.isHidden('#form-view'));
  assert.ok(await page.isDisabled('#v-reset-view'));
});

test('a half-size sweep renders a smaller copy of the view on screen, not a crop of it', async () => {
  const shown = (await job(await viewedJobId())).view;
  await page.check('#sweep-half');
  await page.click('#focus-stack');
  await page.waitForFunction(() => document.querySelectorAll('#sweep-grid .cell[data-ended="true"][data-state="done"]').length === 4);
  const ids = await page.$$eval('#sweep-grid .cell', (cs) => cs.map((c) => c.dataset.id));
  for (const id of ids) {
    const j = await job(id);
    assert.deepEqual([j.width, j.height], [32, 24]);
    assertNear(j.spec.camera.position, shown.position, 1e-4, 'the sweep camera');
    assertNear(j.view.vfov, shown.vfov, 1e-3, 'the sweep field of view');
  }
  await page.uncheck('#sweep-half');
  await page.click('#sweep-close');
});

test('no preview is left and none was ever listed', async () => {
  const { jobs } = await api.json('/api/jobs?limit=1000');
  assert.deepEqual(jobs.filter((j) => previewIds.has(j.id)).map((j) => j.id), []);
  assert.ok(previewIds.size >= 4, `${previewIds.size} previews in all`);
});

test('no uncaught errors on the page', () => {
  assert.deepEqual(pageErrors, []);
});
