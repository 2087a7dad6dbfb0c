// The job list: one row a job (when, what, how far, what it cost), the settings that tell
// neighbouring jobs apart highlighted, pages of 100 with a "more" control, and the actions on a
// job (pause, resume, cancel, delete, render more) that the list and the viewer share.
'use strict';

const JOB_PAGE = 100;  // the server's default page size: the first page is a plain GET /api/jobs
const PRESS_HOLD_MS = 5000;  // longest a press holds the list back (its release may never come)

// Settings beside the columns that can tell two jobs apart: [field, label as text].
const OTHER_SETTINGS = [
  ['light_samples', (v) => `${v} light samples`],
  ['adaptive', (v, s) => (v ? `adaptive ${s.adaptive_tolerance ?? ''}`.trim() : 'not adaptive')],
  ['target_error', (v) => `target ${v}`],
  ['time_limit', (v) => `limit ${v} s`],
  ['seed', (v) => `seed ${v}`],
  ['caustic_tracing', (v) => (v ? 'caustics' : 'no caustics')],
  ['denoise', (v) => (v === 'off' ? 'not denoised' : `denoise ${v}`)],
  ['frame_scene', (v) => (v ? 'fitted to the scene' : 'course framing')],
  ['keep_fov', (v) => (v ? 'whole course view' : 'course crop')],
  ['camera', (v) => `camera ${fmtCamera(v)}`],
];

// The columns after Job and Created: [class, text of a job, key compared between neighbours or null].
const COLUMNS = [
  ['scene', (j, s) => s.scene || '', null],
  ['size', (j) => `${j.width}×${j.height}`, (j) => `${j.width}×${j.height}`],
  ['depth', (j, s) => String(s.max_depth ?? ''), (j, s) => s.max_depth],
  ['aperture', (j, s) => String(s.aperture ?? ''), (j, s) => s.aperture],
  ['focus', (j, s) => String(s.focal_distance ?? ''), (j, s) => s.focal_distance],
  ['spp', (j, s) => `${fmtNum(j.spp_done, 3)} / ${s.spp}`, (j, s) => s.spp],
  ['error-est', (j) => fmtNum(j.error_estimate, 3), null],
  ['duration', (j) => (j.elapsed > 0 ? fmtSeconds(j.elapsed) : '–'), null],
  ['other', (j, s) => otherSettings(s), (j, s) => otherSettings(s)],
];

const jobList = {
  rows: new Map(),  // id -> <tr>
  pages: 1,         // pages of JOB_PAGE shown; each poll fetches them all again
  more: false,      // the server has older jobs than those shown
  pressed: 0,       // when a pointer went down on the list; 0: none is down
  held: null,       // the jobs to render once it is released
};

function fmtSeconds(s) {
  return s < 60 ? `${s.toFixed(1)} s` : fmtDuration(s);
}

// Local time, short: the time of day for today's jobs, else the date and the minute.
function fmtCreated(t) {
  if (!(t > 0)) return '–';
  const d = new Date(t * 1000);
  if (d.toDateString() === new Date().toDateString())
    return d.toLocaleTimeString([], { hour: '2-digit', minute: '2-digit', second: '2-digit' });
  return `${d.toLocaleDateString([], { month: 'short', day: 'numeric' })} ${d.toLocaleTimeString([], { hour: '2-digit', minute: '2-digit' })}`;
}

// The settings without a column of their own that differ from the API's defaults.
function otherSettings(spec) {
  const d = state.defaults;
  const differs = ([name]) => (name === 'camera' ? !!spec.camera : spec[name] !== undefined && spec[name] !== d[name]) ||
    (name === 'adaptive' && spec.adaptive && spec.adaptive_tolerance !== d.adaptive_tolerance);
  return OTHER_SETTINGS.filter(differs).map(([name, label]) => label(spec[name], spec)).join(', ');
}

