// The viewer's tools and the comparison of two jobs, in a real browser against a real
// render-server (harness.mjs): exposure and display mappings on the float pixels (GET /pixels),
// the pixel readout, the sample-rate view, 1:1 zoom and pan, wheel zoom to 32x with square texels,
// the framing choice, and A/B compare side by side, as a wipe and as a false-colour difference. Pictures are checked by pixel statistics; every wait is on a state
// the page shows.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { artifacts, startServer, stopServer, makeDataDir, openBrowser, apiClient, pageSteps, assertFitsWidth } from './harness.mjs';

let dataDir, server, baseUrl, browser, page, api;
let submit, waitViewerEnded;
const pageErrors = [];

before(async () => {
  dataDir = makeDataDir('web-viewer-test');
  ({ proc: server, url: baseUrl } = await startServer(dataDir));
  api = apiClient(baseUrl);
  ({ browser, page } = await openBrowser(baseUrl, pageErrors));
  ({ submit, waitViewerEnded } = pageSteps(page));
});

after(async () => {
  if (browser) await browser.close();
  if (server) await stopServer(server);
  if (dataDir) fs.rmSync(dataDir, { recursive: true, force: true });
});

// A canvas's RGB bytes and size.
function canvasPixels(selector) {
  return page.evaluate((sel) => {
    const c = document.querySelector(sel);
    return { w: c.width, h: c.height, rgba: Array.from(c.getContext('2d').getImageData(0, 0, c.width, c.height).data) };
  }, selector);
}

// The job's /pixels as {w, h, at(x, y) -> [r, g, b, count]}.
async function floatPixels(id) {
  const r = await api.get(`/api/jobs/${id}/pixels`);
  assert.equal(r.status, 200);
  const job = await api.json(`/api/jobs/${id}`);
  const w = job.width, h = job.height;
  assert.equal(r.body.length, w * h * 16);
  return { w, h, at: (x, y) => [0, 1, 2, 3].map((c) => r.body.readFloatLE(16 * (y * w + x) + 4 * c)) };
}

const meanAbsDiff = (a, b) => {
  let s = 0, n = 0;
  for (let i = 0; i < a.length; i += 4) for (let c = 0; c < 3; ++c, ++n) s += Math.abs(a[i + c] - b[i + c]);
  return s / n;
};

async function setExposure(stops) {
  await page.fill('#v-exposure-n', String(stops));
  await page.dispatchEvent('#v-exposure-n', 'change');
}

// Moves a range input as a user's drag does: its value, then an input event.
function setRange(selector, value) {
  return page.$eval(selector, (el, v) => {
    el.value = String(v);
    el.dispatchEvent(new Event('input', { bubbles: true }));
  }, value);
}

async function showJob(values) {
  const id = await submit(values);
  await waitViewerEnded('done');
  await page.waitForSelector('#v-tools[data-data="loaded"]');
  return id;
}

let jobA, jobB;

// The share of a canvas's pixels that are near black (every channel at most 8 of 255).
async function blackShare(selector) {
  const { rgba } = await canvasPixels(selector);
  let black = 0;
  for (let i = 0; i < rgba.length; i += 4) black += rgba[i] <= 8 && rgba[i + 1] <= 8 && rgba[i + 2] <= 8;
  return black / (rgba.length / 4);
}

test('the scene-fitted framing fills the image; the course crop (the default, as the API\'s) and whole view leave black', async () => {
  assert.equal(await page.inputValue('#f-framing'), 'crop');
  assert.equal((await api.json('/api/scenes')).defaults.frame_scene, false);
  const share = {};
  for (const framing of ['scene', 'crop', 'whole']) {
    await page.selectOption('#f-framing', framing);
    // 640x480: the course crop is the middle 80% of the course's 800x600 view (smaller sizes crop
    // into the box, and show less of it rather than black).
    const id = await submit({ scene: 'cornell', width: 640, height: 480, spp: 4, max_depth: 3 });
    await waitViewerEnded('done');
    const spec = (await api.json(`/api/jobs/${id}`)).spec;
    assert.deepEqual([spec.frame_scene, spec.keep_fov], { scene: [true, false], crop: [false, false], whole: [false, true] }[framing]);
    share[framing] = await blackShare('#v-canvas');
    await page.locator('#v-wrap').screenshot({ path: path.join(artifacts, `web-viewer-framing-${framing}.png`) });
  }
  assert.ok(share.scene < share.crop / 2 && share.scene < share.whole / 2, `near-black shares: ${JSON.stringify(share)}`);
  await page.selectOption('#f-framing', 'crop');
});

