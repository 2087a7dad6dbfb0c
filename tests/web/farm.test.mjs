// The render farm's panel (web/farm.js) in a real browser against a real render-server
// (harness.mjs). The server here is embedded (no Redis), so Playwright answers /api/health with the
// server's real answer plus a `farm` object, as a server with --queue redis://... gives it: the
// panel shows the workers, the rejected count and the latest rejections; names from Redis show as
// text, never markup; an insecure or unsigned farm shows a warning; without `farm` the panel is
// hidden; a hidden tab stops polling. Same environment and skip rules as every page test.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { WAIT, artifacts, startServer, stopServer, makeDataDir, launchBrowser, apiClient, waitReady, assertFitsWidth } from './harness.mjs';

const FARM = {
  queue: 'redis://render-server@192.0.2.1:6379/0',
  authenticated: true,
  signed: true,
  insecure: false,
  workers: [
    { name: 'hostA-1234', threads: 16, live: true, last_heard_seconds: 0.4, passes: 12, rejected: 0 },
    { name: 'hostB-77', threads: 8, live: false, last_heard_seconds: 95, passes: 28, rejected: 1 },
  ],
  passes_merged: 40,
  rejected: 3,
  rejections: [
    { worker: 'mallory', job: '1a2b3c4d5e6f7a8b', reason: 'bad signature', seconds_ago: 12.5 },
    { worker: 'hostB-77', job: '99aa88bb77cc66dd', reason: 'image size differs from the job', seconds_ago: 300 },
  ],
};

// Markup a worker could put in Redis: it must arrive as text, and its handler must never run.
const HOSTILE = '<img src=x onerror="window.__farmXss=1"><b>bold</b>';

let dataDir, server, baseUrl, browser, page, api;
let farm = FARM;      // what the routed /api/health carries as `farm`; null: no such key
let healthHits = 0;   // /api/health requests the page sent
const pageErrors = [];

before(async () => {
  dataDir = makeDataDir('web-farm-test');
  ({ proc: server, url: baseUrl } = await startServer(dataDir));
  api = apiClient(baseUrl);
  fs.mkdirSync(artifacts, { recursive: true });
  browser = await launchBrowser();
  page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  page.setDefaultTimeout(WAIT);
  page.on('pageerror', (e) => pageErrors.push(e.message));
  // The real health answer, with `farm` set to what the test says now.
  await page.route('**/api/health', async (route) => {
    healthHits += 1;
    const response = await route.fetch();
    const json = await response.json();
    if (farm) json.farm = farm;
    else delete json.farm;
    await route.fulfill({ response, json });
  });
  await page.goto(baseUrl);
  await waitReady(page);
});

after(async () => {
  if (browser) await browser.close();
  if (server) await stopServer(server);
  if (dataDir) fs.rmSync(dataDir, { recursive: true, force: true });
});

const texts = (sel) => page.$$eval(sel, (els) => els.map((e) => e.textContent));

// Sets the farm the server reports and waits for the panel to show `expect` (a function of the page).
async function report(f, expect, arg) {
  farm = f;
  await page.waitForFunction(expect, arg);
}

test('the embedded server itself reports no farm', async () => {
  const health = await api.json('/api/health');
  assert.equal(health.status, 'ok');
  assert.equal(health.farm, undefined);
});

test('the Farm panel shows the queue, the security line, the workers and the latest rejections', async () => {
  await page.waitForSelector('#farm:not([hidden])');
  await page.waitForFunction(() => document.querySelectorAll('#farm-workers tbody tr').length === 2);
  assert.equal(await page.textContent('#farm-queue'), FARM.queue);
  assert.equal(await page.getAttribute('#farm-security', 'data-level'), 'ok');
  assert.match(await page.textContent('#farm-security'), /signed/);
  assert.deepEqual(await texts('#farm-workers tbody .farm-name'), ['hostA-1234', 'hostB-77']);
  assert.deepEqual(await texts('#farm-workers tbody tr:first-child td'), ['hostA-1234', '16', 'live', '12', '0']);
  assert.deepEqual(await texts('#farm-workers tbody tr:nth-child(2) td'), ['hostB-77', '8', '1 min 35 s ago', '28', '1']);
  assert.equal(await page.textContent('#farm-live'), '1 of 2');
  assert.equal(await page.textContent('#farm-merged'), '40');
  assert.equal(await page.textContent('#farm-rejected'), '3');
  const first = await texts('#farm-rejections tbody tr:first-child td');
  assert.deepEqual(first, ['13 s ago', 'mallory', '5e6f7a8b', 'bad signature']);
  assert.equal(await page.getAttribute('#farm-rejections tbody tr:first-child td:nth-child(3)', 'title'), '1a2b3c4d5e6f7a8b');
  assert.equal((await texts('#farm-rejections tbody tr')).length, 2);
  assert.ok(await page.isHidden('#farm-no-workers') && await page.isHidden('#farm-no-rejections'));
  assert.equal(await page.textContent('#farm-badge'), 'Farm · 1 live');
  assert.equal(await page.getAttribute('#farm-badge', 'data-level'), 'ok');
  await page.locator('#farm').screenshot({ path: path.join(artifacts, 'web-farm.png') });
});

