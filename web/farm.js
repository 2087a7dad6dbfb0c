// The render farm on the page: when the server renders through Redis (--queue redis://...), its
// /api/health carries a `farm` object, and the Farm panel (and a badge in the top bar) shows how
// the farm is secured, its workers, and the passes it rejected. Hidden for the embedded backend.
// Worker names, reasons and job ids come from Redis, which others can write: all go in as text.
'use strict';

const FARM_POLL_MS = 3000;

const farmView = { timer: null, busy: false, last: '' };

// A count from the server, or null when it is not a finite number.
function farmCount(x) { return Number.isFinite(x) ? x : null; }

// A count as text ('–' when the server did not send a number).
function fmtCount(x) { return Number.isFinite(x) ? String(x) : '–'; }

// Any value as display text (null and undefined: empty).
function farmText(x) { return x === null || x === undefined ? '' : String(x); }

// A <td> holding `text` as text, with an optional class and title.
function farmCell(text, cls = '', title = '') {
  const td = document.createElement('td');
  td.textContent = farmText(text);
  if (cls) td.className = cls;
  if (title) td.title = title;
  return td;
}

function fmtAgo(s) { return Number.isFinite(s) && s >= 0 ? `${fmtDuration(s)} ago` : '–'; }

// How the farm is secured: {level: 'ok' | 'warn' | 'bad', text, tag (the badge's word)}.
function farmSecurity(f) {
  const login = f.authenticated ? 'The server logs in to Redis.' : 'The server does not log in to Redis.';
  if (f.insecure) {
    return { level: 'bad', tag: 'insecure', text: 'Insecure farm (--insecure-farm): Redis is not on loopback and passes are ' +
      `NOT signed, so anyone who can reach Redis can put pixels into renders. ${login}` };
  }
  if (!f.signed) return { level: 'warn', tag: 'unsigned', text: `Passes are NOT signed: any Redis client can put pixels into renders. ${login}` };
  return { level: 'ok', tag: '', text: `Passes are signed (HMAC-SHA256). ${login}` };
}

// Shows the farm object `f` from /api/health; null or absent hides the panel and the badge.
function showFarm(f) {
  const panel = $('#farm'), badge = $('#farm-badge');
  const has = Boolean(f && typeof f === 'object');
  panel.hidden = !has;
  badge.hidden = !has;
  if (!has) {
    farmView.last = '';
    return;
  }
  const key = JSON.stringify(f);
  if (key === farmView.last) return;  // unchanged: the rows (and any selection in them) stay
  farmView.last = key;

  const workers = Array.isArray(f.workers) ? f.workers.filter((w) => w && typeof w === 'object') : [];
  const rejections = Array.isArray(f.rejections) ? f.rejections.filter((r) => r && typeof r === 'object') : [];
  const live = workers.filter((w) => w.live === true).length;
  const sec = farmSecurity(f);

  $('#farm-queue').textContent = farmText(f.queue);
  const line = $('#farm-security');
  line.dataset.level = sec.level;
  if (line.textContent !== sec.text) line.textContent = sec.text;  // announced only when it changes

  $('#farm-live').textContent = `${live} of ${workers.length}`;
  $('#farm-merged').textContent = fmtCount(f.passes_merged);
  $('#farm-rejected').textContent = fmtCount(f.rejected);
  $('#farm-rejected-box').dataset.bad = String(farmCount(f.rejected) > 0);

  $('#farm-workers tbody').replaceChildren(...workers.map((w) => {
    const tr = document.createElement('tr');
    const heard = farmCount(w.last_heard_seconds);
    tr.dataset.live = String(w.live === true);
    tr.append(
      farmCell(w.name, 'farm-name'),
      farmCell(fmtCount(w.threads), 'num'),
      farmCell(w.live === true ? 'live' : fmtAgo(heard), 'farm-heard', heard === null ? '' : `last heard ${fmtAgo(heard)}`),
      farmCell(fmtCount(w.passes), 'num'),
      farmCell(fmtCount(w.rejected), farmCount(w.rejected) > 0 ? 'num bad' : 'num'));
    return tr;
  }));
  $('#farm-workers').hidden = workers.length === 0;
  $('#farm-no-workers').hidden = workers.length > 0;

  $('#farm-rejections tbody').replaceChildren(...rejections.map((r) => {
    const tr = document.createElement('tr');
    const job = farmText(r.job);
    tr.append(
      farmCell(fmtAgo(farmCount(r.seconds_ago)), 'farm-when'),
      farmCell(r.worker, 'farm-name'),
      farmCell(shortId(job), 'mono', job),
      farmCell(r.reason, 'farm-reason'));
    return tr;
  }));
  $('#farm-rejections').hidden = rejections.length === 0;
  $('#farm-no-rejections').hidden = rejections.length > 0;

  badge.dataset.level = sec.level;
  badge.textContent = `Farm · ${live} live${sec.tag ? ` · ${sec.tag}` : ''}`;
  badge.title = sec.text;
}

// One look at /api/health, then the next in FARM_POLL_MS; none while the tab is hidden (the
// visibilitychange handler looks again when it shows).
async function pollFarm() {
  clearTimeout(farmView.timer);
  farmView.timer = null;
  if (document.hidden || farmView.busy) return;
  farmView.busy = true;
  try {
    const r = await api('/api/health');
    if (r && r.ok && r.data) showFarm(r.data.farm);  // unreachable: the panel keeps its last state
  } finally {
    farmView.busy = false;
  }
  if (!document.hidden) farmView.timer = setTimeout(pollFarm, FARM_POLL_MS);
}

function initFarm() {
  document.addEventListener('visibilitychange', () => {
    if (!document.hidden) pollFarm();
  });
  $('#farm-badge').addEventListener('click', () => $('#farm').scrollIntoView({ behavior: 'smooth', block: 'start' }));
}
