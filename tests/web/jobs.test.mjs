// The page's job list and what it does to jobs, in a real browser against a real render-server
// (harness.mjs): the columns that tell a focus stack's jobs apart, pause and resume, a cancelled
// job's downloads, delete, render more, the form kept across a reload (Reuse settings copies a job's in),
// paging, and uploading a scene. Every wait is on a state the page or the server shows, never on the clock.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { artifacts, sourceDir, startServer, stopServer, makeDataDir, openBrowser, waitReady, apiClient, pageSteps, assertFitsWidth } from './harness.mjs';

let dataDir, server, baseUrl, browser, page, api, defaults;
let fill, submit, waitViewerEnded;
const pageErrors = [];

before(async () => {
  dataDir = makeDataDir('web-jobs-test');
  // The paging test queues more than the default 32 jobs at once.
  ({ proc: server, url: baseUrl } = await startServer(dataDir, 0, ['--max-queue', '200']));
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

const row = (id) => `#job-rows tr[data-id="${id}"]`;
const cellText = (id, cls) => page.textContent(`${row(id)} td.${cls}`).then((t) => t.trim());

let stack;  // the focus stack's job ids

test('the form offers the adaptive tolerance with the API default and says what it does', async () => {
  await page.click('details.more summary');
  assert.equal(Number(await page.inputValue('#f-adaptive_tolerance')), defaults.adaptive_tolerance);
  const hint = await page.textContent('[data-field="adaptive_tolerance"] .hint');
  assert.match(hint, /before the spp budget/);
  await fill({ adaptive_tolerance: 2 });
  await page.waitForFunction(() => /^Adaptive tolerance must be between 0 and 1/.test(document.querySelector('#err-adaptive_tolerance').textContent));
  await fill({ adaptive_tolerance: defaults.adaptive_tolerance });
  await page.waitForFunction(() => document.querySelector('#err-adaptive_tolerance').textContent === '');
});

test("the job list shows each job's settings, and a focus stack's rows differ in their focus", async () => {
  await fill({ width: 64, height: 48, spp: 4, aperture: 0.1 });
  await page.click('#focus-stack');
  await page.waitForFunction(() => document.querySelectorAll('#sweep-grid .cell').length === 4);
  stack = await page.$$eval('#sweep-grid .cell', (cs) => cs.map((c) => c.dataset.id));
  for (const id of stack) await page.waitForSelector(`${row(id)}[data-state="done"]`);
  const headers = await page.$$eval('#job-table th', (ths) => ths.map((th) => th.textContent.trim()));
  for (const h of ['Created', 'Scene', 'Size', 'Depth', 'Aperture', 'Focus', 'spp', 'Error', 'Duration', 'State', 'Actions'])
    assert.ok(headers.includes(h), `no ${h} column in ${headers}`);

  const focus = [];
  for (const id of stack) {
    const job = await api.json(`/api/jobs/${id}`);
    focus.push(await cellText(id, 'focus'));
    assert.equal(Number(focus.at(-1)), job.spec.focal_distance);
    assert.equal(await cellText(id, 'size'), '64×48');
    assert.equal(await cellText(id, 'depth'), String(defaults.max_depth));
    assert.equal(await cellText(id, 'aperture'), '0.1');
    assert.equal(await cellText(id, 'spp'), '4 / 4');
    assert.match(await cellText(id, 'created'), /\d/);
    assert.match(await cellText(id, 'duration'), /^\d+(\.\d)? s$/);
    assert.notEqual(await cellText(id, 'error-est'), '–');
    assert.equal((await page.textContent(`${row(id)} .badge`)).trim(), 'done');
    // The varied setting is marked, the shared ones are not.
    assert.ok(await page.$(`${row(id)} td.focus.differs`), `job ${id}: focus not marked`);
    for (const cls of ['size', 'depth', 'aperture', 'spp'])
      assert.equal(await page.$(`${row(id)} td.${cls}.differs`), null, `job ${id}: ${cls} marked`);
    // A finished job: Delete instead of Cancel, no Pause, and its images.
    assert.ok(await page.isVisible(`${row(id)} [data-action="delete"]`));
    assert.ok(await page.isHidden(`${row(id)} [data-action="cancel"]`));
    assert.ok(await page.isHidden(`${row(id)} [data-action="pause"]`));
    assert.ok(await page.getAttribute(`${row(id)} [data-action="png"]`, 'href'));
  }
  assert.equal(new Set(focus).size, 4, `focus column ${focus}`);
  await page.click('#sweep-close');
});

// A click is a press and a release on the same element: a refresh between them that moves the rows
// (here a new job on top) must not lose it.
test('a click on a row is not lost when the list refreshes while the button is pressed', async () => {
  const box = `${row(stack[3])} input[data-action="compare"]`;
  await page.locator(box).scrollIntoViewIfNeeded();
  const b = await page.locator(box).boundingBox();
  await page.mouse.move(b.x + b.width / 2, b.y + b.height / 2);
  await page.mouse.down();
  const added = await api.post('/api/jobs', { scene: 'cornell', width: 8, height: 8, spp: 1 });
  assert.equal(added.status, 201);
  // The second refresh starts after the job was added (the first may have been under way).
  await page.evaluate(async () => { await refreshJobs(); await refreshJobs(); });
  await page.mouse.up();
  assert.equal(await page.isChecked(box), true, 'the press and release on the box did not tick it');
  await page.waitForSelector(`#job-rows tr:first-child[data-id="${added.data.id}"]`);  // shown once released
  await page.uncheck(box);
});

test('pause holds a job (paused badge, no ETA), resume takes it to done; a cancelled job downloads', async () => {
  // A long job A holds the renderer; B waits behind it.
  const a = await submit({ width: 320, height: 240, spp: 4096 });
  await page.waitForSelector('#viewer[data-state="running"]');
  await page.waitForFunction(() => !/^0 /.test(document.querySelector('#v-spp').textContent));
  const b = await submit({ width: 64, height: 48, spp: 4 });
  await page.waitForSelector(`${row(b)}[data-state="queued"]`);
  await page.click(`${row(b)} [data-action="pause"]`);
  await page.waitForSelector(`${row(b)}[data-state="paused"]`);
  assert.match(await page.textContent(`${row(b)} .badge`), /^paused/);

  await page.click(`${row(a)} [data-action="open"]`);
  await page.click('#v-pause');
  await page.waitForSelector('#viewer[data-state="paused"]');
  assert.equal((await page.textContent('#v-state')).trim(), 'paused');
  assert.equal(await page.textContent('#v-eta'), '–');
  assert.match(await page.textContent('#v-progress-text'), /^paused/);
  assert.equal((await page.textContent('#v-pause')).trim(), 'Resume');
  assert.equal((await api.json(`/api/jobs/${a}`)).eta, null);
  await page.waitForSelector(`${row(a)}[data-state="paused"]`);
  assert.ok(await page.isVisible(`${row(a)} [data-action="resume"]`));

  // Nothing renders while both wait: B resumed runs to done.
  await page.click(`${row(b)} [data-action="resume"]`);
  await page.waitForSelector(`${row(b)}[data-state="done"]`);
  assert.equal((await api.json(`/api/jobs/${b}`)).spp_done, 4);

  // A resumed from the viewer renders again; cancelled, it keeps its picture for download.
  await page.click('#v-pause');
  await page.waitForSelector('#viewer[data-state="running"]');
  await page.waitForFunction(() => !/^0 /.test(document.querySelector('#v-spp').textContent));
  await page.click('#v-cancel');
  await waitViewerEnded('cancelled');
  await page.waitForSelector(`${row(a)}[data-state="cancelled"] [data-action="png"][href]`);
  const png = await api.get(await page.getAttribute(`${row(a)} [data-action="png"]`, 'href'));
  assert.equal(png.status, 200);
  assert.deepEqual([...png.body.subarray(0, 4)], [0x89, 0x50, 0x4e, 0x47]);
  const exr = await api.get(await page.getAttribute(`${row(a)} [data-action="exr"]`, 'href'));
  assert.equal(exr.status, 200);
  assert.deepEqual([...exr.body.subarray(0, 4)], [0x76, 0x2f, 0x31, 0x01]);
});

test("Delete removes a finished job's row and the job", async () => {
  const id = stack[0];
  const del = `${row(id)} [data-action="delete"]`;
  await page.click(del);
  assert.equal((await page.textContent(del)).trim(), 'Delete?');  // a second click confirms
  assert.equal((await api.get(`/api/jobs/${id}`)).status, 200);
  await page.click(del);
  await page.waitForSelector(row(id), { state: 'detached' });
  assert.equal((await api.get(`/api/jobs/${id}`)).status, 404);
  stack.shift();
});

test('render more continues a done job to a larger spp', async () => {
  const id = stack[0];
  await page.click(`${row(id)} [data-action="open"]`);
  await waitViewerEnded('done');
  assert.equal((await api.json(`/api/jobs/${id}`)).can_continue, true);
  await page.waitForSelector('#v-more-form:not([hidden])');
  assert.ok(await page.isHidden('#v-pause'), 'a done job offers Pause');
  assert.equal(await page.inputValue('#v-more-spp'), '8');  // twice its 4 spp, to start
  await page.click('#v-more');
  await page.waitForFunction(() => /Rendering on to 8 spp/.test(document.querySelector('#v-note').textContent));
  await waitViewerEnded('done');
  const job = await api.json(`/api/jobs/${id}`);
  assert.equal(job.state, 'done');
  assert.equal(job.spec.spp, 8);
  assert.ok(job.spp_done > 4, `spp_done ${job.spp_done}`);
  assert.match(await page.textContent('#v-spp'), /^8 \/ 8$/);
  await page.waitForSelector(`${row(id)}[data-state="done"] td.spp:text-is("8 / 8")`);
});

test("the form keeps what the user set across a reload and opened jobs; Reuse settings copies a job's settings in", async () => {
  const settings = { scene: 'dof', max_depth: 3, light_samples: 2, aperture: 0.05, focal_distance: 3.3, spp: 3,
    width: 40, height: 30, seed: 7, adaptive: false, adaptive_tolerance: 0.2 };
  const first = await submit(settings);
  const firstSpec = (await api.json(`/api/jobs/${first}`)).spec;
  // The user types other values (picking a scene resets the lens to the scene's own) and renders them.
  await fill({ scene: 'cornell', max_depth: 6, spp: 5, width: 48, height: 36, seed: 1, adaptive: true });
  const second = await submit({});
  const typed = (await api.json(`/api/jobs/${second}`)).spec;
  await fill({ light_samples: 3 });  // typed after the last render
  const formHolds = async (s) => {
    await page.waitForFunction((s) => document.querySelector('#f-seed').value === String(s.seed) &&
      document.querySelector('#f-scene').value === s.scene, s);
    for (const [k, v] of Object.entries(s)) {
      if (!(k in settings)) continue;
      if (typeof v === 'boolean') assert.equal(await page.isChecked(`#f-${k}`), v, k);
      else if (k === 'scene') assert.equal(await page.inputValue('#f-scene'), v);
      else assert.equal(Number(await page.inputValue(`#f-${k}`)), v, k);
    }
  };
  const shown = (id, spec) => page.waitForFunction(([id, title]) => location.hash === `#job=${id}` &&
    document.querySelector('#viewer').dataset.state === 'done' && document.querySelector('#v-title').textContent.startsWith(title),
  [id, `${spec.scene} · ${spec.width}×${spec.height}`]);
  // A link to the first job, in the same tab: the job shows, the form keeps what was typed.
  await page.evaluate((id) => { location.hash = `job=${id}`; }, first);
  await shown(first, firstSpec);
  await formHolds({ ...typed, light_samples: 3 });
  // Reloaded on that address: still what was typed, not the job's settings.
  await page.reload();
  await waitReady(page);
  await shown(first, firstSpec);
  await formHolds({ ...typed, light_samples: 3 });
  // "Reuse settings" copies the job's settings in, and they are kept too.
  await page.click('#v-edit');
  await formHolds(firstSpec);
  await page.reload();
  await waitReady(page);
  await formHolds(firstSpec);
});

test('the list shows the newest 100 jobs and more on request', async () => {
  for (let i = 0; i < 101; ++i) {
    const r = await api.post('/api/jobs', { scene: 'cornell', width: 8, height: 8, spp: 1 });
    assert.ok(r.status === 201, `job ${i}: ${r.status} ${JSON.stringify(r.data)}`);
  }
  const total = (await api.json('/api/jobs?limit=1000')).jobs.length;
  const newest = (await api.json('/api/jobs?limit=1')).jobs[0].id;
  await page.waitForSelector(`${row(newest)}`);
  await page.waitForSelector('#jobs-more:not([hidden])');
  assert.equal(await page.$$eval('#job-rows tr', (rs) => rs.length), 100);
  assert.equal(await page.getAttribute('#job-rows tr:first-child', 'data-id'), newest);
  await page.click('#jobs-more');
  await page.waitForFunction((n) => document.querySelectorAll('#job-rows tr').length === n, total);
  assert.ok(await page.isHidden('#jobs-more'));
  fs.mkdirSync(artifacts, { recursive: true });
  await page.screenshot({ path: path.join(artifacts, 'web-jobs.png') });
  await page.setViewportSize({ width: 390, height: 844 });
  await page.waitForFunction(() => window.innerWidth === 390);
  await assertFitsWidth(page, assert);
  await page.screenshot({ path: path.join(artifacts, 'web-jobs-narrow.png') });
  await page.setViewportSize({ width: 1280, height: 900 });
});

test('a scene uploaded with the file picker is summarised, selected and renders; a broken one shows the loader', async () => {
  const cornell = fs.readFileSync(path.join(sourceDir, 'scenes', 'cornell.dae'));
  await page.setInputFiles('#f-upload', { name: 'My Room.dae', mimeType: 'model/vnd.collada+xml', buffer: cornell });
  await page.waitForFunction(() => /Scene 'My-Room' uploaded/.test(document.querySelector('#upload-status').textContent));
  assert.equal(await page.inputValue('#f-scene'), 'My-Room');
  assert.match(await page.textContent('#scene-summary'), /triangles/);
  const listed = (await api.json('/api/scenes')).scenes.find((sc) => sc.name === 'My-Room');
  assert.equal(listed.source, 'uploaded');
  const id = await submit({ scene: 'My-Room', spp: 2, width: 32, height: 24 });
  await waitViewerEnded('done');
  assert.equal((await api.json(`/api/jobs/${id}`)).spec.scene, 'My-Room');
  const broken = Buffer.from(cornell.toString().replace('</COLLADA>', ''));
  await page.setInputFiles('#f-upload', { name: 'broken.dae', mimeType: 'model/vnd.collada+xml', buffer: broken });
  await page.waitForFunction(() => document.querySelector('#upload-status').dataset.kind === 'error');
  assert.match(await page.textContent('#upload-status'), /^broken\.dae: broken\.dae/);
  assert.ok(!(await api.json('/api/scenes')).scenes.some((sc) => sc.name === 'broken'), 'a broken scene was stored');
  // A binary glTF, as a browser hands over a type it does not know: the page names the type by extension.
  const glb = fs.readFileSync(path.join(sourceDir, 'scenes', 'cornell_gltf.glb'));
  await page.setInputFiles('#f-upload', { name: 'box.glb', mimeType: '', buffer: glb });
  await page.waitForFunction(() => /Scene 'box' uploaded/.test(document.querySelector('#upload-status').textContent));
  assert.equal(await page.inputValue('#f-scene'), 'box');
  assert.match(await page.textContent('#scene-summary'), /triangles/);
  await submit({ scene: 'box', spp: 2, width: 32, height: 24 });
  await waitViewerEnded('done');
  assert.ok(await page.isHidden('#v-warnings'), 'a scene without loader warnings shows none');
  // A scene the loader warns about (no camera): the warnings show with its summary and with its job.
  const noCamera = Buffer.from(cornell.toString().replace(/<instance_camera url="[^"]*"\/>/, ''));
  await page.setInputFiles('#f-upload', { name: 'nocam.dae', mimeType: 'model/vnd.collada+xml', buffer: noCamera });
  await page.waitForFunction(() => /Scene 'nocam' uploaded/.test(document.querySelector('#upload-status').textContent));
  assert.match(await page.textContent('#scene-warnings summary'), /^1 loader warning:/);
  assert.match(await page.textContent('#scene-warnings li'), /^nocam\.dae:\d+: .*no <instance_camera>/);
  await submit({ scene: 'nocam', spp: 2, width: 32, height: 24 });
  await waitViewerEnded('done');
  assert.match(await page.textContent('#v-warnings li'), /no <instance_camera>/);
  assert.ok(await page.isVisible('#v-warnings'));
});

test('no uncaught errors on the page', () => {
  assert.deepEqual(pageErrors, []);
});
