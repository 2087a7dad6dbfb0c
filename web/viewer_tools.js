// The viewer's tools, as in tev or Blender's image editor: exposure in stops and a display mapping
// (the course's PNG curve, sRGB, linear) applied to the job's float pixels (GET /pixels), the
// sample-rate image with its legend, 1:1 zoom with drag to pan, and the pixel under the cursor.
'use strict';

// The course's PNG curve (renderer/util/image.cpp, tonemap_course) in float32 steps, so that at
// exposure 0 it gives the PNG's bytes: (uint8)(clamp((sqrt(2) v)^(1/2.2), 0, 1) * 255).
const F_SQRT2 = Math.fround(1.41421356);
const F_INV_GAMMA = Math.fround(1 / 2.2);
function courseByte(v) {
  if (!(v > 0)) return 0;
  const t = Math.fround(Math.pow(Math.fround(F_SQRT2 * Math.fround(v)), F_INV_GAMMA));
  return Math.floor(Math.fround(Math.min(1, t) * 255));
}

function srgbByte(v) {
  if (!(v > 0)) return 0;
  const c = v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055;
  return Math.round(Math.min(1, c) * 255);
}

function linearByte(v) { return v > 0 ? Math.round(Math.min(1, v) * 255) : 0; }

const MAPPINGS = { course: courseByte, srgb: srgbByte, linear: linearByte };

// The course's sample-rate colours (renderer/film.cpp, rate_colour: blue = few, green = half,
// red = all of spp), written through the PNG curve as _rate.png is.
function rateRgb(count, spp) {
  const r = Math.fround(count / spp);
  const c = r <= 0.5 ? [0, 2 * r, 1 - 2 * r] : [2 * r - 1, 2 - 2 * r, 0];
  return c.map(courseByte);
}

// A finished job's float pixels are fetched once, when it ends; a running job's only while a tool
// needs them, at most every REFETCH_MS: they are 16 bytes a pixel (2.7 MB at 480x360) against the
// stream's few PNG tiles, and without a tool the tiles already show the course's mapping.
const REFETCH_MS = 2000;

