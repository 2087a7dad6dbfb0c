// The form in a real browser against a real render-server (harness.mjs): it keeps what the user
// set across a reload (the newest job's settings are not copied over it), picking a scene resets
// the lens to that scene's own, its errors speak the form's labels, and at 1280x800 the Render
// button shows without scrolling and the job table fits its width.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { artifacts, startServer, stopServer, makeDataDir, openBrowser, waitReady, apiClient, pageSteps } from './harness.mjs';

let dataDir, server, baseUrl, browser, page, api, defaults;
let fill, submit, waitViewerEnded;
const pageErrors = [];

before(async () => {
  dataDir = makeDataDir('web-form-test');
  ({ proc: server, url: baseUrl } = await startServer(dataDir));
  api = apiClient(baseUrl);
  ({ defaults } = await api.json('/api/scenes'));
  ({ browser, page } = await openBrowser(baseUrl, pageErrors));
  ({ fill, submit, waitViewerEnded } = pageSteps(page));
});

after(async () => {
  if (browser) await browser.close();
  if (server) await stopServer(server);
  if (dataDir) fs.rmSync(dataDir, { recursive: true, force: true });
});

const value = (name) => page.inputValue(`#f-${name}`);

test('a reload keeps what the user typed; the newest job is shown, not copied into the form', async () => {
  assert.equal(await value('framing'), 'crop');  // the API's and the CLI's framing
  assert.equal(Number(await value('spp')), defaults.spp);
  // Someone else's job is the newest when the page loads again.
  const other = await api.post('/api/jobs', { scene: 'dof', width: 40, height: 30, spp: 3, seed: 9, max_depth: 2 });
  assert.equal(other.status, 201);
  await fill({ spp: 7, width: 56, height: 42, seed: 5, max_depth: 4 });
  await page.selectOption('#f-framing', 'whole');
  await page.reload();
  await waitReady(page);
  // The page opens the newest job in the viewer...
  await page.waitForFunction((id) => location.hash === `#job=${id}`, other.data.id);
  await page.waitForSelector('#viewer[data-state="done"]');
  // ...and the form still holds what was typed.
  for (const [k, v] of Object.entries({ scene: 'cornell', spp: '7', width: '56', height: '42', seed: '5', max_depth: '4', framing: 'whole' }))
    assert.equal(await value(k), v, k);
  await page.selectOption('#f-framing', 'crop');
});

test('picking a scene resets the aperture and focal distance to the job defaults (scenes carry no lens)', async () => {
  await fill({ scene: 'cornell', aperture: 0.3, focal_distance: 2.2 });
  for (const name of ['dof', 'cornell']) {
    await page.selectOption('#f-scene', name);
    assert.equal(Number(await value('focal_distance')), defaults.focal_distance, `${name}: focal distance`);
    assert.equal(Number(await value('aperture')), defaults.aperture, `${name}: aperture`);
    await fill({ aperture: 0.3, focal_distance: 2.2 });
  }
  // A job's settings put in by "Reuse settings" keep their lens: only a pick resets it.
  const id = await submit({ scene: 'dof', aperture: 0.07, focal_distance: 3.1, width: 32, height: 24, spp: 2 });
  await waitViewerEnded('done');
  await fill({ scene: 'cornell' });
  await page.click('#v-edit');
  await page.waitForFunction(() => document.querySelector('#f-scene').value === 'dof');
  assert.deepEqual([await value('aperture'), await value('focal_distance')], ['0.07', '3.1']);
  assert.equal((await api.json(`/api/jobs/${id}`)).spec.aperture, 0.07);
});

test("form errors speak the form's labels, not the API's field names", async () => {
  await fill({ spp: 0, max_depth: -1 });
  await page.waitForFunction(() => document.querySelector('#err-max_depth').textContent !== '');
  assert.match(await page.textContent('#err-spp'), /^Samples per pixel must be between 1 and \d+$/);
  assert.match(await page.textContent('#err-max_depth'), /^Max ray depth must be between 0 and \d+$/);
  await page.click('details.more summary');
  await fill({ spp: 4, max_depth: 2, adaptive_tolerance: 3 });
  await page.waitForFunction(() => document.querySelector('#err-spp').textContent === '' &&
    /^Adaptive tolerance must be between 0 and 1$/.test(document.querySelector('#err-adaptive_tolerance').textContent));
  // The answer to a submit speaks the same way.
  const jobs = (await api.json('/api/jobs')).jobs.length;
  await fill({ adaptive_tolerance: 0.05, spp: 0 });
  await page.click('#submit');
  await page.waitForFunction(() => /^Samples per pixel must be between 1 and \d+$/.test(document.querySelector('#err-spp').textContent));
  assert.equal((await api.json('/api/jobs')).jobs.length, jobs);
  await fill({ spp: 4 });
  await page.waitForFunction(() => !document.querySelector('#job-form [aria-invalid]'));
});

test('at 1280x800 the Render button shows without scrolling and the job table fits its width', async () => {
  // Jobs whose settings fill the "Other settings" column, a camera's too where the server has them.
  const viewed = (await api.post('/api/jobs/check', { scene: 'cornell' })).data.view;
  const long = { scene: 'cornell', width: 24, height: 18, spp: 1, light_samples: 3, seed: 12345, time_limit: 100,
    target_error: 0.001, caustic_tracing: false, adaptive_tolerance: 0.2 };
  const camera = viewed && { position: viewed.position.map((x) => x + 0.123456), target: viewed.target, vfov: 33.3333 };
  for (const extra of [{ frame_scene: true }, { keep_fov: true }, camera ? { camera } : { seed: 123456789 }])
    assert.equal((await api.post('/api/jobs', { ...long, ...extra })).status, 201);
  // The page opened afresh in a window of that size.
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(baseUrl);
  await waitReady(page);
  await page.waitForFunction(() => document.querySelectorAll('#job-rows tr').length >= 5);
  assert.equal(await page.evaluate(() => window.scrollY), 0);
  const box = await page.locator('#submit').boundingBox();
  assert.ok(box.y >= 0 && box.y + box.height <= 800, `the Render button is at ${box.y}..${box.y + box.height} in an 800 px window`);
  if (viewed) {  // and with the line that says the camera was moved
    await page.evaluate((camera) => setFormCamera({ scene: 'cornell', camera }), viewed);
    await page.waitForSelector('#form-view:not([hidden])');
    const moved = await page.locator('#submit').boundingBox();
    assert.ok(moved.y + moved.height <= 800, `with a moved camera the Render button ends at ${moved.y + moved.height}`);
  }
  const [scrollW, clientW, docW] = await page.evaluate(() => {
    const t = document.querySelector('.table-scroll');
    return [t.scrollWidth, t.clientWidth, document.documentElement.scrollWidth];
  });
  assert.ok(scrollW <= clientW, `the job table is ${scrollW} px wide in ${clientW} px`);
  assert.ok(docW <= 1280, `the page is ${docW} px wide`);
  if (viewed) assert.match(await page.textContent('#job-rows td.other'), /camera from \(/);
  fs.mkdirSync(artifacts, { recursive: true });
  await page.screenshot({ path: path.join(artifacts, 'web-form-1280x800.png') });
  await page.close();
});

test('no uncaught errors on the page', () => {
  assert.deepEqual(pageErrors, []);
});
