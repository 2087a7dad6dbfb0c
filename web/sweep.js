// Sweeps: four jobs around the current focal distance or aperture, shown side by side.
'use strict';

function round3(x) { return Number(x.toPrecision(3)); }

async function runSweep(kind) {
  const { spec, errors } = readSpec();
  if (Object.keys(errors).length) return showClientErrors(errors);
  const d = state.defaults;
  const f = spec.focal_distance ?? d.focal_distance ?? 4.7;
  let a = spec.aperture ?? d.aperture ?? 0;
  const base = { ...spec };
  if ($('#sweep-half').checked) {
    base.width = Math.max(8, Math.round((spec.width ?? d.width ?? 480) / 2));
    base.height = Math.max(8, Math.round((spec.height ?? d.height ?? 360) / 2));
    // A smaller copy of the same view, not the centre of it (what the course crop makes of a
    // smaller size): the view on screen, else the form's at full size, as the camera field.
    if (!base.camera) base.camera = await viewOf(spec);
    if (!base.camera) delete base.camera;
  }
  let values, key, title, sub, note = '';
  if (kind === 'focus') {
    key = 'focal_distance';
    // Four distances spread evenly around f, 15% of it apart.
    values = [-1.5, -0.5, 0.5, 1.5].map((k) => round3(Math.max(0.01, f * (1 + 0.15 * k))));
    if (!(a > 0)) {
      a = 0.1;
      note = ' (the form says 0, which keeps everything sharp)';
    }
    base.aperture = a;
    title = 'Focus stack';
    sub = `Focal distances ${values.join(', ')} around ${round3(f)}, at aperture ${round3(a)}${note}.`;
  } else {
    key = 'aperture';
    // Four lens radii a half and a whole-and-a-half stop either side of a (0.1 when a is 0).
    const centre = a > 0 ? a : 0.1;
    values = [-1.5, -0.5, 0.5, 1.5].map((k) => round3(centre * 2 ** k));
    title = 'Aperture sweep';
    sub = `Lens radii ${values.join(', ')} around ${round3(centre)}${a > 0 ? '' : ' (the form says 0)'}, focused at ${round3(f)}.`;
    base.focal_distance = f;
  }
  const buttons = [$('#focus-stack'), $('#aperture-sweep')];
  buttons.forEach((b) => { b.disabled = true; });
  clearErrors();
  try {
    const first = await postJson('/api/jobs/check', { ...base, [key]: values[0] });
    if (!first || !first.ok) {
      return showApiErrors(apiError(first));
    }
    const ids = [];
    for (const v of values) {
      const r = await postJson('/api/jobs', { ...base, [key]: v }, { 'Idempotency-Key': randomKey() });
      if (!r || !r.ok) {
        showApiErrors(apiError(r), `Sweep stopped after ${ids.length} of 4 jobs: `);
        break;
      }
      ids.push({ id: r.data.id, label: `${key === 'aperture' ? 'aperture' : 'focus'} ${v}` });
    }
    if (ids.length) showSweep(title, `${sub} Click one to open it above.`, ids);
    refreshJobs();
  } finally {
    buttons.forEach((b) => { b.disabled = false; });
  }
}

// The shown job's view when it is of the form's scene, else the view the form's spec renders from
// (/api/jobs/check); null when the server reports none.
async function viewOf(spec) {
  const st = viewer.feed && !viewer.preview && viewer.feed.status;
  if (st && st.view && st.spec && st.spec.scene === spec.scene) return st.view;
  const r = await postJson('/api/jobs/check', spec);
  return r && r.ok && r.data.view ? r.data.view : null;
}

class SweepCell {
  constructor(id, label) {
    this.id = id;
    this.el = document.createElement('figure');
    this.el.className = 'cell';
    this.el.dataset.id = id;
    this.el.dataset.state = 'queued';
    this.el.innerHTML = '<button type="button" class="cell-open" title="Open in the viewer"><canvas></canvas></button>' +
      '<figcaption><span class="cell-label"></span><span class="cell-state"></span>' +
      '<label class="compare-pick"><input type="checkbox" data-action="compare"> compare</label></figcaption>' +
      '<div class="progress mini"><div class="bar"></div></div>';
    this.canvas = this.el.querySelector('canvas');
    this.el.querySelector('.cell-label').textContent = label;
    this.el.querySelector('.cell-open').addEventListener('click', () => viewer.show(id));
    this.feed = feedFor(id);
    this.feed.attach(this);
  }

  onFeed(type, feed, rect) {
    if (type === 'size') clearCanvas(this.canvas, feed.canvas.width, feed.canvas.height);
    else if (type === 'pixels') syncCanvas(this.canvas, feed, rect);
    else if (type === 'status' && feed.status) {
      const s = feed.status;
      this.el.dataset.state = s.state;
      const pct = Math.round((s.progress || 0) * 100);
      this.el.querySelector('.cell-state').textContent = s.state === 'running' ? `${pct}%` : s.state;
      this.el.querySelector('.bar').style.width = `${pct}%`;
      this.el.querySelector('.progress').dataset.state = s.state;
    } else if (type === 'end') {
      this.el.dataset.ended = 'true';
    }
  }

  dispose() { this.feed.detach(this); }
}

function showSweep(title, sub, jobs) {
  closeSweep();
  $('#sweep-title').textContent = title;
  $('#sweep-sub').textContent = sub;
  const grid = $('#sweep-grid');
  state.sweepCells = jobs.map((j) => new SweepCell(j.id, j.label));
  state.sweepCells.forEach((c) => grid.appendChild(c.el));
  syncComparePicks();
  $('#sweep').hidden = false;
  $('#sweep').scrollIntoView({ behavior: 'smooth', block: 'nearest' });
}

function closeSweep() {
  state.sweepCells.forEach((c) => c.dispose());
  state.sweepCells = [];
  $('#sweep-grid').innerHTML = '';
  $('#sweep').hidden = true;
}
