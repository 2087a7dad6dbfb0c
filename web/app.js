// The render-job page: a form that validates against /api/jobs/check, a viewer fed by the job's
// event stream (tiles paint as they arrive), click-to-focus, and the wiring. No framework, no
// build step: common.js (state, API), feed.js (a job's event stream), chart.js, sweep.js, jobs.js
// (the job list), viewer_tools.js (exposure, mappings, zoom, readout) and compare.js load before
// this file (index.html), as plain scripts sharing their top-level names.
'use strict';

// Form fields: name -> kind. The input of field F is #f-F and its error line is #err-F.
const FIELDS = {
  scene: 'select', max_depth: 'int', light_samples: 'int', aperture: 'num', focal_distance: 'num',
  spp: 'int', width: 'int', height: 'int', seed: 'int', time_limit: 'num', target_error: 'num', adaptive: 'bool',
  adaptive_tolerance: 'num', caustic_tracing: 'bool',
};

// The framing select sets two job fields (the API refuses both true): value -> fields, and what it does.
const FRAMINGS = {
  scene: { frame_scene: true, keep_fov: false, hint: 'The course\'s view direction, zoomed so the scene fills the image.' },
  crop: { frame_scene: false, keep_fov: false, hint: 'As the course renders: a pixel keeps its angle, and a smaller image shows the centre of the view.' },
  whole: { frame_scene: false, keep_fov: true, hint: 'The course\'s whole view, scaled to this size.' },
};
const FRAMING_FIELDS = ['frame_scene', 'keep_fov'];  // their errors show beside the select

function framingOf(spec) {
  if (spec.frame_scene) return 'scene';
  return spec.keep_fov ? 'whole' : 'crop';
}

function showFramingHint() {
  const f = FRAMINGS[$('#f-framing').value];
  $('#framing-hint').textContent = f ? `${f.hint} COLLADA scenes; a glTF scene keeps its own camera.` : '';
}

// ---------- the main viewer ----------