test('exposure doubles linear values per stop', async () => {
  jobA = await showJob({ scene: 'cornell', width: 96, height: 72, spp: 16, max_depth: 5 });
  // A mapping or an exposure paints from the float pixels; the default view is the stream's PNG.
  await page.selectOption('#v-mapping', 'srgb');
  await page.waitForSelector('#v-tools[data-painted="srgb:0:false"]');
  await page.selectOption('#v-mapping', 'course');
  await setExposure(0.5);
  await page.waitForSelector('#v-tools[data-painted="course:0.5:false"]');
  await setExposure(0);
  await page.waitForSelector('#v-tools[data-painted="stream"]');  // the default view is the stream's own PNG
  await page.selectOption('#v-mapping', 'linear');
  await page.waitForSelector('#v-tools[data-painted="linear:0:false"]');
  const at0 = await canvasPixels('#v-canvas');
  await setExposure(1);
  await page.waitForSelector('#v-tools[data-painted="linear:1:false"]');
  const at1 = await canvasPixels('#v-canvas');
  let s0 = 0, s1 = 0, n = 0;
  for (let i = 0; i < at0.rgba.length; i += 4)
    for (let c = 0; c < 3; ++c) {
      const a = at0.rgba[i + c], b = at1.rgba[i + c];
      if (a >= 10 && a <= 120) { s0 += a; s1 += b; ++n; }  // unclipped at both exposures
    }
  assert.ok(n > 500, `${n} unclipped values`);
  assert.ok(Math.abs(s1 / s0 - 2) < 0.03, `+1 stop scaled the mean by ${s1 / s0}`);
  await page.screenshot({ path: path.join(artifacts, 'web-viewer-exposure.png') });
  await setExposure(0);
  await page.selectOption('#v-mapping', 'course');
  await page.waitForSelector('#v-tools[data-painted="stream"]');
});

