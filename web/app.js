// The render-job page: the viewer fed by the job's event stream (tiles paint as they arrive),
// click-to-focus, and the wiring. No framework, no build step: common.js (state, API), feed.js (a
// job's event stream), chart.js, sweep.js, jobs.js (the job list), viewer_tools.js (exposure,
// mappings, zoom, readout), compare.js, denoise.js (the denoise control and the raw / denoised
// switch), upload.js, form.js (the form), camera.js (moving the camera on the image) and farm.js
// (the Redis render farm's panel) load before this file (index.html), as plain scripts sharing
// their names.
'use strict';

// ---------- the main viewer ----------

const viewer = {
  feed: null,
  id: null,
  moreFor: null,       // the job whose spp the "Render more" field was set for
  preview: false,      // the job shown is a camera move's preview (camera.js), not in the list
  keepPicture: false,  // the last picture stays, scaled, until the new job's tiles cover it

  // Opens a job. The form keeps what the user set ("Reuse settings" copies a job's settings in).
  // A preview, or the job a camera move ends in (keep), keeps the picture and the zoom.
  show(id, { preview = false, keep = false } = {}) {
    if (this.id === id) return;
    if (this.feed) this.feed.detach(this);
    this.id = id;
    this.feed = null;
    this.moreFor = null;
    this.preview = preview;
    this.keepPicture = (preview || keep) && !!id;
    if (!this.keepPicture) tools.reset();
    else tools.resetData();
    $('#v-marker').hidden = true;
    this.note('');
    if (!preview) history.replaceState(null, '', id ? `#job=${id}` : '#');
    $('#viewer').dataset.preview = String(preview);
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
    resetDenoise();
    drawChart($('#v-chart'), []);
    const c = $('#v-canvas');
    if (!this.keepPicture) clearCanvas(c, c.width, c.height);
    highlightRow();
    nav.onShow(id, preview, keep);
    if (!id) {
      $('#v-title').textContent = 'No job open';
      $('#v-view').textContent = '';
      return;
    }
    $('#v-title').textContent = `${preview ? 'Preview' : 'Job'} ${shortId(id)}`;
    $('#v-placeholder').textContent = 'Waiting for the first tiles…';
    $('#v-placeholder').hidden = this.keepPicture;
    this.feed = feedFor(id);
    this.feed.attach(this);
  },

  onFeed(type, feed, rect) {
    const canvas = $('#v-canvas');
    if (type === 'size') {
      const oldWidth = canvas.width;
      if (this.keepPicture) resizeKeeping(canvas, feed.canvas.width, feed.canvas.height);
      else clearCanvas(canvas, feed.canvas.width, feed.canvas.height);
      tools.onResize(oldWidth, canvas.width);
      fitStage();
    } else if (type === 'pixels') {
      // The tools paint from the float pixels; else the picture picked (raw or denoised).
      if (!tools.active()) syncCanvas(canvas, feed, rect, denoiseView.choice);
      if (rect && rect.denoised) showPicture();  // a denoised picture: the float pixels are the same
      else tools.onPixels(feed.ended);
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
      showPicture();
      const st = feed.status && feed.status.state;
      if (!feed.painted && !this.keepPicture) {
        $('#v-placeholder').textContent = st === 'cancelled' ? 'No image: the job was cancelled.'
          : st === 'failed' ? 'No image: the job failed.' : 'This job has no image.';
      }
    } else if (type === 'gone') {
      if (this.preview) return;  // a superseded preview, deleted: its picture stays until the next
      $('#v-state').hidden = true;
      $('#v-cancel').disabled = true;
      $('#v-pause').hidden = true;
      $('#v-more-form').hidden = true;
      setLink($('#v-png'), null);
      setLink($('#v-exr'), null);
      resetDenoise();
      $('#v-placeholder').hidden = false;
      $('#v-placeholder').textContent = 'This job no longer exists on the server.';
      $('#viewer').dataset.state = 'gone';
    }
  },

  renderStatus(s) {
    if (!s) return;
    const spec = s.spec || {};
    $('#viewer').dataset.state = s.state;
    $('#v-title').textContent = `${this.preview ? 'Preview · ' : ''}${spec.scene || 'Job'} · ${s.width}×${s.height} · ${spec.spp} spp`;
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
    $('#v-edit').disabled = this.preview;
    this.renderMore(s);
    nav.onStatus(s, this.preview);
    const hasImage = s.state === 'done' || (this.feed && this.feed.painted);
    setLink($('#v-png'), hasImage ? s.images.png : null, `render-${s.id}.png`);
    setLink($('#v-exr'), hasImage ? s.images.exr : null, `render-${s.id}.exr`);
    showDenoise(s, hasImage);
  },

  // "Render more": a finished job whose film is kept continues, to its own spp when it stopped
  // short of it (cancelled, a target or a time limit reached), else to twice that, to start.
  renderMore(s) {
    const form = $('#v-more-form');
    form.hidden = !(s.can_continue && FINAL.has(s.state)) || this.preview;
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
  saveForm();
  scheduleCheck();
}

function flash(el) {
  el.classList.remove('flash');
  void el.offsetWidth;
  el.classList.add('flash');
}

// ---------- wiring ----------

function init() {
  initForm();
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
  initCamera();
  initCompare();
  initDenoise();
  initFarm();
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
    if (m) viewer.show(m[1]);
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
  checkDenoiser();
  pollFarm();
  await refreshJobs();
  const m = location.hash.match(/job=([0-9a-f]+)/);
  if (m) viewer.show(m[1]);
  else {
    // Show what is rendering now, else the newest job.
    const list = [...jobList.rows.values()].map((tr) => ({ id: tr.dataset.id, state: tr.dataset.state }));
    const pick = list.find((j) => j.state === 'running') || list[0];
    if (pick) viewer.show(pick.id);
  }
  scheduleCheck();
}

document.addEventListener('DOMContentLoaded', init);
