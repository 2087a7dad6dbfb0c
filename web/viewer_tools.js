// The viewer's tools, as in tev or Blender's image editor: exposure in stops and a display mapping
// (the course's PNG curve, sRGB, linear) applied to the job's float pixels (GET /pixels), the
// sample-rate image with its legend, zoom (the wheel around the cursor, fit to 32x, nearest texels
// past 1:1; drag to pan), what the mouse does on the image, and the pixel under the cursor.
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
const MAX_ZOOM = 32;  // device pixels an image pixel, at most

// A wheel event's travel in pixels, whatever unit the browser gave it in.
function wheelPixels(e) {
  return e.deltaY * (e.deltaMode === 1 ? 33 : e.deltaMode === 2 ? 800 : 1);
}

const MOUSE_HINTS = {
  camera: 'Drag to orbit · shift- or right-drag to pan · wheel to dolly · click to focus',
  zoom: 'Wheel to zoom around the cursor (to 32×) · drag to pan the zoomed picture · click to focus',
};

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
  zoom: 'fit',       // 'fit', '1:1' or a magnification (device pixels an image pixel)
  mouse: 'camera',   // what the mouse does on the image: 'camera' (camera.js) or 'zoom'
  pan: { x: 0, y: 0 },
  drag: null,
  dragged: false,

  // Whether the canvas shows the float pixels through the tools rather than the stream's PNG tiles.
  active() { return this.exposure !== 0 || this.mapping !== 'course' || this.rate; },

  reset() {
    this.resetData();
    this.pan = { x: 0, y: 0 };
    this.applyZoom();
  },

  // Another job's picture, seen through the same zoom (a camera move's preview).
  resetData() {
    this.data = null;
    this.missing = null;
    this.stale = true;
    clearTimeout(this.timer);
    this.timer = null;
    $('#v-readout').textContent = '';
    $('#v-tools').dataset.data = 'none';
    this.showLegend();
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
      syncCanvas($('#v-canvas'), viewer.feed, null, denoiseView.choice);
      $('#v-tools').dataset.painted = 'stream';
    }
    this.showLegend();
    showPicture();
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

  // Device pixels an image pixel, now.
  magnification() {
    if (this.zoom === '1:1') return 1;
    if (this.zoom !== 'fit') return this.zoom;
    return ($('#v-wrap').clientWidth / $('#v-canvas').width) * (window.devicePixelRatio || 1);
  },

  applyZoom() {
    const canvas = $('#v-canvas'), wrap = $('#v-wrap');
    const fit = this.zoom === 'fit';
    const dpr = window.devicePixelRatio || 1;
    const m = this.magnification();
    wrap.dataset.zoom = fit ? 'fit' : this.zoom === '1:1' ? '1:1' : 'zoomed';
    wrap.dataset.scale = String(Number(m.toFixed(4)));
    $('#v-zoom-fit').setAttribute('aria-pressed', String(fit));
    $('#v-zoom-1').setAttribute('aria-pressed', String(this.zoom === '1:1'));
    $('#v-zoom-level').textContent = `${fmtNum(m, 3)}×`;
    // Texels as squares once zoomed past 1:1; when fitted, only from 2x (a blur reads better below).
    canvas.style.imageRendering = (fit ? m / dpr >= 2 : m > 1.0001) ? 'pixelated' : 'auto';
    this.showMouse();
    if (fit) {
      canvas.style.width = canvas.style.height = canvas.style.left = canvas.style.top = '';
      return;
    }
    const w = (canvas.width * m) / dpr, h = (canvas.height * m) / dpr;
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

  // Zooms by `factor` keeping the image point under (cx, cy) (client pixels) where it is.
  zoomAt(factor, cx, cy) {
    const canvas = $('#v-canvas'), wrap = $('#v-wrap');
    const dpr = window.devicePixelRatio || 1;
    const fitM = (wrap.clientWidth / canvas.width) * dpr;
    const m = Math.min(Math.max(MAX_ZOOM, fitM), this.magnification() * factor);
    $('#v-marker').hidden = true;
    if (m <= fitM * 1.0001) {
      this.setZoom('fit');
      return;
    }
    const r = canvas.getBoundingClientRect(), wr = wrap.getBoundingClientRect();
    const u = ((cx - r.left) / r.width) * canvas.width, v = ((cy - r.top) / r.height) * canvas.height;
    const s = m / dpr;
    this.zoom = Math.abs(m - 1) < 1e-4 ? '1:1' : m;
    this.pan = {
      x: cx - wr.left - u * s - (wrap.clientWidth - canvas.width * s) / 2,
      y: cy - wr.top - v * s - (wrap.clientHeight - canvas.height * s) / 2,
    };
    this.applyZoom();
  },

  // The picture changed size (a camera move's smaller preview): it keeps its size on screen.
  onResize(oldWidth, newWidth) {
    if (typeof this.zoom === 'number' && oldWidth > 0 && newWidth > 0 && oldWidth !== newWidth)
      this.zoom *= oldWidth / newWidth;
  },

  // ---------- what the mouse does ----------

  // 'camera' where the shown job's view is known (camera.js), else 'zoom'.
  mouseMode() { return this.mouse === 'camera' && nav.available() ? 'camera' : 'zoom'; },

  setMouse(mode) {
    this.mouse = mode;
    this.showMouse();
  },

  showMouse() {
    const mode = this.mouseMode();
    $('#v-wrap').dataset.mouse = mode;
    const cam = $('#v-mouse-camera');
    cam.setAttribute('aria-pressed', String(mode === 'camera'));
    cam.disabled = !nav.available();
    cam.title = cam.disabled ? 'Open a job whose view the server reports to move its camera' : MOUSE_HINTS.camera;
    $('#v-mouse-zoom').setAttribute('aria-pressed', String(mode === 'zoom'));
    $('#v-mouse-hint').textContent = MOUSE_HINTS[mode];
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
    // The float pixels are the raw render's, whichever picture a denoised job shows.
    const raw = viewer.feed && viewer.feed.status && viewer.feed.status.denoise ? ' (raw render)' : '';
    out.textContent = `(${x}, ${y})  R ${f(d.px[i])}  G ${f(d.px[i + 1])}  B ${f(d.px[i + 2])}  · ${d.px[i + 3]} samples${raw}`;
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
  // 1:1 is for looking at pixels: the mouse zooms and pans the picture from then on.
  $('#v-zoom-1').addEventListener('click', () => { tools.setMouse('zoom'); tools.setZoom('1:1'); });
  $('#v-mouse-camera').addEventListener('click', () => tools.setMouse('camera'));
  $('#v-mouse-zoom').addEventListener('click', () => tools.setMouse('zoom'));

  const wrap = $('#v-wrap');
  wrap.addEventListener('wheel', (e) => {
    if (!viewer.id) return;  // nothing shown: the page scrolls
    e.preventDefault();
    if (tools.mouseMode() === 'camera') nav.wheel(e);
    else tools.zoomAt(2 ** (-wheelPixels(e) / 200), e.clientX, e.clientY);
  }, { passive: false });
  wrap.addEventListener('pointerdown', (e) => {
    tools.dragged = false;
    if (tools.zoom === 'fit' || tools.mouseMode() !== 'zoom' || e.button !== 0) return;
    tools.drag = { x: e.clientX, y: e.clientY, pan: { ...tools.pan } };
  });
  wrap.addEventListener('pointermove', (e) => {
    if (tools.drag) {
      const dx = e.clientX - tools.drag.x, dy = e.clientY - tools.drag.y;
      // Captured once it is a drag: a click stays a click on the canvas (focus there).
      if (Math.abs(dx) + Math.abs(dy) > 3 && !tools.dragged) {
        tools.dragged = true;
        wrap.setPointerCapture(e.pointerId);
      }
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
