// Compare two jobs: picked in the job list or a sweep's cells, shown side by side, with a wipe
// (A left of the divider, B right of it) or as their difference in false colour (tev's absolute
// and relative error, from the float pixels), live while they render, and the settings that differ.
// A denoised job shows its denoised picture or its raw render (a pick per side), so that a job's
// raw render can be set against its own denoised picture.
'use strict';

const compare = {
  ids: [],       // [A, B]: the first picked is A; a third pick drops the oldest
  pictures: ['denoised', 'denoised'],  // what each side shows of a denoised job: 'denoised' or 'raw'
  sides: [],     // {id, feed, view}
  mode: 'side',  // or 'wipe', 'diff'
  metric: 'abs', // the difference: 'abs' |A - B| or 'rel' |A - B| / (B + 0.01)
  frame: 0,
};

// Viridis at nine stops: dark purple for no error, yellow for the most shown.
const FALSE_COLOUR = [[68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141],
  [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37]];

function falseColour(t) {
  const x = Math.max(0, Math.min(1, t)) * (FALSE_COLOUR.length - 1);
  const i = Math.min(FALSE_COLOUR.length - 2, Math.floor(x)), f = x - i;
  return [0, 1, 2].map((c) => Math.round(FALSE_COLOUR[i][c] + f * (FALSE_COLOUR[i + 1][c] - FALSE_COLOUR[i][c])));
}

// Spec fields in the order the difference list shows them; others follow by name.
const COMPARE_ORDER = ['scene', 'picture', 'size', 'spp', 'max_depth', 'aperture', 'focal_distance', 'light_samples',
  'camera', 'keep_fov', 'frame_scene', 'adaptive', 'adaptive_tolerance', 'target_error', 'time_limit', 'seed', 'caustic_tracing',
  'denoise'];

function isCompared(id) { return compare.ids.includes(id); }

// Picks (or drops) a job for the comparison; two picked open the panel.
function toggleCompare(id, on) {
  compare.ids = compare.ids.filter((x) => x !== id);
  if (on) compare.ids.push(id);
  if (compare.ids.length > 2) compare.ids = compare.ids.slice(-2);
  compare.pictures = ['denoised', 'denoised'];
  syncComparePicks();
  if (compare.ids.length === 2) showCompare();
  else hideCompare(false);
}

// A denoised job against itself: its denoised picture as A, its raw render as B.
function compareRawDenoised(id) {
  compare.ids = [id, id];
  compare.pictures = ['denoised', 'raw'];
  syncComparePicks();
  showCompare();
}

// Every "compare" checkbox (job rows, sweep cells) shows whether its job is picked, and which side.
function syncComparePicks() {
  document.querySelectorAll('input[data-action="compare"]').forEach((box) => {
    const id = box.closest('[data-id]').dataset.id;
    const k = compare.ids.indexOf(id);
    box.checked = k >= 0;
    box.parentElement.dataset.side = k === 0 ? 'A' : k === 1 ? 'B' : '';
  });
  $('#compare-hint').textContent = compare.ids.length === 1
    ? `Job ${shortId(compare.ids[0])} is A: pick another job to compare with it.` : '';
}

function showCompare() {
  hideCompare(false);
  const [a, b] = compare.ids;
  compare.sides = [a, b].map((id, k) => {
    const side = { id, name: k === 0 ? 'A' : 'B', canvas: $(k === 0 ? '#compare-a' : '#compare-b'), feed: feedFor(id),
      picture: compare.pictures[k] };
    side.view = {
      onFeed(type, feed, rect) {
        if (type === 'size') clearCanvas(side.canvas, feed.canvas.width, feed.canvas.height);
        else if (type === 'pixels') syncCanvas(side.canvas, feed, rect, side.picture);
        else if (type === 'status') { listDifferences(); showSidePictures(); }
        if (type === 'pixels' || type === 'end') side.stale = true;
        compare.schedule();
      },
    };
    side.feed.attach(side.view);
    return side;
  });
  showSidePictures();
  $('#compare').hidden = false;
  listDifferences();
  compare.schedule();
  $('#compare').scrollIntoView({ behavior: 'smooth', block: 'nearest' });
}

