// The README's picture of the page (docs/img/page.png): a render-server with the bundled scenes,
// the page at 1280x800 in Debian's Chromium, cornell rendered at the page's defaults with the
// camera turned a little on the image, then a screenshot. Needs the build and tests/web's packages
// (bash scripts/test.sh installs both). Usage: node scripts/readme-screenshot.mjs [OUT.png]
import path from 'node:path';
import fs from 'node:fs';
import { sourceDir, startServer, stopServer, makeDataDir, launchBrowser, waitReady, pageSteps } from '../tests/web/harness.mjs';

const out = path.resolve(process.argv[2] || path.join(sourceDir, 'docs', 'img', 'page.png'));
const dataDir = makeDataDir('readme-shot');
const { proc, url } = await startServer(dataDir);
const browser = await launchBrowser();
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  page.setDefaultTimeout(300_000);
  await page.goto(url);
  await waitReady(page);
  const { submit, waitViewerEnded } = pageSteps(page);
  await submit({ scene: 'cornell', spp: 64, width: 480, height: 360 });
  await waitViewerEnded('done');
  // An orbit of a tenth of the image width: a preview, then the full render of the moved view.
  const box = await page.locator('#v-canvas').boundingBox();
  const y = box.y + box.height / 2;
  await page.mouse.move(box.x + box.width / 2, y);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width * 0.6, y, { steps: 8 });
  await page.mouse.up();
  await page.waitForFunction(() => document.querySelector('#v-title').textContent.includes('480×360'));
  await waitViewerEnded('done');
  await page.screenshot({ path: out });
  console.log(`wrote ${out}`);
} finally {
  await browser.close();
  await stopServer(proc);
  fs.rmSync(dataDir, { recursive: true, force: true });
}