test('names, jobs and reasons from Redis show as text: no element is made from them', async () => {
  const long = `w${'x'.repeat(300)}`;
  await report({
    ...FARM,
    queue: `redis://${HOSTILE}@h/0`,
    workers: [{ ...FARM.workers[0], name: HOSTILE }, { ...FARM.workers[1], name: long }],
    rejections: [{ worker: HOSTILE, job: HOSTILE, reason: HOSTILE, seconds_ago: 1 }],
  }, (s) => document.querySelector('#farm-workers .farm-name')?.textContent === s, HOSTILE);
  assert.deepEqual(await texts('#farm-workers tbody .farm-name'), [HOSTILE, long]);
  assert.deepEqual((await texts('#farm-rejections tbody tr:first-child td')).filter((t, i) => i !== 0 && i !== 2), [HOSTILE, HOSTILE]);
  assert.equal(await page.getAttribute('#farm-rejections tbody tr:first-child td:nth-child(3)', 'title'), HOSTILE);
  assert.equal(await page.textContent('#farm-queue'), `redis://${HOSTILE}@h/0`);
  await page.waitForTimeout(300);  // time for an onerror to fire, were an <img> made
  assert.equal(await page.evaluate(() => document.querySelectorAll('img, b').length), 0);
  assert.equal(await page.evaluate(() => window.__farmXss), undefined);
  // A long name wraps: no sideways scrolling in a narrow window.
  await page.setViewportSize({ width: 390, height: 844 });
  await page.waitForTimeout(200);
  await assertFitsWidth(page, assert);
  await page.screenshot({ path: path.join(artifacts, 'web-farm-narrow.png'), fullPage: true });
  await page.setViewportSize({ width: 1280, height: 900 });
});

test('an insecure farm, and an unsigned one, show a warning; a signed one does not', async () => {
  await report({ ...FARM, signed: false, insecure: true },
    () => document.querySelector('#farm-security').dataset.level === 'bad');
  const line = await page.textContent('#farm-security');
  assert.match(line, /insecure/i);
  assert.match(line, /not signed/i);
  assert.ok(await page.isVisible('#farm-security'));
  // The danger colour (--bad), not the quiet one.
  assert.equal(await page.$eval('#farm-security', (el) => getComputedStyle(el).color), 'rgb(239, 107, 107)');
  assert.equal(await page.getAttribute('#farm-badge', 'data-level'), 'bad');
  assert.match(await page.textContent('#farm-badge'), /insecure/);
  await page.locator('#farm').screenshot({ path: path.join(artifacts, 'web-farm-insecure.png') });
  // The warning's longer badge still fits a narrow window's top bar.
  await page.setViewportSize({ width: 360, height: 800 });
  await page.waitForTimeout(200);
  await assertFitsWidth(page, assert);
  await page.setViewportSize({ width: 1280, height: 900 });

  await report({ ...FARM, signed: false, insecure: false },
    () => document.querySelector('#farm-security').dataset.level === 'warn');
  assert.match(await page.textContent('#farm-security'), /not signed/i);
  assert.equal(await page.$eval('#farm-security', (el) => getComputedStyle(el).color), 'rgb(232, 193, 90)');
  assert.match(await page.textContent('#farm-badge'), /unsigned/);

  await report({ ...FARM, authenticated: false },
    () => document.querySelector('#farm-security').dataset.level === 'ok');
  assert.match(await page.textContent('#farm-security'), /does not log in/);
  assert.equal(await page.textContent('#farm-badge'), 'Farm · 1 live');
});

test('no workers and no rejections yet: the panel says so', async () => {
  await report({ ...FARM, workers: [], rejections: [], rejected: 0, passes_merged: 0 },
    () => !document.querySelector('#farm-no-workers').hidden);
  assert.ok(await page.isHidden('#farm-workers') && await page.isHidden('#farm-rejections'));
  assert.ok(await page.isVisible('#farm-no-rejections'));
  assert.equal(await page.textContent('#farm-live'), '0 of 0');
});

test('a hidden tab stops polling /api/health; showing it polls at once', async () => {
  farm = FARM;
  await page.evaluate(() => {
    Object.defineProperty(document, 'hidden', { configurable: true, get: () => true });
    Object.defineProperty(document, 'visibilityState', { configurable: true, get: () => 'hidden' });
    document.dispatchEvent(new Event('visibilitychange'));
  });
  await page.waitForTimeout(1000);  // a request in flight when it hid may still land
  const hits = healthHits;
  await page.waitForTimeout(7000);  // more than two poll periods
  assert.equal(healthHits, hits, 'the page polled /api/health while hidden');
  await page.evaluate(() => {
    delete document.hidden;  // the own properties go; the prototype's getters are back
    delete document.visibilityState;
    document.dispatchEvent(new Event('visibilitychange'));
  });
  await page.waitForTimeout(1000);
  assert.ok(healthHits > hits, 'showing the tab did not poll at once');
  await page.waitForFunction(() => document.querySelectorAll('#farm-workers tbody tr').length === 2);
});

test('without a farm in /api/health the panel and the badge are hidden, live and after a reload', async () => {
  await report(null, () => document.querySelector('#farm').hidden);
  assert.ok(await page.isHidden('#farm-badge'));
  const hits = healthHits;
  await page.reload();
  await waitReady(page);
  // The denoiser check and the first farm poll, both after the scenes loaded.
  for (const end = Date.now() + WAIT; healthHits < hits + 2 && Date.now() < end;) await page.waitForTimeout(200);
  assert.ok(healthHits >= hits + 2, 'the reloaded page did not ask /api/health');
  await page.waitForTimeout(300);
  assert.ok(await page.isHidden('#farm'));
  assert.ok(await page.isHidden('#farm-badge'));
});

test('no uncaught errors on the page', () => {
  assert.deepEqual(pageErrors, []);
});