// Each side's label, and its picture pick where its job is denoised.
function showSidePictures() {
  compare.sides.forEach((side, k) => {
    const dn = side.feed.status && side.feed.status.denoise;
    const pick = k === 0 ? '#compare-a-picture' : '#compare-b-picture';
    $(`${pick}-box`).hidden = !dn;
    $(pick).value = side.picture;
    const picture = dn ? ` · ${side.picture}` : '';
    $(k === 0 ? '#compare-a-label' : '#compare-b-label').textContent = `${side.name} · job ${shortId(side.id)}${picture}`;
    $(k === 0 ? '#compare .tag.a' : '#compare .tag.b').textContent = `${side.name}${picture}`;
  });
}

// A side now shows its job's other picture.
function setSidePicture(k, picture) {
  const side = compare.sides[k];
  if (!side) return;
  compare.pictures[k] = side.picture = picture;
  if (side.feed.painted) syncCanvas(side.canvas, side.feed, null, picture);
  side.stale = true;
  showSidePictures();
  listDifferences();
  compare.schedule();
}

// Whether a side shows a denoised picture: its pixels are 8-bit only (no float pixels of it here).
function showsDenoised(side) { return side.picture === 'denoised' && Boolean(side.feed.denoised); }

function hideCompare(clearPicks = true) {
  compare.sides.forEach((s) => { s.feed.detach(s.view); clearTimeout(s.timer); });
  compare.sides = [];
  $('#compare-stage').dataset.diff = '';
  $('#compare').hidden = true;
  if (clearPicks) {
    compare.ids = [];
    syncComparePicks();
  }
}

// One redraw of the wipe a frame, however many tiles arrived.
compare.schedule = function schedule() {
  if (this.frame) return;
  this.frame = requestAnimationFrame(() => {
    this.frame = 0;
    drawWipe();
    drawDiff();
  });
};

// ---------- the difference ----------

// A side's float pixels, fetched while the difference shows: again after new tiles, at most every
// REFETCH_MS (viewer_tools.js), since they are 16 bytes a pixel.
function needPixels(side) {
  if (side.fetching || (side.px && !side.stale)) return;
  const wait = (side.fetchedAt || -Infinity) + REFETCH_MS - performance.now();
  if (wait > 0 && !side.feed.ended) {
    clearTimeout(side.timer);
    side.timer = setTimeout(() => compare.schedule(), wait);
    return;
  }
  side.stale = false;
  side.fetching = (async () => {
    try {
      const res = await fetch(`/api/jobs/${side.id}/pixels`, { cache: 'no-store', headers: authHeaders() });
      side.missing = res.status === 404;
      if (!res.ok) return;
      const w = Number(res.headers.get('X-Image-Width')), h = Number(res.headers.get('X-Image-Height'));
      const buf = await res.arrayBuffer();
      if (buf.byteLength === w * h * 16) side.px = { w, h, data: new Float32Array(buf) };
    } catch (e) {
      // the connection indicator says so; the next tile asks again
    } finally {
      side.fetching = null;
      side.fetchedAt = performance.now();
      compare.schedule();
    }
  })();
}

// A side's linear RGB: its float pixels, else (none kept, or `eightBit`) its 8-bit picture through
// the inverse of the course's PNG curve. {w, h, rgb(i, c)}, or null while loading.
function linearOf(side, eightBit) {
  if (side.px && !eightBit) return { w: side.px.w, h: side.px.h, rgb: (i, c) => side.px.data[4 * i + c], exact: true };
  if (!side.feed.painted || (!eightBit && !side.missing)) return null;
  const c = side.canvas, bytes = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  return { w: c.width, h: c.height, rgb: (i, k) => (bytes[4 * i + k] / 255) ** 2.2 / Math.SQRT2, exact: false };
}

