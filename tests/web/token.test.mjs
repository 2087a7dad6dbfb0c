// The web page against a render-server started with --token, in a real browser (Debian's Chromium
// driven by playwright-core): the token given in the address's fragment (#token=...) is taken out
// of the address bar and sent on every API call, in the event stream's query (EventSource cannot
// send headers) and in the image links; without it the page asks for it once and then works.
// Same environment and skip rules (exit 77; under CI=true, 1) as every page test (harness.mjs).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import { WAIT, launchBrowser, makeDataDir, startServer, stopServer, waitReady } from './harness.mjs';

const TOKEN = 'web-t0ken&with=odd#chars';

let dataDir, server, baseUrl, browser;

before(async () => {
  dataDir = makeDataDir('web-token-test');
  ({ proc: server, url: baseUrl } = await startServer(dataDir, 0, ['--token', TOKEN]));
  browser = await launchBrowser();
});

after(async () => {
  if (browser) await browser.close();
  if (server) await stopServer(server);
  if (dataDir) fs.rmSync(dataDir, { recursive: true, force: true });
});

// A fresh tab (its own sessionStorage); every request it sends is recorded.
async function newPage() {
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  page.setDefaultTimeout(WAIT);
  page.errors = [];
  page.sent = [];
  page.on('pageerror', (e) => page.errors.push(e.message));
  page.on('request', (r) => page.sent.push({ url: r.url(), auth: r.headers().authorization }));
  return page;
}

async function renderOne(page) {
  await waitReady(page);
  for (const [k, v] of Object.entries({ width: 320, height: 240, spp: 64 })) await page.fill(`#f-${k}`, String(v));
  const before = await page.evaluate(() => (location.hash.match(/job=([0-9a-f]+)/) || [])[1]);
  await page.click('#submit');
  await page.waitForFunction((prev) => {
    const m = location.hash.match(/job=([0-9a-f]+)/);
    return m && m[1] !== prev;
  }, before);
  await page.waitForSelector('#viewer[data-ended="true"][data-state="done"]');
  assert.ok(Number(await page.getAttribute('#viewer', 'data-tiles')) > 0 ||
            await page.isHidden('#v-placeholder'), 'no pixels arrived');
}

test('a token in the fragment is used everywhere and leaves the address bar', async () => {
  const page = await newPage();
  await page.goto(`${baseUrl}#token=${encodeURIComponent(TOKEN)}`);
  await renderOne(page);
  assert.ok(!page.url().includes('token'), `the token stayed in the address: ${page.url()}`);
  const api = page.sent.filter((r) => new URL(r.url).pathname.startsWith('/api/') && !r.url.includes('/events'));
  assert.ok(api.length > 3);
  for (const r of api) assert.equal(r.auth, `Bearer ${TOKEN}`, r.url);
  const events = page.sent.filter((r) => r.url.includes('/events'));
  assert.ok(events.length > 0, 'no event stream was opened');
  for (const r of events) assert.equal(new URL(r.url).searchParams.get('token'), TOKEN);
  // The download links carry it in the query and work as plain links.
  const href = await page.getAttribute('#v-png', 'href');
  assert.equal(new URL(href, baseUrl).searchParams.get('token'), TOKEN);
  const png = await fetch(new URL(href, baseUrl));
  assert.equal(png.status, 200);
  assert.equal(png.headers.get('content-type'), 'image/png');
  assert.deepEqual(page.errors, []);
  await page.close();
});

test('without a token the page asks once, then works', async () => {
  const page = await newPage();
  const prompts = [];
  page.on('dialog', async (d) => {
    prompts.push(d.message());
    await d.accept(TOKEN);
  });
  await page.goto(baseUrl);
  await renderOne(page);
  assert.equal(prompts.length, 1, prompts.join(' | '));
  assert.match(prompts[0], /token/i);
  assert.deepEqual(page.errors, []);
  await page.close();
});
