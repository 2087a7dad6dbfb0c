// The render-job page: a form that validates against /api/jobs/check, a viewer fed by the job's
// event stream (tiles paint as they arrive), click-to-focus, four-job sweeps, and the job list.
// No framework, no build step. Every job's pixels come from one shared Feed per job (one
// EventSource, one decode), copied into each canvas that shows that job.
'use strict';

const $ = (sel) => document.querySelector(sel);

// Form fields: name -> kind. The input of field F is #f-F and its error line is #err-F.
const FIELDS = {
  scene: 'select', max_depth: 'int', light_samples: 'int', aperture: 'num', focal_distance: 'num',
  spp: 'int', width: 'int', height: 'int', seed: 'int', time_limit: 'num', target_error: 'num', adaptive: 'bool',
  keep_fov: 'bool', caustic_tracing: 'bool',
};
const FINAL = new Set(['done', 'failed', 'cancelled']);
const POLL_MS = 2000;

const state = {
  scenes: [],        // [{name, summary}]
  defaults: {},
  feeds: new Map(),  // job id -> Feed
  pollOk: null,      // null before the first answer
  sweepCells: [],
};

// ---------- small helpers ----------

function fmtNum(x, digits = 3) {
  if (x === null || x === undefined || !Number.isFinite(x)) return '–';
  return Number(x.toPrecision(digits)).toString();
}

function fmtDuration(s) {
  if (s === null || s === undefined || !Number.isFinite(s) || s < 0) return '–';
  if (s < 1) return s < 0.05 ? '0 s' : `${s.toFixed(1)} s`;
  if (s < 60) return `${Math.round(s)} s`;
  if (s < 3600) return `${Math.floor(s / 60)} min ${Math.round(s % 60)} s`;
  return `${Math.floor(s / 3600)} h ${Math.round((s % 3600) / 60)} min`;
}

function shortId(id) { return id.length > 8 ? id.slice(-8) : id; }

function randomKey() {
  if (window.crypto && crypto.randomUUID) return crypto.randomUUID();
  return Array.from({ length: 4 }, () => Math.random().toString(36).slice(2, 10)).join('-');
}

// ---------- access token (a server started with --token) ----------