// The error of A against B a pixel, averaged over RGB, in false colour up to its 99th percentile
// (a few fireflies do not wash out the rest); the legend says the scale.
function drawDiff() {
  if (compare.sides.length !== 2 || compare.mode !== 'diff') return;
  // A denoised picture has 8-bit pixels only: then both sides are compared as 8-bit, alike.
  const eightBit = compare.sides.some(showsDenoised);
  if (!eightBit) compare.sides.forEach(needPixels);
  const [a, b] = compare.sides.map((side) => linearOf(side, eightBit));
  const stats = $('#compare-diff-stats'), out = $('#compare-diff-canvas');
  showDiffRamp();
  if (!a || !b) {
    stats.textContent = 'loading the float pixels…';
    return;
  }
  if (a.w !== b.w || a.h !== b.h) {
    stats.textContent = `The pictures differ in size (A ${a.w}×${a.h}, B ${b.w}×${b.h}): no difference to show.`;
    clearCanvas(out, b.w, b.h);
    $('#compare-stage').dataset.diff = 'none';
    return;
  }
  const n = a.w * a.h, rel = compare.metric === 'rel';
  const err = new Float32Array(n);
  let sum = 0;
  for (let i = 0; i < n; ++i) {
    let e = 0;
    for (let c = 0; c < 3; ++c) {
      const d = Math.abs(a.rgb(i, c) - b.rgb(i, c));
      e += rel ? d / (Math.abs(b.rgb(i, c)) + 0.01) : d;
    }
    err[i] = e / 3;
    sum += err[i];
  }
  const sorted = Float32Array.from(err).sort();
  let top = sorted[Math.floor(0.99 * (n - 1))];
  if (!(top > 0)) top = sorted[n - 1];
  const scale = top > 0 ? top : 1;
  if (out.width !== a.w || out.height !== a.h) { out.width = a.w; out.height = a.h; }
  const ctx = out.getContext('2d'), img = ctx.createImageData(a.w, a.h);
  for (let i = 0; i < n; ++i) {
    const rgb = falseColour(err[i] / scale);
    img.data[4 * i] = rgb[0];
    img.data[4 * i + 1] = rgb[1];
    img.data[4 * i + 2] = rgb[2];
    img.data[4 * i + 3] = 255;
  }
  ctx.putImageData(img, 0, 0);
  $('#compare-diff-max').textContent = fmtNum(top > 0 ? top : 0, 3);
  stats.textContent = `${rel ? 'relative' : 'absolute'} error: mean ${fmtNum(sum / n, 3)}, largest ${fmtNum(sorted[n - 1], 3)}` +
    (a.exact && b.exact ? '' : eightBit ? ' (from the 8-bit pictures: a denoised picture has no float pixels here)'
      : ' (from the 8-bit pictures: a job kept no float pixels)');
  $('#compare-stage').dataset.diff = compare.metric;
}

function showDiffRamp() {
  const ramp = $('#compare-diff-ramp');
  if (ramp.dataset.drawn) return;
  const ctx = ramp.getContext('2d'), img = ctx.createImageData(ramp.width, 1);
  for (let x = 0; x < ramp.width; ++x) img.data.set([...falseColour(x / (ramp.width - 1)), 255], 4 * x);
  ctx.putImageData(img, 0, 0);
  ramp.dataset.drawn = 'true';
}

// The wipe: B whole, A over it left of the divider (A drawn at B's size when the sizes differ).
function drawWipe() {
  if (compare.sides.length !== 2 || compare.mode !== 'wipe') return;
  const [a, b] = compare.sides;
  const out = $('#compare-wipe-canvas');
  const w = b.canvas.width, h = b.canvas.height;
  if (out.width !== w || out.height !== h) { out.width = w; out.height = h; }
  const p = Number($('#compare-wipe').value) / 100;
  const ctx = out.getContext('2d');
  ctx.drawImage(b.canvas, 0, 0);
  const x = Math.round(p * w);
  if (x > 0) ctx.drawImage(a.canvas, 0, 0, (x / w) * a.canvas.width, a.canvas.height, 0, 0, x, h);
  $('#compare-divider').style.left = `${p * 100}%`;
  $('#compare-stage').dataset.wipe = String(Math.round(p * 100));
}

