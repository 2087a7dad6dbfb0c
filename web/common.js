// What every part of the render-job page shares: the page state, small formatting helpers, the
// access token, fetch + JSON against the API, and the connection indicator. Loaded first (see
// index.html: classic scripts, deferred, in order; their top-level names are shared).
'use strict';

const $ = (sel) => document.querySelector(sel);

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

// A point or direction, short: (0.12, 1, -4.5); rounding noise (2.9e-16) reads 0.
function fmtVec(v) { return `(${(v || []).map((x) => fmtNum(Math.abs(x) < 1e-9 ? 0 : x, 3)).join(', ')})`; }

// A camera ({position, target, up, vfov}) in one line; null is the scene's own framing.
function fmtCamera(c) {
  if (!c) return 'the scene\'s own framing';
  return `from ${fmtVec(c.position)} at ${fmtVec(c.target)}${c.vfov ? `, ${fmtNum(c.vfov, 3)}°` : ''}`;
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

// fetch + JSON. Resolves {ok, status, data}; resolves null when the server cannot be reached or
// its JSON answer is cut short.
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
    try {
      data = await res.json();
    } catch (e) {
      connectionLost();  // a JSON answer cut short: the server went away mid-answer
      return null;
    }
  }
  return { ok: res.ok, status: res.status, data };
}

function postJson(path, body, headers = {}) {
  return api(path, { method: 'POST', headers: { 'Content-Type': 'application/json', ...headers }, body: JSON.stringify(body) });
}

// An error answer as {message, field, errors}: `errors` lists every invalid field ({field,
// message}) where the server sent error.errors, else the one error.field / error.message.
function apiError(r) {
  if (!r) return { message: 'The server cannot be reached.', errors: [] };
  const e = r.data && r.data.error;
  if (!e) return { message: `The server answered ${r.status}.`, errors: [] };
  const list = Array.isArray(e.errors) && e.errors.length ? e.errors.filter((x) => x && x.message)
    : [{ field: e.field, message: e.message }];
  return { message: e.message, field: e.field, errors: list };
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

// What a scene's loader ignored or defaulted (a scene summary's or a job's `warnings`), as a
// collapsed list under `el` (a <details> with a <summary> and a <ul>); hidden when there is none.
function showWarnings(el, warnings) {
  const list = Array.isArray(warnings) ? warnings : [];
  el.hidden = list.length === 0;
  el.querySelector('summary').textContent =
    `${list.length} loader warning${list.length === 1 ? '' : 's'}: what the scene file asks for that is not rendered as written`;
  const ul = el.querySelector('ul');
  ul.replaceChildren(...list.map((w) => Object.assign(document.createElement('li'), { textContent: w })));
}