const viewer = {
  feed: null,
  id: null,
  fillPending: false,  // the form takes the job's settings when its status arrives
  moreFor: null,       // the job whose spp the "Render more" field was set for

  // Opens a job; with fill, its settings go into the form (a reload, a link, the list's Open), so
  // that click-to-focus and the sweeps start from the image on screen.
  show(id, { fill = false } = {}) {
    if (this.id === id) {
      if (fill && this.feed && this.feed.status) fillForm(this.feed.status.spec);
      return;
    }
    if (this.feed) this.feed.detach(this);
    this.id = id;
    this.feed = null;
    this.fillPending = fill;
    this.moreFor = null;
    tools.reset();
    $('#v-marker').hidden = true;
    this.note('');
    history.replaceState(null, '', id ? `#job=${id}` : '#');
    $('#viewer').dataset.ended = 'false';
    $('#viewer').dataset.tiles = '0';
    $('#viewer').dataset.state = id ? 'loading' : 'empty';
    $('#viewer').dataset.conn = 'live';
    $('#v-state').hidden = true;
    $('#v-bar').style.width = '0%';
    $('#v-progress-text').textContent = '';
    for (const k of ['#v-spp', '#v-elapsed', '#v-eta', '#v-error']) $(k).textContent = '–';
    $('#v-cancel').disabled = true;
    $('#v-pause').hidden = true;
    $('#v-edit').disabled = true;
    $('#v-more-form').hidden = true;
    setLink($('#v-png'), null);
    setLink($('#v-exr'), null);
    drawChart($('#v-chart'), []);
    const c = $('#v-canvas');
    clearCanvas(c, c.width, c.height);
    highlightRow();
    if (!id) {
      $('#v-title').textContent = 'No job open';
      return;
    }
    $('#v-title').textContent = `Job ${shortId(id)}`;
    $('#v-placeholder').textContent = 'Waiting for the first tiles…';
    $('#v-placeholder').hidden = false;
    this.feed = feedFor(id);
    this.feed.attach(this);
  },

  onFeed(type, feed, rect) {
    const canvas = $('#v-canvas');
    if (type === 'size') {
      clearCanvas(canvas, feed.canvas.width, feed.canvas.height);
      fitStage();
    } else if (type === 'pixels') {
      if (!tools.active()) syncCanvas(canvas, feed, rect);  // else the tools paint from the float pixels
      tools.onPixels(feed.ended);
      $('#v-placeholder').hidden = true;
      $('#viewer').dataset.tiles = String(feed.tiles);
    } else if (type === 'status') {
      this.renderStatus(feed.status);
      if (tools.rate) tools.showLegend();
    } else if (type === 'conn') {
      $('#viewer').dataset.conn = feed.conn;
    } else if (type === 'history') {
      drawChart($('#v-chart'), feed.history);
    } else if (type === 'reopen') {
      $('#viewer').dataset.ended = 'false';
    } else if (type === 'end') {
      $('#viewer').dataset.ended = 'true';
      if (feed.painted) tools.onPixels(true);
      const st = feed.status && feed.status.state;
      if (!feed.painted) {
        $('#v-placeholder').textContent = st === 'cancelled' ? 'No image: the job was cancelled.'
          : st === 'failed' ? 'No image: the job failed.' : 'This job has no image.';
      }
    } else if (type === 'gone') {
      $('#v-state').hidden = true;
      $('#v-cancel').disabled = true;
      $('#v-pause').hidden = true;
      $('#v-more-form').hidden = true;
      setLink($('#v-png'), null);
      setLink($('#v-exr'), null);
      $('#v-placeholder').hidden = false;
      $('#v-placeholder').textContent = 'This job no longer exists on the server.';
      $('#viewer').dataset.state = 'gone';
    }
  },

  renderStatus(s) {
    if (!s) return;
    const spec = s.spec || {};
    $('#viewer').dataset.state = s.state;
    $('#v-title').textContent = `${spec.scene || 'Job'} · ${s.width}×${s.height} · ${spec.spp} spp`;
    $('#v-title').title = `job ${s.id}`;
    const badge = $('#v-state');
    badge.hidden = false;
    badge.textContent = s.state;
    badge.dataset.state = s.state;
    const pct = Math.max(0, Math.min(100, (s.progress || 0) * 100));
    $('#v-bar').style.width = `${pct}%`;
    $('#v-progress').setAttribute('aria-valuenow', pct.toFixed(0));
    $('#v-progress').dataset.state = s.state;
    let text = `${pct.toFixed(pct < 10 && pct > 0 ? 1 : 0)}%`;
    if (s.state === 'running' && s.eta !== null && s.eta !== undefined) text += ` · ETA ${fmtDuration(s.eta)}`;
    if (s.state === 'queued') text = 'queued';
    if (s.state === 'paused') text = `paused · ${text}`;
    if (s.state === 'done' && s.stopped && s.stopped !== 'finished') text += ` · ${s.stopped}`;
    if (s.state === 'failed') text = `failed${s.message ? `: ${s.message}` : ''}`;
    $('#v-progress-text').textContent = text;
    showWarnings($('#v-warnings'), s.warnings);
    $('#v-spp').textContent = `${fmtNum(s.spp_done, 3)} / ${spec.spp}`;
    $('#v-spp').title = `${Number(s.samples || 0).toLocaleString()} samples taken`;
    $('#v-elapsed').textContent = fmtDuration(s.elapsed);
    $('#v-eta').textContent = s.state === 'running' ? fmtDuration(s.eta) : s.state === 'queued' ? '…' : '–';
    $('#v-error').textContent = fmtNum(s.error_estimate, 3);
    $('#v-cancel').disabled = FINAL.has(s.state);
    const pause = $('#v-pause');
    pause.hidden = FINAL.has(s.state);
    pause.textContent = s.state === 'paused' ? 'Resume' : 'Pause';
    pause.dataset.action = s.state === 'paused' ? 'resume' : 'pause';
    $('#v-edit').disabled = false;
    this.renderMore(s);
    if (this.fillPending && s.spec) {
      this.fillPending = false;
      fillForm(s.spec);
    }
    const hasImage = s.state === 'done' || (this.feed && this.feed.painted);
    setLink($('#v-png'), hasImage ? s.images.png : null, `render-${s.id}.png`);
    setLink($('#v-exr'), hasImage ? s.images.exr : null, `render-${s.id}.exr`);
  },

  // "Render more": a finished job whose film is kept continues, to its own spp when it stopped
  // short of it (cancelled, a target or a time limit reached), else to twice that, to start.
  renderMore(s) {
    const form = $('#v-more-form');
    form.hidden = !(s.can_continue && FINAL.has(s.state));
    if (form.hidden) return;
    const key = `${s.id}:${s.spec.spp}`;
    if (this.moreFor === key) return;  // keep what the user typed
    this.moreFor = key;
    const spent = s.state === 'done' && s.stopped === 'finished';
    $('#v-more-spp').value = String(spent ? s.spec.spp * 2 : s.spec.spp);
    $('#v-more-spp').min = String(s.spec.spp);
  },

  note(text, kind = '') {
    const n = $('#v-note');
    n.textContent = text;
    n.dataset.kind = kind;
  },
};