function compareValue(spec, status, key) {
  if (key === 'size') return status.width && status.height ? `${status.width}×${status.height}` : undefined;
  if (key === 'camera') return spec.camera || null;  // absent (an older job) is none too
  return spec[key];
}

// The settings whose values differ between A and B, one row each.
function listDifferences() {
  const body = $('#compare-diff tbody');
  const st = compare.sides.map((s) => s.feed.status);
  body.innerHTML = '';
  if (st.length !== 2 || st.some((s) => !s)) return;  // both attached and their statuses known
  const specs = st.map((s) => s.spec || {});
  const keys = new Set([...Object.keys(specs[0]), ...Object.keys(specs[1]), 'size']);
  ['width', 'height'].forEach((k) => keys.delete(k));
  if (st.some((s) => s.denoise)) keys.add('picture');
  const ordered = [...COMPARE_ORDER.filter((k) => keys.has(k)), ...[...keys].filter((k) => !COMPARE_ORDER.includes(k)).sort()];
  const fmt = (v, k) => (k === 'camera' ? fmtCamera(v) : v === undefined ? '–' : v === null ? 'none'
    : typeof v === 'boolean' ? (v ? 'yes' : 'no') : String(v));
  let n = 0;
  for (const k of ordered) {
    const [va, vb] = [0, 1].map((i) => (k === 'picture' ? (st[i].denoise ? compare.sides[i].picture : undefined)
      : compareValue(specs[i], st[i], k)));
    if (JSON.stringify(va) === JSON.stringify(vb)) continue;
    const tr = document.createElement('tr');
    tr.dataset.field = k;
    for (const text of [k.replace(/_/g, ' '), fmt(va, k), fmt(vb, k)]) {
      const td = document.createElement('td');
      td.textContent = text;
      tr.appendChild(td);
    }
    body.appendChild(tr);
    n += 1;
  }
  $('#compare-same').hidden = n > 0;
}

function setCompareMode(mode) {
  compare.mode = mode;
  $('#compare-stage').dataset.mode = mode;
  $('#compare-wipe-box').hidden = mode !== 'wipe';
  $('#compare-metric-box').hidden = mode !== 'diff';
  compare.schedule();
}

function initCompare() {
  document.querySelectorAll('input[name="compare-mode"]').forEach((r) => r.addEventListener('change', (e) => setCompareMode(e.target.value)));
  $('#compare-wipe').addEventListener('input', () => compare.schedule());
  $('#compare-metric').addEventListener('change', (e) => { compare.metric = e.target.value; compare.schedule(); });
  $('#compare-close').addEventListener('click', () => hideCompare());
  ['#compare-a-picture', '#compare-b-picture'].forEach((sel, k) =>
    $(sel).addEventListener('change', (e) => setSidePicture(k, e.target.value)));
  $('#compare-swap').addEventListener('click', () => {
    compare.ids.reverse();
    compare.pictures.reverse();
    syncComparePicks();
    showCompare();
  });
  // Dragging on the wipe moves its divider.
  const out = $('#compare-wipe-canvas');
  const moveTo = (e) => {
    const r = out.getBoundingClientRect();
    $('#compare-wipe').value = String(Math.round(Math.max(0, Math.min(1, (e.clientX - r.left) / r.width)) * 100));
    compare.schedule();
  };
  out.addEventListener('pointerdown', (e) => { out.setPointerCapture(e.pointerId); moveTo(e); });
  out.addEventListener('pointermove', (e) => { if (out.hasPointerCapture(e.pointerId)) moveTo(e); });
  // A sweep cell's or a job row's "compare" box.
  document.addEventListener('change', (e) => {
    const box = e.target;
    if (box.matches && box.matches('input[data-action="compare"]')) toggleCompare(box.closest('[data-id]').dataset.id, box.checked);
  });
}
