// Denoising on the page, in a real browser against a real render-server (harness.mjs): a job
// submitted through the form with denoise "final" shows a Raw / Denoised switch whose two pictures
// are the raw render and a smoother denoised one (read back from the canvas, live and after a
// reload), the panel labels its error estimate raw and shows the denoised noise estimate, its raw
// downloads are ?raw=1, the list names its setting and compare sets its raw render against its
// denoised picture. A server without a denoiser (PT_OIDN_LIB at nothing) leaves the form's Denoise
// control disabled, its reason beside it, and a 422 naming denoise shows beside that control; one
// whose denoiser fails (tests/fake_oidn.cpp: PT_FAKE_OIDN, default libfake_oidn.so in
// PT_WEB_ARTIFACTS, which ctest makes build/tests where it is built) shows the job's warning.
//
// It needs a render-server that can denoise (scripts/install-oidn.sh); without one it exits 77
// (skipped), or fails under CI=true, as a missing browser does (missing.mjs).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { skip } from './missing.mjs';
import { artifacts, startServer, stopServer, makeDataDir, openBrowser, apiClient, pageSteps, waitReady, assertFitsWidth } from './harness.mjs';

let dataDir, server, baseUrl, browser, page, api, jobId;
let fill, submit, waitViewerEnded;
const pageErrors = [];

before(async () => {
  dataDir = makeDataDir('web-denoise-test');
  ({ proc: server, url: baseUrl } = await startServer(dataDir));
  api = apiClient(baseUrl);
  const { denoiser } = await api.json('/api/health');
  if (!denoiser || !denoiser.available) {
    await stopServer(server);
    fs.rmSync(dataDir, { recursive: true, force: true });
    skip(`the render-server cannot denoise: ${denoiser ? denoiser.description : 'no denoiser in /api/health'}`);
  }
  fs.mkdirSync(artifacts, { recursive: true });
  ({ browser, page } = await openBrowser(baseUrl, pageErrors));
  ({ fill, submit, waitViewerEnded } = pageSteps(page));
});

after(async () => {
  if (browser) await browser.close();
  if (server) await stopServer(server);
  if (dataDir) fs.rmSync(dataDir, { recursive: true, force: true });
});

// The viewer canvas's roughness: the mean absolute luma step between neighbouring pixels (0-255).
// Path-tracing noise is rough; a denoised picture of the same scene is far smoother.
function canvasRoughness(selector = '#v-canvas') {
  return page.evaluate((sel) => {
    const c = document.querySelector(sel);
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    const luma = (x, y) => { const i = 4 * (y * c.width + x); return 0.2126 * d[i] + 0.7152 * d[i + 1] + 0.0722 * d[i + 2]; };
    let sum = 0, n = 0;
    for (let y = 0; y + 1 < c.height; ++y) {
      for (let x = 0; x + 1 < c.width; ++x) {
        sum += Math.abs(luma(x, y) - luma(x + 1, y)) + Math.abs(luma(x, y) - luma(x, y + 1));
        n += 2;
      }
    }
    return sum / n;
  }, selector);
}