function setLink(a, href, name) {
  if (href) {
    a.href = withToken(href);
    a.download = name;
    a.removeAttribute('aria-disabled');
  } else {
    a.removeAttribute('href');
    a.setAttribute('aria-disabled', 'true');
  }
}

// Keeps the picture inside the window: as wide as the column, at most 70% of the window high.
function fitStage() {
  const canvas = $('#v-canvas');
  const wrap = $('#v-wrap');
  const w = canvas.width, h = canvas.height;
  wrap.style.aspectRatio = `${w} / ${h}`;
  wrap.style.maxWidth = `calc(70vh * ${w / h})`;
  requestAnimationFrame(() => {
    const scale = wrap.clientWidth / w;
    canvas.style.imageRendering = scale >= 2 ? 'pixelated' : 'auto';
    tools.applyZoom();
  });
}

// ---------- click to focus ----------

async function focusAt(ev) {
  const id = viewer.id;
  if (!id || !viewer.feed || !viewer.feed.status) return;
  const canvas = $('#v-canvas');
  const rect = canvas.getBoundingClientRect();
  const fx = (ev.clientX - rect.left) / rect.width;
  const fy = (ev.clientY - rect.top) / rect.height;
  if (!(fx >= 0 && fx <= 1 && fy >= 0 && fy <= 1)) return;
  const px = Math.min(canvas.width - 1, Math.floor(fx * canvas.width)) + 0.5;
  const py = Math.min(canvas.height - 1, Math.floor(fy * canvas.height)) + 0.5;
  const marker = $('#v-marker');
  const wrap = $('#v-wrap').getBoundingClientRect();  // the canvas may be zoomed and panned inside it
  marker.style.left = `${((ev.clientX - wrap.left) / wrap.width) * 100}%`;
  marker.style.top = `${((ev.clientY - wrap.top) / wrap.height) * 100}%`;
  marker.hidden = false;
  marker.classList.remove('pulse');
  void marker.offsetWidth;
  marker.classList.add('pulse');
  viewer.note('Measuring the distance there…');
  const r = await api(`/api/jobs/${id}/focus?x=${px}&y=${py}`);
  if (viewer.id !== id) return;
  const note = $('#v-note');
  note.dataset.x = String(px);
  note.dataset.y = String(py);
  if (!r || !r.ok) return viewer.note(`Cannot focus there: ${apiError(r).message}`, 'error');
  const where = `pixel (${Math.floor(px)}, ${Math.floor(py)})`;
  if (r.data.distance === null) return viewer.note(`Nothing to focus on at ${where}: that ray leaves the scene. Focal distance unchanged.`, 'warn');
  const d = Number(r.data.distance.toFixed(3));
  const input = $('#f-focal_distance');
  input.value = String(d);
  flash(input);
  const jobScene = viewer.feed.status.spec.scene;
  let extra = '';
  if ($('#f-scene').value !== jobScene && state.scenes.some((s) => s.name === jobScene)) {
    $('#f-scene').value = jobScene;
    showSceneSummary();
    extra = ` Scene set to ${jobScene}.`;
  }
  const ap = Number($('#f-aperture').value || 0);
  const hint = ap > 0 ? ' Render again to see it.' : ' Raise the aperture above 0 to see the depth of field.';
  viewer.note(`Focal distance set to ${d}: the surface under ${where}.${extra}${hint}`, 'ok');
  scheduleCheck();
}

function flash(el) {
  el.classList.remove('flash');
  void el.offsetWidth;
  el.classList.add('flash');
}

// ---------- the form ----------

function input(name) { return document.getElementById(`f-${name}`); }

// The job spec from the form; empty fields are left out (the server's default applies).
function readSpec() {
  const spec = {}, errors = {};
  for (const [name, kind] of Object.entries(FIELDS)) {
    const el = input(name);
    if (kind === 'bool') spec[name] = el.checked;
    else if (kind === 'select') { if (el.value) spec[name] = el.value; }
    else if (el.validity && el.validity.badInput) errors[name] = 'Enter a number.';
    else if (el.value.trim() !== '') spec[name] = Number(el.value);
  }
  const framing = FRAMINGS[$('#f-framing').value];
  for (const name of FRAMING_FIELDS) spec[name] = framing[name];
  return { spec, errors };
}