const tools = {
  data: null,        // {id, w, h, px: Float32Array (r, g, b, count) a pixel, min, max}
  stale: true,       // tiles arrived after the data was fetched
  missing: null,     // a finished job whose pixels the server does not have: not asked again
  fetching: null,    // the request in flight
  lastFetch: 0,
  timer: null,
  exposure: 0,
  mapping: 'course',
  rate: false,
  zoom: 'fit',       // or '1:1'
  pan: { x: 0, y: 0 },
  drag: null,
  dragged: false,

  // Whether the canvas shows the float pixels through the tools rather than the stream's PNG tiles.
  active() { return this.exposure !== 0 || this.mapping !== 'course' || this.rate; },

  reset() {
    this.data = null;
    this.missing = null;
    this.stale = true;
    clearTimeout(this.timer);
    this.timer = null;
    this.pan = { x: 0, y: 0 };
    $('#v-readout').textContent = '';
    $('#v-tools').dataset.data = 'none';
    this.showLegend();
    this.applyZoom();
  },

  // The job's picture changed (new tiles); with `ended`, it will not change again.
  onPixels(ended) {
    this.stale = true;
    if (ended || this.active()) this.request();
  },

  // Fetches the pixels now, or once REFETCH_MS after the last fetch.
  request() {
    const id = viewer.id;
    if (!id || this.fetching || this.timer || this.missing === id) return;
    const wait = this.lastFetch + REFETCH_MS - performance.now();
    const ended = viewer.feed && viewer.feed.ended;
    if (wait > 0 && !ended) {
      this.timer = setTimeout(() => { this.timer = null; this.request(); }, wait);
      return;
    }
    this.fetching = this.load(id).finally(() => {
      this.fetching = null;
      if (this.stale && viewer.id === id && (this.active() || (viewer.feed && viewer.feed.ended))) this.request();
    });
  },

  async load(id) {
    this.lastFetch = performance.now();
    this.stale = false;
    let res;
    try {
      res = await fetch(`/api/jobs/${id}/pixels`, { cache: 'no-store', headers: authHeaders() });
    } catch (e) {
      return;  // the connection indicator says so; the next tile asks again
    }
    if (res.status === 404 && viewer.feed && viewer.feed.ended && viewer.id === id) {
      this.missing = id;
      this.missingText = `No float pixels for this job: ${apiError({ status: 404, data: await res.json().catch(() => null) }).message}`;
      $('#v-tools').dataset.data = 'missing';
    }
    if (!res.ok || viewer.id !== id) return;
    const w = Number(res.headers.get('X-Image-Width')), h = Number(res.headers.get('X-Image-Height'));
    const buf = await res.arrayBuffer();
    if (viewer.id !== id || buf.byteLength !== w * h * 16) return;
    const px = new Float32Array(buf);  // typed arrays read the host's byte order: little-endian on every browser host we serve
    let min = Infinity, max = 0;
    for (let i = 3; i < px.length; i += 4) { min = Math.min(min, px[i]); max = Math.max(max, px[i]); }
    this.data = { id, w, h, px, min, max };
    $('#v-tools').dataset.data = 'loaded';
    $('#v-tools').dataset.samples = String(Math.round(px.reduce((s, v, i) => (i % 4 === 3 ? s + v : s), 0)));
    this.showLegend();
    this.paint();
  },

  // Paints the canvas from the float pixels through exposure and mapping, or the rate colours.
  paint() {
    const d = this.data;
    if (!this.active() || !d || d.id !== viewer.id) return;
    const canvas = $('#v-canvas');
    if (canvas.width !== d.w || canvas.height !== d.h) { canvas.width = d.w; canvas.height = d.h; }
    const ctx = canvas.getContext('2d');
    const img = ctx.createImageData(d.w, d.h);
    const out = img.data, px = d.px, n = d.w * d.h;
    const spp = (viewer.feed && viewer.feed.status && viewer.feed.status.spec.spp) || d.max || 1;
    const map = MAPPINGS[this.mapping], gain = Math.fround(2 ** this.exposure);
    for (let i = 0; i < n; ++i) {
      const rgb = this.rate ? rateRgb(px[4 * i + 3], spp)
        : [map(Math.fround(px[4 * i] * gain)), map(Math.fround(px[4 * i + 1] * gain)), map(Math.fround(px[4 * i + 2] * gain))];
      out[4 * i] = rgb[0];
      out[4 * i + 1] = rgb[1];
      out[4 * i + 2] = rgb[2];
      out[4 * i + 3] = 255;
    }
    ctx.putImageData(img, 0, 0);
    $('#v-tools').dataset.painted = `${this.mapping}:${this.exposure}:${this.rate}`;
  },

  // A tool changed: the float pixels paint the canvas, or the stream's picture comes back.
  changed() {
    $('#v-tools').dataset.painted = '';
    if (this.active()) {
      if (this.data && this.data.id === viewer.id) this.paint();
      if (!this.data || this.stale) this.request();
    } else if (viewer.feed && viewer.feed.painted) {
      syncCanvas($('#v-canvas'), viewer.feed);
      $('#v-tools').dataset.painted = 'stream';
    }
    this.showLegend();
  },

  showLegend() {
    const legend = $('#v-legend');
    legend.hidden = !this.rate;
    if (!this.rate) return;
    const spp = viewer.feed && viewer.feed.status ? viewer.feed.status.spec.spp : null;
    $('#v-legend-max').textContent = spp ? `${spp} spp` : 'spp';
    const ramp = $('#v-legend-ramp');
    if (!ramp.dataset.drawn) {
      const ctx = ramp.getContext('2d'), img = ctx.createImageData(ramp.width, 1);
      for (let x = 0; x < ramp.width; ++x) {
        const c = rateRgb(x, ramp.width - 1);
        img.data.set([c[0], c[1], c[2], 255], 4 * x);
      }
      ctx.putImageData(img, 0, 0);
      ramp.dataset.drawn = 'true';
    }
    const d = this.data;
    $('#v-legend-range').textContent = d && d.id === viewer.id
      ? `samples taken: ${Math.round(d.min)} to ${Math.round(d.max)} a pixel` : 'loading the sample counts…';
  },

  // ---------- zoom and pan ----------

  applyZoom() {
    const canvas = $('#v-canvas'), wrap = $('#v-wrap');
    wrap.dataset.zoom = this.zoom;
    $('#v-zoom-fit').setAttribute('aria-pressed', String(this.zoom === 'fit'));
    $('#v-zoom-1').setAttribute('aria-pressed', String(this.zoom === '1:1'));
    if (this.zoom === 'fit') {
      canvas.style.width = canvas.style.height = canvas.style.left = canvas.style.top = '';
      return;
    }
    const dpr = window.devicePixelRatio || 1;
    const w = canvas.width / dpr, h = canvas.height / dpr;
    // Centred, then panned; a quarter of the picture always stays in view.
    const maxX = Math.max(0, (w - wrap.clientWidth) / 2) + wrap.clientWidth / 4;
    const maxY = Math.max(0, (h - wrap.clientHeight) / 2) + wrap.clientHeight / 4;
    this.pan.x = Math.max(-maxX, Math.min(maxX, this.pan.x));
    this.pan.y = Math.max(-maxY, Math.min(maxY, this.pan.y));
    // On whole device pixels, or the browser resamples the picture it should show as it is.
    const r = wrap.getBoundingClientRect();
    const snap = (origin, at) => Math.round((origin + at) * dpr) / dpr - origin;
    canvas.style.width = `${w}px`;
    canvas.style.height = `${h}px`;
    canvas.style.left = `${snap(r.left, (wrap.clientWidth - w) / 2 + this.pan.x)}px`;
    canvas.style.top = `${snap(r.top, (wrap.clientHeight - h) / 2 + this.pan.y)}px`;
  },

  setZoom(z) {
    this.zoom = z;
    this.pan = { x: 0, y: 0 };
    $('#v-marker').hidden = true;
    this.applyZoom();
  },

  // ---------- the pixel under the cursor ----------

  readout(ev) {
    const canvas = $('#v-canvas');
    const rect = canvas.getBoundingClientRect();
    const x = Math.floor(((ev.clientX - rect.left) / rect.width) * canvas.width);
    const y = Math.floor(((ev.clientY - rect.top) / rect.height) * canvas.height);
    const out = $('#v-readout');
    if (!(x >= 0 && y >= 0 && x < canvas.width && y < canvas.height) || !viewer.id) {
      out.textContent = '';
      return;
    }
    const d = this.data;
    if (this.missing === viewer.id) {
      out.textContent = this.missingText;
      return;
    }
    if (!d || d.id !== viewer.id) {
      out.textContent = `(${x}, ${y}) …`;
      this.request();
      return;
    }
    if (this.stale) this.request();
    const i = 4 * (y * d.w + x);
    const f = (v) => v.toPrecision(4);
    out.textContent = `(${x}, ${y})  R ${f(d.px[i])}  G ${f(d.px[i + 1])}  B ${f(d.px[i + 2])}  · ${d.px[i + 3]} samples`;
    Object.assign(out.dataset, { x, y, r: d.px[i], g: d.px[i + 1], b: d.px[i + 2], n: d.px[i + 3] });
  },
};