function rowFor(id) {
  let tr = jobList.rows.get(id);
  if (tr) return tr;
  tr = document.createElement('tr');
  tr.dataset.id = id;
  tr.innerHTML = '<td class="mono id-col" data-label="Job"></td><td class="created" data-label="Created"></td>' +
    COLUMNS.map(([cls]) => `<td class="${cls}" data-label="${$(`#job-table th.${cls}`).textContent}"></td>`).join('') +
    '<td class="state-col"><span class="badge"></span><div class="progress mini"><div class="bar"></div></div></td>' +
    '<td class="row-actions"><button type="button" data-action="open">Open</button>' +
    '<button type="button" data-action="pause">Pause</button><button type="button" data-action="resume">Resume</button>' +
    '<button type="button" data-action="cancel" class="danger">Cancel</button>' +
    '<button type="button" data-action="delete" class="danger" title="Delete the job and its images">Delete</button>' +
    '<a class="button" data-action="png">PNG</a><a class="button" data-action="exr">EXR</a>' +
    '<span class="raw-links" title="The raw render, before denoising"><a class="button" data-action="raw-png">raw PNG</a>' +
    '<a class="button" data-action="raw-exr">raw EXR</a></span>' +
    '<label class="compare-pick" title="Compare two jobs: the first picked is A"><input type="checkbox" data-action="compare"> compare</label></td>';
  jobList.rows.set(id, tr);
  return tr;
}

// A cancelled job keeps the picture it had (the status does not say whether it had one: a pass done tells).
function hasImage(j) {
  return j.state === 'done' || (j.state === 'cancelled' && j.samples > 0);
}

function renderJobs(jobs) {
  // A click is a press and a release on one element: rows moved in between (a job added on top,
  // columns resized by a job's progress) would send it to the table instead, and the tick or the
  // button's action would be lost. So the list waits for the release.
  if (jobList.pressed && performance.now() - jobList.pressed < PRESS_HOLD_MS) {
    jobList.held = jobs;
    return;
  }
  jobList.held = null;
  const body = $('#job-rows');
  const seen = new Set();
  jobs.forEach((j, i) => {
    seen.add(j.id);
    const tr = rowFor(j.id);
    const spec = j.spec || {};
    tr.dataset.state = j.state;
    tr.cells[0].textContent = shortId(j.id);
    tr.cells[0].title = j.id;
    tr.cells[1].textContent = fmtCreated(j.created_at);
    tr.cells[1].title = j.created_at ? new Date(j.created_at * 1000).toLocaleString() : '';
    COLUMNS.forEach(([, text], k) => { tr.cells[2 + k].textContent = text(j, spec); });
    tr.querySelector('td.spp').title = `${Number(j.samples || 0).toLocaleString()} samples taken, ${spec.spp} spp asked`;
    const pct = Math.max(0, Math.min(100, (j.progress || 0) * 100));
    const badge = tr.querySelector('.badge');
    const shown = pct.toFixed(pct < 10 && pct > 0 ? 1 : 0);
    badge.textContent = j.state === 'running' || j.state === 'paused' ? `${j.state} ${shown}%` : j.state;
    badge.dataset.state = j.state;
    badge.title = j.message || (j.stopped ? `stopped: ${j.stopped}` : '');
    tr.querySelector('.bar').style.width = `${pct}%`;
    const live = !FINAL.has(j.state);
    tr.querySelector('[data-action=pause]').hidden = !(j.state === 'queued' || j.state === 'running');
    tr.querySelector('[data-action=resume]').hidden = j.state !== 'paused';
    tr.querySelector('[data-action=cancel]').hidden = !live;
    tr.querySelector('[data-action=delete]').hidden = live;
    const img = hasImage(j);
    setLink(tr.querySelector('[data-action=png]'), img ? j.images.png : null, `render-${j.id}.png`);
    setLink(tr.querySelector('[data-action=exr]'), img ? j.images.exr : null, `render-${j.id}.exr`);
    showRowDenoise(tr, j, img);
    if (body.children[i] !== tr) body.insertBefore(tr, body.children[i] || null);
  });
  for (const [id, tr] of jobList.rows) {
    if (!seen.has(id)) { tr.remove(); jobList.rows.delete(id); }
  }
  markDifferences(jobs);
  syncComparePicks();
  $('#jobs-empty').hidden = jobs.length > 0;
  $('#jobs-more').hidden = !jobList.more;
  highlightRow();
}

// A denoised job's row: its images are the denoised ones, its raw ones beside them, and its error
// estimate is the raw render's (the denoised noise estimate in the cell's tooltip).
function showRowDenoise(tr, j, img) {
  const dn = j.denoise;
  tr.querySelector('.raw-links').hidden = !dn;
  for (const ext of ['png', 'exr']) {
    setLink(tr.querySelector(`[data-action=raw-${ext}]`), dn && img ? dn.raw_images[ext] : null, `render-${j.id}-raw.${ext}`);
    tr.querySelector(`[data-action=${ext}]`).title = dn ? 'The denoised image' : '';
  }
  const noise = dn && Number.isFinite(dn.noise_estimate) ? `; denoised noise estimate ${fmtNum(dn.noise_estimate, 3)} (halves, excludes bias)` : '';
  tr.querySelector('td.error-est').title = dn ? `The raw render's error estimate${noise}` : '';
}

// A cell is marked where its setting differs from the job above or below of the same scene: a
// sweep's varied value lights up on each of its rows, a run of identical jobs stays quiet.
function markDifferences(jobs) {
  jobs.forEach((j, i) => {
    const near = [jobs[i - 1], jobs[i + 1]].filter((n) => n && n.spec.scene === j.spec.scene);
    const tr = jobList.rows.get(j.id);
    COLUMNS.forEach(([, , key], k) => {
      if (!key) return;
      const v = JSON.stringify(key(j, j.spec));
      tr.cells[2 + k].classList.toggle('differs', near.some((n) => JSON.stringify(key(n, n.spec)) !== v));
    });
  });
}

function highlightRow() {
  for (const [id, tr] of jobList.rows) tr.classList.toggle('current', id === viewer.id);
}

// ---------- actions on a job ----------

const ACTIONS = {
  cancel: { what: 'cancel', request: (id) => api(`/api/jobs/${id}`, { method: 'DELETE' }) },
  delete: { what: 'delete', request: (id) => api(`/api/jobs/${id}`, { method: 'DELETE' }) },
  pause: { what: 'pause', request: (id) => postJson(`/api/jobs/${id}/pause`, {}) },
  resume: { what: 'resume', request: (id) => postJson(`/api/jobs/${id}/resume`, {}) },
  continue: { what: 'render more of', request: (id, body) => postJson(`/api/jobs/${id}/continue`, body) },
};

// Runs an action; says why it failed beside the job (the viewer's note, else an alert). Resolves
// the answer's data, or null.
async function jobAction(id, action, body = {}) {
  const a = ACTIONS[action];
  const r = await a.request(id, body);
  if (!r || !r.ok) {
    const e = apiError(r);
    if (viewer.id === id) viewer.note(`Cannot ${a.what} the job: ${e.message}`, 'error');
    else alert(`Cannot ${a.what} job ${shortId(id)}: ${e.message}`);
  } else if (r.data.state === 'deleted') {
    const tr = jobList.rows.get(id);
    if (tr) { tr.remove(); jobList.rows.delete(id); }
    const f = state.feeds.get(id);
    if (f) { f.gone = true; f.emit('gone'); }
  } else if (action === 'continue') {
    const f = state.feeds.get(id);
    if (f) f.reopen();
  }
  refreshJobs();
  refreshJobsSoon(400);
  return r && r.ok ? r.data : null;
}

// Delete takes a second click: it removes the job's images for good. Leaving the button disarms it.
function armDelete(button, id) {
  if (button.dataset.armed === 'true') {
    jobAction(id, 'delete');
    return;
  }
  button.dataset.armed = 'true';
  button.textContent = 'Delete?';
  button.addEventListener('blur', () => {
    button.dataset.armed = 'false';
    button.textContent = 'Delete';
  }, { once: true });
}

// ---------- polling ----------

let pollTimer = null;
function schedulePoll(ms = POLL_MS) {
  clearTimeout(pollTimer);
  pollTimer = setTimeout(refreshJobs, ms);
}

let soonTimer = null;
function refreshJobsSoon(ms = 150) {
  clearTimeout(soonTimer);
  soonTimer = setTimeout(refreshJobs, ms);
}

// The pages shown, newest first; null when the server cannot be reached.
async function fetchJobs() {
  let jobs = [], cursor = null;
  for (let p = 0; p < jobList.pages; ++p) {
    const r = await api(p === 0 ? '/api/jobs' : `/api/jobs?limit=${JOB_PAGE}&cursor=${cursor}`);
    if (!r || !r.ok) return null;
    jobs = jobs.concat(r.data.jobs || []);
    cursor = r.data.next_cursor;
    if (!cursor) break;
  }
  jobList.more = Boolean(cursor);
  return jobs;
}

let refreshing = null;
async function refreshJobs() {
  if (refreshing) return refreshing;
  refreshing = (async () => {
    const jobs = await fetchJobs();
    if (!jobs) {
      connectionLost();
      return;
    }
    const wasDown = state.pollOk === false;
    state.pollOk = true;
    // A camera move's previews come and go: the list leaves them out, once a preview being posted
    // has its id (it may be in this list already).
    while (nav.posting) await nav.posting.catch(() => null);
    renderJobs(jobs.filter((j) => !nav.previews.has(j.id)));
    if (wasDown) onReconnected();
    updateConn();
    schedulePoll();
  })();
  try { await refreshing; } finally { refreshing = null; }
}

// The server is back: reload what may have changed, and restart the streams that gave up.
function onReconnected() {
  if (!state.scenes.length) loadScenes();
  checkDenoiser();  // the server may have come back with or without its denoiser
  for (const f of state.feeds.values()) {
    if (f.gone || f.ended) continue;
    if (!f.es || f.es.readyState === EventSource.CLOSED) {
      f.es = null;
      f.start();
    }
  }
}

function initJobs() {
  $('#job-rows').addEventListener('pointerdown', () => { jobList.pressed = performance.now(); });
  const release = (e) => {
    if (!jobList.pressed || (e.type === 'blur' && e.target !== window)) return;
    jobList.pressed = 0;
    // A task later: the click comes in the release's task, and its handlers see the rows it hit.
    setTimeout(() => { if (jobList.held && !jobList.pressed) renderJobs(jobList.held); });
  };
  for (const type of ['pointerup', 'pointercancel', 'blur']) window.addEventListener(type, release, true);
  $('#job-rows').addEventListener('click', (e) => {
    const b = e.target.closest('[data-action]');
    if (!b || b.tagName === 'A' || b.tagName === 'INPUT') return;  // links; compare boxes: compare.js
    const id = b.closest('tr').dataset.id;
    if (b.dataset.action === 'open') viewer.show(id);
    else if (b.dataset.action === 'delete') armDelete(b, id);
    else jobAction(id, b.dataset.action);
  });
  $('#jobs-more').addEventListener('click', () => {
    jobList.pages += 1;
    refreshJobs();
  });
}