function clearErrors() {
  document.querySelectorAll('#job-form .error').forEach((e) => { e.textContent = ''; });
  document.querySelectorAll('#job-form [aria-invalid]').forEach((e) => e.removeAttribute('aria-invalid'));
}

function showError(field, message) {
  if (FRAMING_FIELDS.includes(field)) field = 'framing';
  const line = field && document.getElementById(`err-${field}`);
  if (line) {
    line.textContent = message;
    const el = input(field);
    if (el) el.setAttribute('aria-invalid', 'true');
    // An error inside the closed "More options" must be seen.
    const details = line.closest('details');
    if (details) details.open = true;
  } else {
    const form = $('#err-form');
    form.textContent = form.textContent ? `${form.textContent} ${message}` : message;
  }
}

// Marks every field an error answer names (all of error.errors, else error.field).
function showApiErrors(e, prefix = '') {
  const list = e.errors && e.errors.length ? e.errors : [{ field: e.field, message: e.message }];
  for (const x of list) showError(x.field, prefix + x.message);
}

function showClientErrors(errors) {
  clearErrors();
  for (const [f, m] of Object.entries(errors)) showError(f, m);
}

let checkTimer = null, checkSeq = 0;
function scheduleCheck() {
  clearTimeout(checkTimer);
  checkTimer = setTimeout(checkForm, 250);
}

// Validates the form with the server as the user types: the error appears beside its field.
async function checkForm() {
  const seq = ++checkSeq;
  const { spec, errors } = readSpec();
  if (Object.keys(errors).length) return showClientErrors(errors);
  $('#check-state').textContent = '';
  const r = await postJson('/api/jobs/check', spec);
  if (seq !== checkSeq || !r) return;
  clearErrors();
  if (r.ok) {
    const s = r.data.spec;
    const n = new Intl.NumberFormat('en', { notation: 'compact', maximumFractionDigits: 1 }).format(s.width * s.height * s.spp);
    $('#check-state').textContent = `✓ ${n} samples`;
  } else {
    showApiErrors(apiError(r));
  }
}

async function submitJob(ev) {
  ev.preventDefault();
  clearTimeout(checkTimer);
  ++checkSeq;  // a check still in flight must not overwrite what the submit says
  const { spec, errors } = readSpec();
  if (Object.keys(errors).length) return showClientErrors(errors);
  const btn = $('#submit');
  btn.disabled = true;
  $('#check-state').textContent = '';
  try {
    const r = await postJson('/api/jobs', spec, { 'Idempotency-Key': randomKey() });
    clearErrors();
    if (!r || !r.ok) {
      showApiErrors(apiError(r));
      return;
    }
    viewer.show(r.data.id);
    scheduleCheck();
    if (window.matchMedia('(max-width: 900px)').matches) $('#viewer').scrollIntoView({ behavior: 'smooth', block: 'start' });
    refreshJobs();
  } finally {
    btn.disabled = false;
  }
}

function showSceneSummary() {
  const sc = state.scenes.find((s) => s.name === $('#f-scene').value);
  const el = $('#scene-summary');
  const btn = $('#use-center');
  showWarnings($('#scene-warnings'), sc && sc.summary && sc.summary.warnings);
  if (!sc || !sc.summary) { el.textContent = ''; btn.hidden = true; return; }
  const s = sc.summary;
  const parts = [];
  if (s.triangles) parts.push(`${s.triangles.toLocaleString()} triangles`);
  if (s.spheres) parts.push(`${s.spheres} sphere${s.spheres === 1 ? '' : 's'}`);
  if (s.materials && s.materials.length) parts.push(s.materials.join(', '));
  if (s.lights && s.lights.length) parts.push(`${s.lights.join(', ')} light${s.lights.length === 1 ? '' : 's'}`);
  el.textContent = parts.join(' · ');
  if (Number.isFinite(s.center_distance) && s.center_distance > 0) {
    btn.hidden = false;
    btn.textContent = `Use the scene centre (${s.center_distance.toFixed(2)})`;
    btn.dataset.value = String(Number(s.center_distance.toFixed(3)));
  } else {
    btn.hidden = true;
  }
}

function fillForm(spec) {
  for (const [name, kind] of Object.entries(FIELDS)) {
    if (!(name in spec)) continue;
    const el = input(name);
    if (kind === 'bool') el.checked = !!spec[name];
    else el.value = spec[name] === null ? '' : String(spec[name]);
  }
  $('#f-framing').value = framingOf(spec);
  showFramingHint();
  showSceneSummary();
  scheduleCheck();
}

