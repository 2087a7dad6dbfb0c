// Feed: one job's pixels, status and error history from its event stream (one EventSource, one
// decode per job, however many canvases show it), and copying them into a canvas. A denoised job
// has two pictures: the raw render (image and tile events) and the denoised one (the last
// 'denoised' event with the raw tiles since painted over it, so it refreshes at pass ends).
'use strict';

class Feed {
  constructor(id) {
    this.id = id;
    this.views = new Set();
    this.status = null;
    this.history = [];
    this.canvas = document.createElement('canvas');  // the raw render
    this.ctx = this.canvas.getContext('2d');
    this.denoised = null;  // a canvas once a denoised picture came, same size as the raw one
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

  // The job is live again (continued to render more): its stream opens anew, from the kept picture.
  reopen() {
    if (this.closed || this.es) return;
    this.ended = false;
    this.emit('reopen');
    this.start();
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
    es.addEventListener('denoised', (e) => {
      const decoded = decodePng(JSON.parse(e.data).png);
      decoded.catch(() => {});
      this.chain = this.chain.then(() => decoded).then((bmp) => this.setDenoised(bmp))
        .catch((err) => console.warn(`job ${this.id}: cannot draw a denoised picture`, err));
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
    this.denoised = null;
    this.emit('size');
  }

  // The picture a view asks for: 'raw', or 'denoised' (the raw one until a denoised one came).
  picture(which) {
    return which === 'raw' || !this.denoised ? this.canvas : this.denoised;
  }

  // A whole denoised picture: the denoised view starts over from it.
  setDenoised(bmp) {
    const w = this.canvas.width, h = this.canvas.height;
    const fits = bmp.width === w && bmp.height === h;  // else from before a resize: stale
    if (fits && !this.denoised) {
      this.denoised = document.createElement('canvas');
      this.denoised.width = w;
      this.denoised.height = h;
    }
    if (fits) this.denoised.getContext('2d').drawImage(bmp, 0, 0);
    if (bmp.close) bmp.close();
    if (fits) this.emit('pixels', { x: 0, y: 0, w, h, denoised: true });
  }

  paint(b64, x, y, w, h, whole) {
    const decoded = decodePng(b64);
    decoded.catch(() => {});
    this.chain = this.chain.then(() => decoded).then((bmp) => {
      if (whole) this.setSize(w, h);
      this.ctx.drawImage(bmp, x, y);
      // Raw tiles cover the denoised picture as they come, until the next pass end's.
      if (this.denoised && !whole) this.denoised.getContext('2d').drawImage(bmp, x, y);
      if (bmp.close) bmp.close();
      this.painted = true;
      if (!whole) this.tiles += 1;
      this.emit('pixels', { x, y, w, h });
    }).catch((err) => console.warn(`job ${this.id}: cannot draw a tile`, err));
  }

  // The stored image; a job with denoised pictures has two: image.png is the denoised one.
  async loadStoredImage() {
    const dn = this.status && this.status.denoise;
    const denoised = dn && dn.frames > 0;
    const bmp = await fetchBitmap(denoised ? dn.raw_images.png : `/api/jobs/${this.id}/image.png`);
    if (!bmp) return;  // no image (yet): the view keeps its placeholder
    this.setSize(bmp.width, bmp.height);
    this.ctx.drawImage(bmp, 0, 0);
    this.painted = true;
    this.emit('pixels', { x: 0, y: 0, w: bmp.width, h: bmp.height });
    if (!denoised) return;
    const dbmp = await fetchBitmap(`/api/jobs/${this.id}/image.png`);
    if (dbmp) this.setDenoised(dbmp);
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
    } else if (s.state === 'queued' && this.history.length && !s.error_history) {
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

// An image of the API as an ImageBitmap, its bytes as they are; null when there is none.
async function fetchBitmap(url) {
  try {
    const res = await fetch(url, { cache: 'no-store', headers: authHeaders() });
    if (!res.ok) return null;
    return await createImageBitmap(await res.blob(), { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
  } catch (e) {
    return null;
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

// Copies the feed's picture ('denoised' where it has one, or 'raw') into a view's canvas (same
// size, so an exact copy).
function syncCanvas(canvas, feed, rect, which = 'denoised') {
  const ctx = canvas.getContext('2d');
  if (!rect) rect = { x: 0, y: 0, w: feed.canvas.width, h: feed.canvas.height };
  ctx.drawImage(feed.picture(which), rect.x, rect.y, rect.w, rect.h, rect.x, rect.y, rect.w, rect.h);
}

function clearCanvas(canvas, w, h) {
  if (canvas.width !== w) canvas.width = w;
  if (canvas.height !== h) canvas.height = h;
  const ctx = canvas.getContext('2d');
  ctx.fillStyle = '#0b0d10';
  ctx.fillRect(0, 0, canvas.width, canvas.height);
}

// Resizes a canvas to w x h keeping its picture, scaled: what was seen stays until new tiles cover it.
function resizeKeeping(canvas, w, h) {
  if (canvas.width === w && canvas.height === h) return;
  const old = document.createElement('canvas');
  old.width = canvas.width;
  old.height = canvas.height;
  old.getContext('2d').drawImage(canvas, 0, 0);
  canvas.width = w;
  canvas.height = h;
  canvas.getContext('2d').drawImage(old, 0, 0, w, h);
}