function initViewerTools() {
  const exposure = $('#v-exposure'), number = $('#v-exposure-n');
  const setExposure = (v) => {
    tools.exposure = Number.isFinite(v) ? Math.max(-10, Math.min(10, v)) : 0;
    exposure.value = String(tools.exposure);
    number.value = String(tools.exposure);
    tools.changed();
  };
  exposure.addEventListener('input', () => setExposure(Number(exposure.value)));
  number.addEventListener('change', () => setExposure(Number(number.value)));
  $('#v-exposure-reset').addEventListener('click', () => setExposure(0));
  $('#v-mapping').addEventListener('change', (e) => { tools.mapping = e.target.value; tools.changed(); });
  $('#v-rate').addEventListener('change', (e) => { tools.rate = e.target.checked; tools.changed(); });
  $('#v-zoom-fit').addEventListener('click', () => tools.setZoom('fit'));
  $('#v-zoom-1').addEventListener('click', () => tools.setZoom('1:1'));

  const wrap = $('#v-wrap');
  wrap.addEventListener('pointerdown', (e) => {
    tools.dragged = false;
    if (tools.zoom !== '1:1' || e.button !== 0) return;
    tools.drag = { x: e.clientX, y: e.clientY, pan: { ...tools.pan } };
    wrap.setPointerCapture(e.pointerId);
  });
  wrap.addEventListener('pointermove', (e) => {
    if (tools.drag) {
      const dx = e.clientX - tools.drag.x, dy = e.clientY - tools.drag.y;
      if (Math.abs(dx) + Math.abs(dy) > 3) tools.dragged = true;
      tools.pan = { x: tools.drag.pan.x + dx, y: tools.drag.pan.y + dy };
      $('#v-marker').hidden = true;
      tools.applyZoom();
    }
    tools.readout(e);
  });
  const endDrag = () => { tools.drag = null; };
  wrap.addEventListener('pointerup', endDrag);
  wrap.addEventListener('pointercancel', endDrag);
  wrap.addEventListener('pointerleave', () => { if (!tools.drag) $('#v-readout').textContent = ''; });
  // A drag that panned is not a click to focus.
  wrap.addEventListener('click', (e) => {
    if (tools.dragged) {
      e.stopPropagation();
      tools.dragged = false;
    }
  }, true);
}