async function loadScenes() {
  const r = await api('/api/scenes');
  if (!r || !r.ok) return false;
  state.scenes = r.data.scenes || [];
  state.defaults = r.data.defaults || {};
  const sel = $('#f-scene');
  const current = sel.value;
  sel.innerHTML = '';
  for (const s of state.scenes) {
    const o = document.createElement('option');
    o.value = s.name;
    o.textContent = s.name;
    sel.appendChild(o);
  }
  if (current && state.scenes.some((s) => s.name === current)) sel.value = current;
  else if (state.scenes.some((s) => s.name === 'cornell')) sel.value = 'cornell';
  if (!state.formFilled) {
    state.formFilled = true;
    for (const [name, kind] of Object.entries(FIELDS)) {
      if (name === 'scene' || !(name in state.defaults)) continue;
      const el = input(name);
      if (kind === 'bool') el.checked = !!state.defaults[name];
      else el.value = String(state.defaults[name]);
      if (kind !== 'bool') el.placeholder = String(state.defaults[name]);
    }
    // The API keeps the course's cropping by default; on the page the scene fills the image.
    $('#f-framing').value = 'scene';
    showFramingHint();
  }
  showSceneSummary();
  return true;
}

// ---------- wiring ----------

function init() {
  const form = $('#job-form');
  form.addEventListener('submit', submitJob);
  form.addEventListener('input', (e) => {
    if (e.target.id === 'f-scene') showSceneSummary();
    scheduleCheck();
  });
  form.addEventListener('change', (e) => {
    if (e.target.id === 'f-scene') showSceneSummary();
    if (e.target.id === 'f-framing') showFramingHint();
    scheduleCheck();
  });
  $('#use-center').addEventListener('click', (e) => {
    input('focal_distance').value = e.currentTarget.dataset.value;
    flash(input('focal_distance'));
    scheduleCheck();
  });
  $('#focus-stack').addEventListener('click', () => runSweep('focus'));
  $('#aperture-sweep').addEventListener('click', () => runSweep('aperture'));
  $('#sweep-close').addEventListener('click', closeSweep);
  $('#v-canvas').addEventListener('click', focusAt);
  $('#v-cancel').addEventListener('click', () => viewer.id && jobAction(viewer.id, 'cancel'));
  $('#v-pause').addEventListener('click', (e) => viewer.id && jobAction(viewer.id, e.currentTarget.dataset.action));
  $('#v-more-form').addEventListener('submit', async (e) => {
    e.preventDefault();
    const id = viewer.id, spp = Number($('#v-more-spp').value);
    if (!id) return;
    if (!(Number.isInteger(spp) && spp > 0)) return viewer.note('Render more: enter a whole number of samples per pixel.', 'error');
    if (await jobAction(id, 'continue', { spp })) viewer.note(`Rendering on to ${spp} spp.`, 'ok');
  });
  $('#v-edit').addEventListener('click', () => {
    if (viewer.feed && viewer.feed.status) {
      fillForm(viewer.feed.status.spec);
      viewer.note('The form now holds this job\'s settings.', 'ok');
    }
  });
  initJobs();
  initUpload();
  initViewerTools();
  initCompare();
  let resizeTimer = null;
  window.addEventListener('resize', () => {
    clearTimeout(resizeTimer);
    resizeTimer = setTimeout(() => {
      fitStage();
      drawChart($('#v-chart'), viewer.feed ? viewer.feed.history : []);
    }, 100);
  });
  window.addEventListener('hashchange', () => {
    const m = location.hash.match(/job=([0-9a-f]+)/);
    if (m) viewer.show(m[1], { fill: true });
  });
  drawChart($('#v-chart'), []);
  fitStage();
  start();
}

async function start() {
  // Until the server answers, retry every second with the indicator up.
  while (!(await loadScenes())) {
    state.pollOk = false;
    updateConn();
    await new Promise((r) => setTimeout(r, 1000));
  }
  await refreshJobs();
  const m = location.hash.match(/job=([0-9a-f]+)/);
  if (m) viewer.show(m[1], { fill: true });
  else {
    // Show what is rendering now, else the newest job.
    const list = [...jobList.rows.values()].map((tr) => ({ id: tr.dataset.id, state: tr.dataset.state }));
    const pick = list.find((j) => j.state === 'running') || list[0];
    if (pick) viewer.show(pick.id, { fill: true });
  }
  scheduleCheck();
}

document.addEventListener('DOMContentLoaded', init);