// The mean absolute byte difference between the viewer canvas and the image at `url` (decoded by
// the browser as the page decodes it), over RGB.
function canvasVersusImage(url) {
  return page.evaluate(async (u) => {
    const c = document.querySelector('#v-canvas');
    const bmp = await createImageBitmap(await (await fetch(u)).blob(), { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
    const o = document.createElement('canvas');
    o.width = bmp.width;
    o.height = bmp.height;
    o.getContext('2d').drawImage(bmp, 0, 0);
    if (o.width !== c.width || o.height !== c.height) return Infinity;
    const a = c.getContext('2d').getImageData(0, 0, c.width, c.height).data, b = o.getContext('2d').getImageData(0, 0, o.width, o.height).data;
    let s = 0;
    for (let i = 0; i < a.length; i += 4) for (let k = 0; k < 3; ++k) s += Math.abs(a[i + k] - b[i + k]);
    return s / ((a.length / 4) * 3);
  }, url);
}

async function pick(picture) {
  await page.click(picture === 'raw' ? '#v-show-raw' : '#v-show-denoised');
  await page.waitForSelector(`#viewer[data-picture="${picture}"]`);
}

// Raw and denoised on the canvas: different pictures, the denoised one smoother, each the server's.
async function assertSwitchPaints(where) {
  await pick('denoised');
  const denoised = await canvasRoughness();
  assert.ok(await canvasVersusImage(`/api/jobs/${jobId}/image.png`) < 0.5, `${where}: the denoised view is image.png`);
  await pick('raw');
  const raw = await canvasRoughness();
  assert.equal(await canvasVersusImage(`/api/jobs/${jobId}/image.png?raw=1`), 0, `${where}: the raw view is image.png?raw=1`);
  assert.ok(denoised < 0.6 * raw, `${where}: the denoised picture (roughness ${denoised}) is not smoother than the raw one (${raw})`);
  await pick('denoised');
  assert.equal(await canvasRoughness(), denoised, `${where}: back to the same denoised picture`);
}

test('a job denoised "final" through the form: the Raw / Denoised switch paints two different pictures', async () => {
  assert.equal(await page.isDisabled('#f-denoise'), false);
  assert.ok(await page.isHidden('#denoiser-note'));
  await fill({ scene: 'cornell', width: 96, height: 72, spp: 64, max_depth: 4, adaptive: false });
  await page.selectOption('#f-denoise', 'final');
  jobId = await submit({});
  assert.equal((await api.json(`/api/jobs/${jobId}`)).spec.denoise, 'final');
  await page.waitForSelector('#v-denoise:not([hidden])');  // the switch shows for a denoised job at once
  await waitViewerEnded('done');
  assert.ok(await page.isVisible('#v-show-denoised') && await page.isVisible('#v-show-raw'));
  await page.waitForSelector('#viewer[data-picture="denoised"]');
  assert.match(await page.textContent('#v-picture'), /denoised image/);
  await assertSwitchPaints('live');
  await page.screenshot({ path: path.join(artifacts, 'web-denoise-viewer.png') });
});

test('the panel labels the estimate raw and shows the denoised noise estimate and the denoise facts', async () => {
  const job = await api.json(`/api/jobs/${jobId}`);
  const dn = job.denoise;
  assert.ok(dn && dn.final && dn.frames >= 1 && Number.isFinite(dn.noise_estimate), JSON.stringify(dn));
  assert.equal(await page.textContent('#v-error-label'), 'Raw error estimate');
  assert.notEqual(await page.textContent('#v-error'), '–');
  assert.ok(await page.isVisible('#v-noise-box'));
  assert.match(await page.textContent('#v-noise-box dt'), /Denoised noise estimate.*halves, excludes bias/);
  assert.equal(Number(await page.textContent('#v-noise')), Number(dn.noise_estimate.toPrecision(3)));
  assert.match(await page.textContent('#v-denoise-info'), new RegExp(`^final · ${dn.frames} pictures? · last `));
  assert.ok(await page.isHidden('#v-denoise-warning'));
});

test('downloads: the denoised images and the raw ones at ?raw=1, in the viewer and the job list', async () => {
  const row = `#job-rows tr[data-id="${jobId}"]`;
  await page.waitForSelector(`${row}[data-state="done"] [data-action="raw-png"][href]`);
  for (const [sel, ext, raw] of [['#v-png', 'png', false], ['#v-exr', 'exr', false], ['#v-raw-png', 'png', true],
    ['#v-raw-exr', 'exr', true], [`${row} [data-action="raw-png"]`, 'png', true], [`${row} [data-action="raw-exr"]`, 'exr', true]]) {
    const href = await page.getAttribute(sel, 'href');
    assert.equal(href, `/api/jobs/${jobId}/image.${ext}${raw ? '?raw=1' : ''}`, sel);
    const r = await api.get(href);
    assert.equal(r.status, 200, sel);
    assert.ok(r.body.length > 100, sel);
  }
  assert.match(await page.getAttribute('#v-raw-png', 'download'), /-raw\.png$/);
  assert.deepEqual([await page.textContent('#v-png'), await page.textContent('#v-raw-png')], ['Denoised PNG', 'Raw PNG']);
  assert.match(await page.textContent(`${row} td.other`), /denoise final/);
  assert.match(await page.getAttribute(`${row} td.error-est`, 'title'), /raw render.*denoised noise estimate/);
  const [scrollW, clientW] = await page.evaluate(() => {
    const t = document.querySelector('.table-scroll');
    return [t.scrollWidth, t.clientWidth];
  });
  assert.ok(scrollW <= clientW, `the job table is ${scrollW} px wide in ${clientW} px`);
});

test('after a reload the finished job shows both pictures from its stored images', async () => {
  await page.reload();
  await waitReady(page);
  await page.waitForFunction((id) => location.hash === `#job=${id}`, jobId);
  await waitViewerEnded('done');
  await assertSwitchPaints('reloaded');
});

test('compare sets the raw render against the denoised picture of the same job', async () => {
  await page.click('#v-compare-raw');
  await page.waitForSelector('#compare:not([hidden])');
  assert.match(await page.textContent('#compare-a-label'), new RegExp(`job ${jobId.slice(-8)} · denoised$`));
  assert.match(await page.textContent('#compare-b-label'), new RegExp(`job ${jobId.slice(-8)} · raw$`));
  assert.equal(await page.inputValue('#compare-b-picture'), 'raw');
  await page.waitForSelector('#compare-diff tr[data-field="picture"]');
  assert.deepEqual(await page.$$eval('#compare-diff tbody tr', (rows) => rows.map((r) => r.dataset.field)), ['picture']);
  await page.waitForFunction(() => ['#compare-a', '#compare-b'].every((s) => document.querySelector(s).width === 96));
  assert.ok(await canvasRoughness('#compare-a') < 0.6 * await canvasRoughness('#compare-b'));
  await page.check('input[name="compare-mode"][value="diff"]');
  await page.waitForSelector('#compare-stage[data-diff="abs"]');
  assert.match(await page.textContent('#compare-diff-stats'), /^absolute error: mean \d.*8-bit pictures: a denoised picture/);
  // B back to the denoised picture: the same picture on both sides, no error.
  await page.selectOption('#compare-b-picture', 'denoised');
  await page.waitForFunction(() => /largest 0 \(/.test(document.querySelector('#compare-diff-stats').textContent));
  await page.locator('#compare').screenshot({ path: path.join(artifacts, 'web-denoise-compare.png') });
  await page.click('#compare-close');
});

test('a narrow window needs no sideways scrolling with the denoise controls, the raw links and compare open', async () => {
  await page.click('#v-compare-raw');
  await page.waitForSelector('#compare:not([hidden])');
  await page.setViewportSize({ width: 390, height: 844 });
  await page.waitForTimeout(300);
  await assertFitsWidth(page, assert);
  await page.screenshot({ path: path.join(artifacts, 'web-denoise-narrow.png'), fullPage: true });
  await page.setViewportSize({ width: 1280, height: 900 });
  await page.click('#compare-close');
});

// Runs `fn(page, url)` against a render-server of its own, started with environment `env`, in a
// browser of its own; its page must raise no uncaught error.
async function withServer(name, env, fn) {
  const dir = makeDataDir(name);
  const srv = await startServer(dir, 0, [], env);
  const errors = [];
  let b;
  try {
    let p;
    ({ browser: b, page: p } = await openBrowser(srv.url, errors));
    await fn(p, srv.url);
  } finally {
    if (b) await b.close();
    await stopServer(srv.proc);
    fs.rmSync(dir, { recursive: true, force: true });
  }
  assert.deepEqual(errors, []);
}

test('a server without a denoiser: the Denoise control is disabled with its reason, a 422 shows beside it', async () => {
  await withServer('web-denoise-bare', { PT_OIDN_LIB: '/nonexistent/lib.so' }, async (p, url) => {
    const { denoiser } = await apiClient(url).json('/api/health');
    assert.equal(denoiser.available, false);
    await p.waitForSelector('#f-denoise:disabled');
    assert.equal(await p.inputValue('#f-denoise'), 'off');
    assert.ok(await p.isVisible('#denoiser-note'));
    const note = await p.textContent('#denoiser-note');
    assert.match(note, /^Denoising is not available on this server/);
    assert.ok(note.includes(denoiser.description), `${note} lacks ${denoiser.description}`);
    // A page that asks anyway (as one from before the server lost its denoiser would): the
    // server's refusal is shown beside the control, in the form's words, and no job is made.
    await p.evaluate(() => {
      const s = document.querySelector('#f-denoise');
      s.disabled = false;
      s.value = 'final';
    });
    await p.click('#submit');
    await p.waitForFunction(() => document.querySelector('#err-denoise').textContent !== '');
    assert.match(await p.textContent('#err-denoise'), /^Denoise is "final", but on this server/);
    assert.equal(await p.getAttribute('#f-denoise', 'aria-invalid'), 'true');
    assert.equal((await apiClient(url).json('/api/jobs')).jobs.length, 0);
    await p.screenshot({ path: path.join(artifacts, 'web-denoise-unavailable.png') });
  });
});

// tests/fake_oidn.cpp, built beside the web tests' artifacts (build/tests) by ctest's build.
const fakeOidn = process.env.PT_FAKE_OIDN || path.join(artifacts, 'libfake_oidn.so');

test('a denoiser that fails: the job renders raw and the viewer shows the warning prominently', { skip: !fs.existsSync(fakeOidn) && `no ${fakeOidn}` }, async () => {
  await withServer('web-denoise-failing', { PT_OIDN_LIB: fakeOidn, FAKE_OIDN_FAIL: '1' }, async (p, url) => {
    const steps = pageSteps(p);
    await steps.fill({ scene: 'cornell', width: 48, height: 36, spp: 8, max_depth: 2 });
    await p.selectOption('#f-denoise', 'final');
    await steps.submit({});
    await steps.waitViewerEnded('done');
    await p.waitForSelector('#v-denoise-warning:not([hidden])');
    assert.match(await p.textContent('#v-denoise-warning'), /^Denoising failed: .*out of memory/);
    assert.equal(await p.getAttribute('#viewer', 'data-picture'), 'raw');
    assert.match(await p.textContent('#v-picture'), /denoising failed/);
    assert.ok(await p.isHidden('#v-noise-box'));  // no denoised image, no noise estimate of one
    assert.equal(await p.textContent('#v-png'), 'PNG');  // image.png is the raw render too
    await p.locator('#viewer').screenshot({ path: path.join(artifacts, 'web-denoise-failed.png') });
  });
});

test('no uncaught errors on the page', () => {
  assert.deepEqual(pageErrors, []);
});
