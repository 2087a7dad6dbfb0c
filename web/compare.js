// Compare two jobs: picked in the job list or a sweep's cells, shown side by side or with a wipe
// (A left of the divider, B right of it), live while they render, and the settings that differ.
'use strict';

const compare = {
  ids: [],       // [A, B]: the first picked is A; a third pick drops the oldest
  sides: [],     // {id, feed, view}
  mode: 'side',  // or 'wipe'
  frame: 0,
};

// Spec fields in the order the difference list shows them; others follow by name.
const COMPARE_ORDER = ['scene', 'size', 'spp', 'max_depth', 'aperture', 'focal_distance', 'light_samples',
  'keep_fov', 'frame_scene', 'adaptive', 'adaptive_tolerance', 'target_error', 'time_limit', 'seed', 'caustic_tracing'];

function isCompared(id) { return compare.ids.includes(id); }

// Picks (or drops) a job for the comparison; two picked open the panel.
function toggleCompare(id, on) {
  compare.ids = compare.ids.filter((x) => x !== id);
  if (on) compare.ids.push(id);
  if (compare.ids.length > 2) compare.ids = compare.ids.slice(-2);
  syncComparePicks();
  if (compare.ids.length === 2) showCompare();
  else hideCompare(false);
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
    const side = { id, canvas: $(k === 0 ? '#compare-a' : '#compare-b'), feed: feedFor(id) };
    side.view = {
      onFeed(type, feed, rect) {
        if (type === 'size') clearCanvas(side.canvas, feed.canvas.width, feed.canvas.height);
        else if (type === 'pixels') syncCanvas(side.canvas, feed, rect);
        else if (type === 'status') listDifferences();
        compare.schedule();
      },
    };
    $(k === 0 ? '#compare-a-label' : '#compare-b-label').textContent = `${k === 0 ? 'A' : 'B'} · job ${shortId(id)}`;
    side.feed.attach(side.view);
    return side;
  });
  $('#compare').hidden = false;
  listDifferences();
  compare.schedule();
  $('#compare').scrollIntoView({ behavior: 'smooth', block: 'nearest' });
}

function hideCompare(clearPicks = true) {
  compare.sides.forEach((s) => s.feed.detach(s.view));
  compare.sides = [];
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
  });
};

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
  const ordered = [...COMPARE_ORDER.filter((k) => keys.has(k)), ...[...keys].filter((k) => !COMPARE_ORDER.includes(k)).sort()];
  const fmt = (v) => (v === undefined ? '–' : v === null ? 'none' : typeof v === 'boolean' ? (v ? 'yes' : 'no') : String(v));
  let n = 0;
  for (const k of ordered) {
    const [va, vb] = [0, 1].map((i) => compareValue(specs[i], st[i], k));
    if (JSON.stringify(va) === JSON.stringify(vb)) continue;
    const tr = document.createElement('tr');
    tr.dataset.field = k;
    for (const text of [k.replace(/_/g, ' '), fmt(va), fmt(vb)]) {
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
  compare.schedule();
}

function initCompare() {
  document.querySelectorAll('input[name="compare-mode"]').forEach((r) => r.addEventListener('change', (e) => setCompareMode(e.target.value)));
  $('#compare-wipe').addEventListener('input', () => compare.schedule());
  $('#compare-close').addEventListener('click', () => hideCompare());
  $('#compare-swap').addEventListener('click', () => {
    compare.ids.reverse();
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