test('the course curve computed from the float pixels gives image.png', async () => {
  await setExposure(0.000001);  // active, so the tools paint (2^1e-6 changes no byte here)
  await page.waitForSelector('#v-tools[data-painted="course:0.000001:false"]');
  const painted = await canvasPixels('#v-canvas');
  const png = await page.evaluate(async (id) => {
    const bmp = await createImageBitmap(await (await fetch(`/api/jobs/${id}/image.png`)).blob(),
      { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
    const off = new OffscreenCanvas(bmp.width, bmp.height);
    off.getContext('2d').drawImage(bmp, 0, 0);
    return Array.from(off.getContext('2d').getImageData(0, 0, bmp.width, bmp.height).data);
  }, jobA);
  let max = 0, off = 0;
  for (let i = 0; i < png.length; i += 4)
    for (let c = 0; c < 3; ++c) {
      const d = Math.abs(png[i + c] - painted.rgba[i + c]);
      max = Math.max(max, d);
      off += d > 0;
    }
  assert.ok(max <= 1 && off < png.length / 400, `the JS curve differs from image.png: max ${max}, ${off} values`);
  await setExposure(0);
  await page.waitForSelector('#v-tools[data-painted="stream"]');
});

test('the readout shows the float value and sample count under the cursor', async () => {
  const px = await floatPixels(jobA);
  const box = await page.locator('#v-canvas').boundingBox();
  for (const [fx, fy] of [[0.5, 0.6], [0.2, 0.3]]) {
    await page.mouse.move(box.x + box.width * fx, box.y + box.height * fy);
    const want = [Math.floor(fx * px.w), Math.floor(fy * px.h)];
    await page.waitForFunction((xy) => {
      const d = document.querySelector('#v-readout').dataset;
      return d.n !== undefined && Math.abs(Number(d.x) - xy[0]) <= 1 && Math.abs(Number(d.y) - xy[1]) <= 1;
    }, want);
    const d = await page.$eval('#v-readout', (el) => ({ ...el.dataset, text: el.textContent }));
    const [r, g, b, n] = px.at(Number(d.x), Number(d.y));
    assert.deepEqual([Number(d.r), Number(d.g), Number(d.b), Number(d.n)], [r, g, b, n]);
    assert.match(d.text, new RegExp(`${n} samples`));
  }
});

test('the sample-rate view paints the course colours of each pixel\'s count, with a legend', async () => {
  const px = await floatPixels(jobA);
  await page.check('#v-rate');
  await page.waitForSelector('#v-tools[data-painted="course:0:true"]');
  assert.equal(await page.isVisible('#v-legend'), true);
  let lo = Infinity, hi = 0;
  for (let y = 0; y < px.h; ++y) for (let x = 0; x < px.w; ++x) { const n = px.at(x, y)[3]; lo = Math.min(lo, n); hi = Math.max(hi, n); }
  assert.match(await page.textContent('#v-legend-range'), new RegExp(`${lo} to ${hi}`));
  assert.match(await page.textContent('#v-legend-max'), /16 spp/);
  // The course's rate_colour (renderer/film.cpp) through its PNG curve, as _rate.png has it.
  const curve = (v) => (v > 0 ? Math.floor(Math.min(1, Math.pow(1.41421356 * v, 1 / 2.2)) * 255) : 0);
  const { rgba } = await canvasPixels('#v-canvas');
  let worst = 0;
  for (let y = 0; y < px.h; ++y)
    for (let x = 0; x < px.w; ++x) {
      const r = px.at(x, y)[3] / 16;
      const c = (r <= 0.5 ? [0, 2 * r, 1 - 2 * r] : [2 * r - 1, 2 - 2 * r, 0]).map(curve);
      for (let k = 0; k < 3; ++k) worst = Math.max(worst, Math.abs(c[k] - rgba[4 * (y * px.w + x) + k]));
    }
  assert.ok(worst <= 1, `a rate colour is ${worst} levels off`);
  await page.screenshot({ path: path.join(artifacts, 'web-viewer-rate.png') });
  await page.uncheck('#v-rate');
  await page.waitForSelector('#v-tools[data-painted="stream"]');
  assert.equal(await page.isVisible('#v-legend'), false);
});

test('1:1 shows an image pixel a device pixel, and dragging pans it', async () => {
  const fit = await page.locator('#v-canvas').boundingBox();
  assert.ok(fit.width > 300, `fit is ${fit.width} px wide`);  // a 96 px image is scaled up to the column
  await page.click('#v-zoom-1');
  await page.waitForSelector('#v-wrap[data-zoom="1:1"]');
  const dpr = await page.evaluate(() => window.devicePixelRatio);
  const one = await page.locator('#v-canvas').boundingBox();
  assert.ok(Math.abs(one.width * dpr - 96) < 0.5 && Math.abs(one.height * dpr - 72) < 0.5, `1:1 box ${one.width}x${one.height}`);
  // What the screen shows there is the canvas's pixels, one for one.
  const shot = await page.screenshot({ clip: { x: one.x, y: one.y, width: one.width, height: one.height } });
  const { rgba } = await canvasPixels('#v-canvas');
  const seen = await page.evaluate(async (b64) => {
    const bytes = Uint8Array.from(atob(b64), (ch) => ch.charCodeAt(0));
    const bmp = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
    const off = new OffscreenCanvas(bmp.width, bmp.height);
    off.getContext('2d').drawImage(bmp, 0, 0);
    return { w: bmp.width, h: bmp.height, rgba: Array.from(off.getContext('2d').getImageData(0, 0, bmp.width, bmp.height).data) };
  }, shot.toString('base64'));
  assert.deepEqual([seen.w, seen.h], [96, 72]);
  assert.ok(meanAbsDiff(seen.rgba, rgba) < 1.5, `screen vs canvas: mean difference ${meanAbsDiff(seen.rgba, rgba)}`);
  // Drag from the picture's middle: it follows the pointer; the drag sets no focus.
  const note = await page.textContent('#v-note');
  await page.mouse.move(one.x + 48, one.y + 36);
  await page.mouse.down();
  await page.mouse.move(one.x + 68, one.y + 51, { steps: 4 });
  await page.mouse.up();
  await page.waitForFunction((x0) => document.querySelector('#v-canvas').getBoundingClientRect().x !== x0, one.x);
  const moved = await page.locator('#v-canvas').boundingBox();
  assert.ok(Math.abs(moved.x - one.x - 20) <= 1 && Math.abs(moved.y - one.y - 15) <= 1, `panned by ${moved.x - one.x}, ${moved.y - one.y}`);
  assert.equal(await page.textContent('#v-note'), note);
  await page.screenshot({ path: path.join(artifacts, 'web-viewer-zoom.png') });
  await page.click('#v-zoom-fit');
  await page.waitForSelector('#v-wrap[data-zoom="fit"]');
  const back = await page.locator('#v-canvas').boundingBox();
  assert.ok(Math.abs(back.width - fit.width) < 1, `fit again: ${back.width} px`);
});

test('the wheel zooms around the cursor from fit to 32x, texels drawn as squares past 1:1', async () => {
  await page.click('#v-mouse-zoom');  // the wheel zooms (with "Move camera" it dollies)
  await page.waitForSelector('#v-wrap[data-mouse="zoom"]');
  assert.match(await page.textContent('#v-mouse-hint'), /Wheel to zoom/);
  await page.locator('#v-wrap').scrollIntoViewIfNeeded();
  const fit = await page.locator('#v-canvas').boundingBox();
  const cursor = { x: fit.x + fit.width * 0.3, y: fit.y + fit.height * 0.4 };
  const under = { u: 0.3 * 96, v: 0.4 * 72 };  // the image point under the cursor
  await page.mouse.move(cursor.x, cursor.y);
  let scale = Number(await page.getAttribute('#v-wrap', 'data-scale'));
  for (let i = 0; i < 30 && scale < 32; ++i) {
    await page.mouse.wheel(0, -100);
    await page.waitForFunction((s) => Number(document.querySelector('#v-wrap').dataset.scale) > s, scale);
    scale = Number(await page.getAttribute('#v-wrap', 'data-scale'));
  }
  const dpr = await page.evaluate(() => window.devicePixelRatio);
  assert.equal(scale, 32);
  await page.mouse.wheel(0, -100);  // no further than 32x
  await page.waitForTimeout(200);
  assert.equal(Number(await page.getAttribute('#v-wrap', 'data-scale')), 32);
  const box = await page.locator('#v-canvas').boundingBox();
  assert.ok(Math.abs(box.width * dpr - 96 * 32) < 1, `the picture is ${box.width} px wide at 32x`);
  // The point under the cursor stayed under it.
  const u = ((cursor.x - box.x) / box.width) * 96, v = ((cursor.y - box.y) / box.height) * 72;
  assert.ok(Math.abs(u - under.u) < 0.2 && Math.abs(v - under.v) < 0.2, `(${u}, ${v}) under the cursor, not (${under.u}, ${under.v})`);
  assert.equal(await page.$eval('#v-canvas', (c) => getComputedStyle(c).imageRendering), 'pixelated');
  // Nearest texels: every 32x32 block on screen is one flat colour, the canvas pixel's.
  const tx = Math.floor(under.u) - 1, ty = Math.floor(under.v) - 1, n = 3, side = 32 / dpr;
  const clip = { x: box.x + tx * side, y: box.y + ty * side, width: n * side, height: n * side };
  const shot = await page.screenshot({ clip });
  const seen = await page.evaluate(async (b64) => {
    const bytes = Uint8Array.from(atob(b64), (ch) => ch.charCodeAt(0));
    const bmp = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
    const off = new OffscreenCanvas(bmp.width, bmp.height);
    off.getContext('2d').drawImage(bmp, 0, 0);
    return { w: bmp.width, rgba: Array.from(off.getContext('2d').getImageData(0, 0, bmp.width, bmp.height).data) };
  }, shot.toString('base64'));
  const { rgba } = await canvasPixels('#v-canvas');
  let spread = 0, off = 0, edges = 0;
  for (let by = 0; by < n; ++by)
    for (let bx = 0; bx < n; ++bx) {
      const at = (x, y) => 4 * (y * seen.w + x);
      const c = at(bx * 32 + 16, by * 32 + 16), t = 4 * ((ty + by) * 96 + tx + bx);
      for (let k = 0; k < 3; ++k) off = Math.max(off, Math.abs(seen.rgba[c + k] - rgba[t + k]));
      for (let y = by * 32 + 1; y < by * 32 + 31; ++y)
        for (let x = bx * 32 + 1; x < bx * 32 + 31; ++x)
          for (let k = 0; k < 3; ++k) spread = Math.max(spread, Math.abs(seen.rgba[at(x, y) + k] - seen.rgba[c + k]));
      if (bx > 0) for (let k = 0; k < 3; ++k) edges += Math.abs(seen.rgba[at(bx * 32, by * 32 + 16) + k] - seen.rgba[at(bx * 32 - 1, by * 32 + 16) + k]);
    }
  assert.ok(spread <= 2, `a texel's block varies by ${spread} levels: smoothed, not nearest`);
  assert.ok(off <= 3, `a block is ${off} levels off its canvas pixel`);
  assert.ok(edges > 0, 'the blocks around the cursor are all one colour: nothing was checked');
  await page.screenshot({ path: path.join(artifacts, 'web-viewer-zoom32.png') });
  // Zooming out stops at fit.
  for (let i = 0; i < 30 && (await page.getAttribute('#v-wrap', 'data-zoom')) !== 'fit'; ++i) {
    await page.mouse.wheel(0, 100);
    await page.waitForTimeout(50);
  }
  await page.waitForSelector('#v-wrap[data-zoom="fit"]');
  const back = await page.locator('#v-canvas').boundingBox();
  assert.ok(Math.abs(back.width - fit.width) < 1, `fit again: ${back.width} px`);
});

test('two jobs compare side by side and by wipe, with their differing settings listed', async () => {
  jobB = await showJob({ scene: 'cornell', width: 96, height: 72, spp: 16, max_depth: 1, aperture: 0.05 });
  await page.check(`#job-rows tr[data-id="${jobA}"] input[data-action="compare"]`);
  await page.check(`#job-rows tr[data-id="${jobB}"] input[data-action="compare"]`);
  await page.waitForSelector('#compare:not([hidden])');
  await page.waitForSelector('#compare-diff tr[data-field="max_depth"]');
  const fields = await page.$$eval('#compare-diff tbody tr', (rows) => rows.map((r) => r.dataset.field));
  assert.deepEqual(fields.sort(), ['aperture', 'max_depth']);
  assert.deepEqual(await page.$$eval('#compare-diff tr[data-field="max_depth"] td', (t) => t.map((x) => x.textContent)),
    ['max depth', '5', '1']);
  // Both canvases hold their job's picture once it has arrived.
  await page.waitForFunction(() => ['#compare-a', '#compare-b'].every((s) => document.querySelector(s).width === 96));
  await page.check('input[name="compare-mode"][value="wipe"]');
  for (const [p, shows, other] of [[100, '#compare-a', '#compare-b'], [0, '#compare-b', '#compare-a']]) {  // A left of the divider
    await setRange('#compare-wipe', p);
    await page.waitForSelector(`#compare-stage[data-wipe="${p}"]`);
    const wipe = await canvasPixels('#compare-wipe-canvas');
    const want = await canvasPixels(shows), not = await canvasPixels(other);
    assert.ok(meanAbsDiff(wipe.rgba, want.rgba) < 0.5, `wipe at ${p}% is not ${shows}`);
    assert.ok(meanAbsDiff(wipe.rgba, not.rgba) > 3, `the two jobs look alike (${meanAbsDiff(wipe.rgba, not.rgba)})`);
  }
  await setRange('#compare-wipe', 50);
  await page.waitForSelector('#compare-stage[data-wipe="50"]');
  await page.locator('#compare').screenshot({ path: path.join(artifacts, 'web-viewer-compare.png') });
});

// The share of a canvas's pixels that are not `rgb` (to 2 levels).
async function shareNot(selector, rgb) {
  const { rgba } = await canvasPixels(selector);
  let n = 0;
  for (let i = 0; i < rgba.length; i += 4) n += [0, 1, 2].some((k) => Math.abs(rgba[i + k] - rgb[k]) > 2);
  return n / (rgba.length / 4);
}

test('the difference view shows the error in false colour: none for identical jobs, plenty for different ones', async () => {
  const zero = [68, 1, 84];  // the false colour of no error (viridis at 0)
  await page.check('input[name="compare-mode"][value="diff"]');
  await page.waitForSelector('#compare-metric-box:not([hidden])');
  await page.waitForSelector('#compare-stage[data-diff="abs"]');
  assert.ok(await page.isVisible('#compare-diff-canvas'));
  assert.ok(await page.isVisible('#compare-diff-ramp'));
  assert.deepEqual(await page.$eval('#compare-diff-canvas', (c) => [c.width, c.height]), [96, 72]);
  const absShare = await shareNot('#compare-diff-canvas', zero);
  assert.ok(absShare > 0.3, `only ${absShare} of the pixels show an error between depth 5 and depth 1`);
  assert.match(await page.textContent('#compare-diff-stats'), /^absolute error: mean \d/);
  const absPixels = (await canvasPixels('#compare-diff-canvas')).rgba;
  await page.selectOption('#compare-metric', 'rel');
  await page.waitForSelector('#compare-stage[data-diff="rel"]');
  assert.match(await page.textContent('#compare-diff-stats'), /^relative error/);
  assert.ok(meanAbsDiff(absPixels, (await canvasPixels('#compare-diff-canvas')).rgba) > 1, 'relative error looks like absolute');
  await page.locator('#compare').screenshot({ path: path.join(artifacts, 'web-viewer-diff.png') });
  await page.selectOption('#compare-metric', 'abs');
  // The same settings again: the same pixels (deterministic sampling), no error anywhere.
  const jobC = await showJob({ scene: 'cornell', width: 96, height: 72, spp: 16, max_depth: 5 });
  await page.uncheck(`#job-rows tr[data-id="${jobB}"] input[data-action="compare"]`);
  await page.check(`#job-rows tr[data-id="${jobC}"] input[data-action="compare"]`);
  await page.waitForFunction((id) => document.querySelector('#compare-b-label').textContent.endsWith(id), jobC.slice(-8));
  assert.match(await page.textContent('#compare-a-label'), new RegExp(`${jobA.slice(-8)}$`));
  await page.waitForSelector('#compare-stage[data-diff="abs"]');
  await page.waitForFunction(() => /largest 0$/.test(document.querySelector('#compare-diff-stats').textContent));
  assert.equal(await shareNot('#compare-diff-canvas', zero), 0);
  // Back to A and B, side by side, for the tests after.
  await page.uncheck(`#job-rows tr[data-id="${jobC}"] input[data-action="compare"]`);
  await page.check(`#job-rows tr[data-id="${jobB}"] input[data-action="compare"]`);
  await page.check('input[name="compare-mode"][value="side"]');
});

test('a finished job without float pixels says so once, and is not asked again', async () => {
  let asked = 0;
  await page.route('**/api/jobs/*/pixels', (route) => {
    asked += 1;
    return route.fulfill({ status: 404, contentType: 'application/json',
      body: JSON.stringify({ error: { status: 404, message: "the job's sample counts are missing" } }) });
  });
  await page.click(`#job-rows tr[data-id="${jobA}"] [data-action="open"]`);
  await page.waitForSelector('#v-tools[data-data="missing"]');
  await page.locator('#v-canvas').scrollIntoViewIfNeeded();
  const box = await page.locator('#v-canvas').boundingBox();
  for (const f of [0.3, 0.5, 0.7]) await page.mouse.move(box.x + box.width * f, box.y + box.height * f);
  await page.waitForFunction(() => /sample counts are missing/.test(document.querySelector('#v-readout').textContent));
  assert.equal(asked, 1);
  await page.unroute('**/api/jobs/*/pixels');
});

test('a narrow window needs no sideways scrolling with the tools and the comparison open', async () => {
  await page.setViewportSize({ width: 390, height: 844 });
  await page.waitForFunction(() => window.innerWidth === 390);
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));  // laid out
  await assertFitsWidth(page, assert);
  await page.screenshot({ path: path.join(artifacts, 'web-viewer-narrow.png'), fullPage: true });
  await page.setViewportSize({ width: 1280, height: 900 });
  await page.click('#compare-close');
  await page.waitForSelector('#compare[hidden]', { state: 'attached' });
  assert.equal(await page.isChecked(`#job-rows tr[data-id="${jobA}"] input[data-action="compare"]`), false);
});

test('no uncaught errors on the page', () => {
  assert.deepEqual(pageErrors, []);
});