// Read once from the address's fragment (#token=...; a fragment never reaches a server or its
// logs), then kept for this tab in sessionStorage and taken out of the address bar. When the
// server answers 401 the page asks for it.
const TOKEN_KEY = 'render-server-token';
let token = (() => {
  const m = location.hash.match(/(?:^#|&)token=([^&]*)/);
  if (!m) return sessionStorage.getItem(TOKEN_KEY) || '';
  const t = decodeURIComponent(m[1]);
  sessionStorage.setItem(TOKEN_KEY, t);
  const rest = location.hash.slice(1).split('&').filter((kv) => !kv.startsWith('token=')).join('&');
  history.replaceState(null, '', location.pathname + location.search + (rest ? `#${rest}` : ''));
  return t;
})();

function authHeaders(headers = {}) {
  return token ? { ...headers, Authorization: `Bearer ${token}` } : headers;
}

// EventSource and links cannot send a header: the server takes the token from their query instead.
function withToken(url) {
  if (!token || !url) return url;
  return `${url}${url.includes('?') ? '&' : '?'}token=${encodeURIComponent(token)}`;
}

// Asks for the token once, however many requests were refused together. Resolves true when one was given.
let tokenPrompt = null;
function askToken() {
  if (!tokenPrompt) {
    tokenPrompt = new Promise((resolve) => setTimeout(() => {
      const t = window.prompt(token ? 'The access token was refused. Token:' : 'This render server needs an access token:', '');
      if (t && t.trim()) {
        token = t.trim();
        sessionStorage.setItem(TOKEN_KEY, token);
      }
      resolve(Boolean(t && t.trim()));
      setTimeout(() => { tokenPrompt = null; }, 1000);  // a burst of 401s gets one prompt
    }, 0));
  }
  return tokenPrompt;
}

// fetch + JSON. Resolves {ok, status, data}; resolves null when the server cannot be reached.
async function api(path, options = {}, retried = false) {
  let res;
  try {
    res = await fetch(path, { cache: 'no-store', ...options, headers: authHeaders(options.headers) });
  } catch (e) {
    connectionLost();
    return null;
  }
  if (res.status === 401 && !retried && await askToken()) return api(path, options, true);
  let data = null;
  const type = res.headers.get('Content-Type') || '';
  if (type.includes('application/json')) {
    try { data = await res.json(); } catch (e) { data = null; }
  }
  return { ok: res.ok, status: res.status, data };
}

function postJson(path, body, headers = {}) {
  return api(path, { method: 'POST', headers: { 'Content-Type': 'application/json', ...headers }, body: JSON.stringify(body) });
}

function apiError(r) {
  if (!r) return { message: 'The server cannot be reached.' };
  const e = r.data && r.data.error;
  return e ? { message: e.message, field: e.field } : { message: `The server answered ${r.status}.` };
}

function decodePng(b64) {
  const bin = atob(b64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; ++i) bytes[i] = bin.charCodeAt(i);
  return createImageBitmap(new Blob([bytes], { type: 'image/png' }), { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
}

// ---------- connection indicator ----------

function updateConn() {
  const el = $('#conn');
  let s;
  if (state.pollOk === null) s = 'connecting';
  else if (!state.pollOk) s = 'reconnecting';
  else s = [...state.feeds.values()].some((f) => f.conn === 'reconnecting') ? 'reconnecting' : 'live';
  el.dataset.state = s;
  el.textContent = s === 'live' ? 'live' : s === 'reconnecting' ? 'reconnecting…' : 'connecting…';
}

// A request could not reach the server: show it, and poll every second until it answers.
function connectionLost() {
  state.pollOk = false;
  updateConn();
  schedulePoll(1000);
}

// ---------- Feed: one job's pixels, status and error history, from its event stream ----------

class Feed {
  constructor(id) {
    this.id = id;
    this.views = new Set();
    this.status = null;
    this.history = [];
    this.canvas = document.createElement('canvas');
    this.ctx = this.canvas.getContext('2d');
    this.chain = Promise.resolve();  // decodes run in parallel, draws in arrival order
    this.painted = false;
    this.tiles = 0;
    this.ended = false;
    this.gone = false;
    this.es = null;
    this.conn = 'connecting';
    this.retry = null;
    this.sized = false;
    this.start();
  }

  attach(view) {
    this.views.add(view);
    if (this.sized) view.onFeed('size', this);
    if (this.painted) view.onFeed('pixels', this, { x: 0, y: 0, w: this.canvas.width, h: this.canvas.height });
    if (this.status) view.onFeed('status', this);
    view.onFeed('history', this);
    if (this.ended) view.onFeed('end', this);
    if (this.gone) view.onFeed('gone', this);
  }

  detach(view) {
    this.views.delete(view);
    if (this.views.size === 0) this.close();
  }

  close() {
    if (this.es) this.es.close();
    this.es = null;
    clearTimeout(this.retry);
    this.closed = true;
    state.feeds.delete(this.id);
    updateConn();
  }

  emit(type, detail) {
    for (const v of this.views) v.onFeed(type, this, detail);
  }

  setConn(c) {
    if (this.conn === c) return;
    this.conn = c;
    updateConn();
    this.emit('conn');
  }

  // Fetches the job (with its full error history); a finished job shows its stored image,
  // an unfinished one opens the event stream.
  async start() {
    clearTimeout(this.retry);
    const r = await api(`/api/jobs/${this.id}`);
    if (this.closed) return;
    if (!r) return this.scheduleRetry();
    if (r.status === 404) {
      this.gone = true;
      this.setConn('live');
      this.emit('gone');
      return;
    }
    if (!r.ok) return this.scheduleRetry();
    this.history = (r.data.error_history || []).map((p) => ({ seconds: p.seconds, spp: p.spp, error: p.error }));
    this.setSize(r.data.width, r.data.height);
    this.setStatus(r.data);
    this.emit('history');
    if (FINAL.has(r.data.state)) {
      this.setConn('live');
      // A finished job shows its stored image (it may have finished while we were away).
      if (!this.painted || r.data.state === 'done') await this.loadStoredImage();
      this.finish(r.data.state);
    } else if (!this.es) {
      this.openStream();
    }
  }

  scheduleRetry(ms = 2000) {
    clearTimeout(this.retry);
    this.setConn('reconnecting');
    this.retry = setTimeout(() => this.start(), ms);
  }

  openStream() {
    const es = new EventSource(withToken(`/api/jobs/${this.id}/events`));
    this.es = es;
    let hadError = false;
    es.onopen = () => {
      this.setConn('live');
      // Back after a drop (a server restart): re-fetch the history the stream does not repeat.
      if (hadError) this.refreshHistory();
    };
    es.onerror = () => {
      if (this.ended || this.closed) return;
      hadError = true;
      this.setConn('reconnecting');
      if (es.readyState === EventSource.CLOSED) {  // refused (an HTTP error): EventSource gives up, we don't
        this.es = null;
        this.scheduleRetry(3000);
      }
    };
    es.addEventListener('image', (e) => {
      const d = JSON.parse(e.data);
      this.paint(d.png, 0, 0, d.width, d.height, true);
    });
    es.addEventListener('tile', (e) => {
      const d = JSON.parse(e.data);
      this.paint(d.png, d.x, d.y, d.w, d.h, false);
    });
    es.addEventListener('status', (e) => {
      const s = JSON.parse(e.data);
      this.chain = this.chain.then(() => this.setStatus(s));
    });
    es.addEventListener('end', (e) => {
      const d = JSON.parse(e.data);
      es.close();
      this.es = null;
      this.chain = this.chain.then(async () => {
        if (!this.painted) await this.loadStoredImage();
        this.finish(d.state);
      });
    });
  }

  async refreshHistory() {
    const r = await api(`/api/jobs/${this.id}`);
    if (!r || !r.ok || this.closed) return;
    this.history = (r.data.error_history || []).map((p) => ({ seconds: p.seconds, spp: p.spp, error: p.error }));
    this.emit('history');
  }

  setSize(w, h) {
    if (!(w > 0 && h > 0) || (this.sized && this.canvas.width === w && this.canvas.height === h)) return;
    this.sized = true;
    this.canvas.width = w;
    this.canvas.height = h;
    this.painted = false;
    this.emit('size');
  }

  paint(b64, x, y, w, h, whole) {
    const decoded = decodePng(b64);
    decoded.catch(() => {});
    this.chain = this.chain.then(() => decoded).then((bmp) => {
      if (whole) this.setSize(w, h);
      this.ctx.drawImage(bmp, x, y);
      if (bmp.close) bmp.close();
      this.painted = true;
      if (!whole) this.tiles += 1;
      this.emit('pixels', { x, y, w, h });
    }).catch((err) => console.warn(`job ${this.id}: cannot draw a tile`, err));
  }

  async loadStoredImage() {
    try {
      const res = await fetch(`/api/jobs/${this.id}/image.png`, { cache: 'no-store', headers: authHeaders() });
      if (!res.ok) return;
      const bmp = await createImageBitmap(await res.blob(), { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
      this.setSize(bmp.width, bmp.height);
      this.ctx.drawImage(bmp, 0, 0);
      this.painted = true;
      this.emit('pixels', { x: 0, y: 0, w: bmp.width, h: bmp.height });
    } catch (e) {
      // No image (yet): the view keeps its placeholder.
    }
  }

  setStatus(s) {
    const prevState = this.status && this.status.state;
    this.status = s;
    const p = s.error_point;
    if (p) {
      const last = this.history[this.history.length - 1];
      if (last && p.seconds < last.seconds) this.history = [];  // the job started over (server restart)
      if (!last || p.seconds !== last.seconds || p.error !== last.error) {
        this.history.push({ seconds: p.seconds, spp: p.spp, error: p.error });
        this.emit('history');
      }
    } else if (s.state === 'queued' && this.history.length) {
      this.history = [];
      this.emit('history');
    }
    this.emit('status');
    if (prevState && prevState !== s.state) refreshJobsSoon();
  }

  finish(st) {
    if (this.status) this.status = { ...this.status, state: st };
    this.ended = true;
    this.setConn('live');
    this.emit('status');
    this.emit('end');
    refreshJobsSoon();
  }
}

function feedFor(id) {
  let f = state.feeds.get(id);
  if (!f) {
    f = new Feed(id);
    state.feeds.set(id, f);
  }
  return f;
}

// Copies the feed's pixels into a view's canvas (same size, so an exact copy).
function syncCanvas(canvas, feed, rect) {
  const ctx = canvas.getContext('2d');
  if (!rect) rect = { x: 0, y: 0, w: feed.canvas.width, h: feed.canvas.height };
  ctx.drawImage(feed.canvas, rect.x, rect.y, rect.w, rect.h, rect.x, rect.y, rect.w, rect.h);
}

function clearCanvas(canvas, w, h) {
  if (canvas.width !== w) canvas.width = w;
  if (canvas.height !== h) canvas.height = h;
  const ctx = canvas.getContext('2d');
  ctx.fillStyle = '#0b0d10';
  ctx.fillRect(0, 0, canvas.width, canvas.height);
}

// ---------- the main viewer ----------

const viewer = {
  feed: null,
  id: null,

  show(id) {
    if (this.id === id) return;
    if (this.feed) this.feed.detach(this);
    this.id = id;
    this.feed = null;
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
    $('#v-edit').disabled = true;
    setLink($('#v-png'), null);
    setLink($('#v-exr'), null);
    drawChart($('#v-chart'), []);
    const c = $('#v-canvas');
    clearCanvas(c, c.width, c.height);
    highlightRow();
    if (!id) return;
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
      syncCanvas(canvas, feed, rect);
      $('#v-placeholder').hidden = true;
      $('#viewer').dataset.tiles = String(feed.tiles);
    } else if (type === 'status') {
      this.renderStatus(feed.status);
    } else if (type === 'conn') {
      $('#viewer').dataset.conn = feed.conn;
    } else if (type === 'history') {
      drawChart($('#v-chart'), feed.history);
    } else if (type === 'end') {
      $('#viewer').dataset.ended = 'true';
      const st = feed.status && feed.status.state;
      if (!feed.painted) {
        $('#v-placeholder').textContent = st === 'cancelled' ? 'No image: the job was cancelled.'
          : st === 'failed' ? 'No image: the job failed.' : 'This job has no image.';
      }
    } else if (type === 'gone') {
      $('#v-state').hidden = true;
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
    if (s.state === 'failed') text = `failed${s.message ? `: ${s.message}` : ''}`;
    $('#v-progress-text').textContent = text;
    $('#v-spp').textContent = `${fmtNum(s.spp_done, 3)} / ${spec.spp}`;
    $('#v-spp').title = `${Number(s.samples || 0).toLocaleString()} samples taken`;
    $('#v-elapsed').textContent = fmtDuration(s.elapsed);
    $('#v-eta').textContent = s.state === 'running' ? fmtDuration(s.eta) : FINAL.has(s.state) ? '–' : '…';
    $('#v-error').textContent = fmtNum(s.error_estimate, 3);
    $('#v-cancel').disabled = FINAL.has(s.state);
    $('#v-edit').disabled = false;
    const hasImage = s.state === 'done' || (this.feed && this.feed.painted);
    setLink($('#v-png'), hasImage ? s.images.png : null, `render-${s.id}.png`);
    setLink($('#v-exr'), hasImage ? s.images.exr : null, `render-${s.id}.exr`);
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
  marker.style.left = `${fx * 100}%`;
  marker.style.top = `${fy * 100}%`;
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

// ---------- the error chart: log error against log seconds ----------

function drawChart(canvas, points) {
  const dpr = window.devicePixelRatio || 1;
  const cw = canvas.clientWidth || 300, ch = canvas.clientHeight || 120;
  if (canvas.width !== Math.round(cw * dpr) || canvas.height !== Math.round(ch * dpr)) {
    canvas.width = Math.round(cw * dpr);
    canvas.height = Math.round(ch * dpr);
  }
  const ctx = canvas.getContext('2d');
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, cw, ch);
  const css = getComputedStyle(document.documentElement);
  const muted = css.getPropertyValue('--muted').trim() || '#888';
  const grid = css.getPropertyValue('--line').trim() || '#333';
  const accent = css.getPropertyValue('--accent').trim() || '#f0a04b';
  ctx.font = '11px system-ui, sans-serif';
  const pts = points.filter((p) => p.seconds > 0 && p.error > 0);
  const L = 44, R = 10, T = 8, B = 20;
  const W = cw - L - R, H = ch - T - B;
  if (!pts.length) {
    ctx.fillStyle = muted;
    ctx.textAlign = 'center';
    ctx.fillText('the error estimate appears after the first passes', cw / 2, ch / 2);
    return;
  }
  const lx = pts.map((p) => Math.log10(p.seconds)), ly = pts.map((p) => Math.log10(p.error));
  // Log ranges padded a little around the data, at least one decade wide.
  const range = (vals) => {
    let lo = Math.min(...vals) - 0.08, hi = Math.max(...vals) + 0.08;
    if (hi - lo < 1) { const mid = (lo + hi) / 2; lo = mid - 0.5; hi = mid + 0.5; }
    return [lo, hi];
  };
  const [x0, x1] = range(lx), [y0, y1] = range(ly);
  const X = (v) => L + ((v - x0) / (x1 - x0)) * W;
  const Y = (v) => T + (1 - (v - y0) / (y1 - y0)) * H;
  const label = (v) => (v >= 1 ? String(Number(v.toPrecision(1))) : v.toPrecision(1));
  // Grid lines at 1..9 x 10^e; labels at 1, 2 and 5 x 10^e, thinned to what fits.
  const ticks = (lo, hi, maxLabels) => {
    const lines = [], labels = [];
    for (let e = Math.floor(lo); e <= Math.ceil(hi); ++e)
      for (let k = 1; k < 10; ++k) {
        const v = e + Math.log10(k);
        if (v < lo || v > hi) continue;
        lines.push({ v, major: k === 1 });
        if (k === 1 || k === 2 || k === 5) labels.push({ v, k, text: label(k * 10 ** e) });
      }
    let shown = labels;
    if (shown.length > maxLabels) shown = labels.filter((t) => t.k !== 2);
    if (shown.length > maxLabels) shown = labels.filter((t) => t.k === 1);
    return { lines, labels: shown };
  };

  ctx.strokeStyle = grid;
  ctx.lineWidth = 1;
  ctx.fillStyle = muted;
  const tx = ticks(x0, x1, Math.max(2, Math.floor(W / 60)));
  for (const t of tx.lines) {
    ctx.globalAlpha = t.major ? 1 : 0.35;
    ctx.beginPath(); ctx.moveTo(Math.round(X(t.v)) + 0.5, T); ctx.lineTo(Math.round(X(t.v)) + 0.5, T + H); ctx.stroke();
  }
  ctx.globalAlpha = 1;
  ctx.textAlign = 'center';
  for (const t of tx.labels) ctx.fillText(`${t.text} s`, Math.min(cw - 18, Math.max(L + 14, X(t.v))), ch - 5);
  const ty = ticks(y0, y1, Math.max(2, Math.floor(H / 22)));
  for (const t of ty.lines) {
    ctx.globalAlpha = t.major ? 1 : 0.35;
    ctx.beginPath(); ctx.moveTo(L, Math.round(Y(t.v)) + 0.5); ctx.lineTo(L + W, Math.round(Y(t.v)) + 0.5); ctx.stroke();
  }
  ctx.globalAlpha = 1;
  ctx.textAlign = 'right';
  for (const t of ty.labels) ctx.fillText(t.text, L - 6, Math.min(T + H, Math.max(T + 8, Y(t.v) + 4)));
  // Reference: Monte Carlo error falls as 1/sqrt(time), through the first point.
  ctx.save();
  ctx.beginPath();
  ctx.rect(L, T, W, H);
  ctx.clip();
  ctx.setLineDash([4, 4]);
  ctx.strokeStyle = muted;
  ctx.beginPath();
  ctx.moveTo(X(x0), Y(ly[0] - 0.5 * (x0 - lx[0])));
  ctx.lineTo(X(x1), Y(ly[0] - 0.5 * (x1 - lx[0])));
  ctx.stroke();
  ctx.restore();

  ctx.strokeStyle = accent;
  ctx.fillStyle = accent;
  ctx.lineWidth = 2;
  ctx.beginPath();
  pts.forEach((p, i) => (i ? ctx.lineTo(X(lx[i]), Y(ly[i])) : ctx.moveTo(X(lx[i]), Y(ly[i]))));
  ctx.stroke();
  pts.forEach((p, i) => { ctx.beginPath(); ctx.arc(X(lx[i]), Y(ly[i]), 2.5, 0, 2 * Math.PI); ctx.fill(); });
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
  return { spec, errors };
}

function clearErrors() {
  document.querySelectorAll('#job-form .error').forEach((e) => { e.textContent = ''; });
  document.querySelectorAll('#job-form [aria-invalid]').forEach((e) => e.removeAttribute('aria-invalid'));
}

function showError(field, message) {
  const line = field && document.getElementById(`err-${field}`);
  if (line) {
    line.textContent = message;
    const el = input(field);
    if (el) el.setAttribute('aria-invalid', 'true');
    // An error inside the closed "More options" must be seen.
    const details = line.closest('details');
    if (details) details.open = true;
  } else {
    $('#err-form').textContent = message;
  }
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
    const e = apiError(r);
    showError(e.field, e.message);
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
      const e = apiError(r);
      showError(e.field, e.message);
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
    // The API keeps the course's cropping by default; on the page a small image shows the whole view.
    input('keep_fov').checked = true;
  }
  showSceneSummary();
  return true;
}

// ---------- sweeps: four jobs around the current focal distance or aperture ----------

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
      const e = apiError(first);
      return showError(e.field, e.message);
    }
    const ids = [];
    for (const v of values) {
      const r = await postJson('/api/jobs', { ...base, [key]: v }, { 'Idempotency-Key': randomKey() });
      if (!r || !r.ok) {
        const e = apiError(r);
        showError(e.field, `Sweep stopped after ${ids.length} of 4 jobs: ${e.message}`);
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

class SweepCell {
  constructor(id, label) {
    this.id = id;
    this.el = document.createElement('figure');
    this.el.className = 'cell';
    this.el.dataset.id = id;
    this.el.dataset.state = 'queued';
    this.el.innerHTML = '<button type="button" class="cell-open" title="Open in the viewer"><canvas></canvas></button>' +
      '<figcaption><span class="cell-label"></span><span class="cell-state"></span></figcaption>' +
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
  $('#sweep').hidden = false;
  $('#sweep').scrollIntoView({ behavior: 'smooth', block: 'nearest' });
}

function closeSweep() {
  state.sweepCells.forEach((c) => c.dispose());
  state.sweepCells = [];
  $('#sweep-grid').innerHTML = '';
  $('#sweep').hidden = true;
}

// ---------- the job list ----------

const rows = new Map();  // id -> <tr>

function rowFor(id) {
  let tr = rows.get(id);
  if (tr) return tr;
  tr = document.createElement('tr');
  tr.dataset.id = id;
  tr.innerHTML = '<td class="mono id-col"></td><td class="scene"></td><td class="opt size"></td><td class="opt spp"></td>' +
    '<td><span class="badge"></span><div class="progress mini"><div class="bar"></div></div></td>' +
    '<td class="row-actions"><button type="button" data-action="open">Open</button>' +
    '<button type="button" data-action="cancel" class="danger">Cancel</button>' +
    '<a class="button" data-action="png">PNG</a><a class="button" data-action="exr">EXR</a></td>';
  rows.set(id, tr);
  return tr;
}

function renderJobs(jobs) {
  jobs.sort((a, b) => (a.id < b.id ? 1 : -1));  // ids sort by creation time: newest first
  const body = $('#job-rows');
  const seen = new Set();
  jobs.forEach((j, i) => {
    seen.add(j.id);
    const tr = rowFor(j.id);
    const spec = j.spec || {};
    tr.dataset.state = j.state;
    tr.cells[0].textContent = shortId(j.id);
    tr.cells[0].title = j.id;
    tr.cells[1].textContent = spec.scene || '';
    tr.cells[2].textContent = `${j.width}×${j.height}`;
    tr.cells[3].textContent = String(spec.spp);
    const badge = tr.querySelector('.badge');
    badge.textContent = j.state === 'running' ? `running ${Math.round(j.progress * 100)}%` : j.state;
    badge.dataset.state = j.state;
    tr.querySelector('.bar').style.width = `${Math.round((j.progress || 0) * 100)}%`;
    tr.querySelector('[data-action=cancel]').hidden = FINAL.has(j.state);
    setLink(tr.querySelector('[data-action=png]'), j.state === 'done' ? j.images.png : null, `render-${j.id}.png`);
    setLink(tr.querySelector('[data-action=exr]'), j.state === 'done' ? j.images.exr : null, `render-${j.id}.exr`);
    if (body.children[i] !== tr) body.insertBefore(tr, body.children[i] || null);
  });
  for (const [id, tr] of rows) {
    if (!seen.has(id)) { tr.remove(); rows.delete(id); }
  }
  $('#jobs-empty').hidden = jobs.length > 0;
  highlightRow();
}

function highlightRow() {
  for (const [id, tr] of rows) tr.classList.toggle('current', id === viewer.id);
}

async function cancelJob(id) {
  const r = await api(`/api/jobs/${id}`, { method: 'DELETE' });
  if (!r || !r.ok) {
    const e = apiError(r);
    if (viewer.id === id) viewer.note(`Cannot cancel: ${e.message}`, 'error');
    else alert(`Cannot cancel job ${shortId(id)}: ${e.message}`);
  }
  refreshJobs();
  refreshJobsSoon(400);
}

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

let refreshing = null;
async function refreshJobs() {
  if (refreshing) return refreshing;
  refreshing = (async () => {
    const r = await api('/api/jobs');
    if (!r || !r.ok) {
      connectionLost();
      return;
    }
    const wasDown = state.pollOk === false;
    state.pollOk = true;
    renderJobs(r.data.jobs || []);
    if (wasDown) onReconnected();
    updateConn();
    schedulePoll();
  })();
  try { await refreshing; } finally { refreshing = null; }
}

// The server is back: reload what may have changed, and restart the streams that gave up.
function onReconnected() {
  if (!state.scenes.length) loadScenes();
  for (const f of state.feeds.values()) {
    if (f.gone || f.ended) continue;
    if (!f.es || f.es.readyState === EventSource.CLOSED) {
      f.es = null;
      f.start();
    }
  }
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
  $('#v-cancel').addEventListener('click', () => viewer.id && cancelJob(viewer.id));
  $('#v-edit').addEventListener('click', () => {
    if (viewer.feed && viewer.feed.status) {
      fillForm(viewer.feed.status.spec);
      viewer.note('The form now holds this job\'s settings.', 'ok');
    }
  });
  $('#job-rows').addEventListener('click', (e) => {
    const b = e.target.closest('[data-action]');
    if (!b) return;
    const id = b.closest('tr').dataset.id;
    if (b.dataset.action === 'open') viewer.show(id);
    else if (b.dataset.action === 'cancel') cancelJob(id);
  });
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
  await refreshJobs();
  const m = location.hash.match(/job=([0-9a-f]+)/);
  if (m) viewer.show(m[1]);
  else {
    // Show what is rendering now, else the newest job.
    const list = [...rows.values()].map((tr) => ({ id: tr.dataset.id, state: tr.dataset.state }));
    const pick = list.find((j) => j.state === 'running') || list[0];
    if (pick) viewer.show(pick.id);
  }
  scheduleCheck();
}

document.addEventListener('DOMContentLoaded', init);
