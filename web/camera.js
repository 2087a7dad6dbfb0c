// Moving the camera on the image, as the course's window does (its Camera: rotate_by, move_by,
// move_forward): drag orbits around the view's target, shift- or right-drag pans camera and target
// in the view plane, the wheel dollies. The moves start from the shown job's `view`. While the view
// moves, a small preview job streams into the viewer, one at a time: a new view cancels and
// deletes the stale preview first. When the view rests, the real job is submitted with the form's
// settings and the camera. Reset view goes back to the scene's own framing (no camera field).
'use strict';

const POLE_EPS = 1e-3;      // radians kept from the poles, where the orbit's up would flip
const PREVIEW_SPP = 4;
const PREVIEW_MIN = 16;     // pixels a side, at least
const REST_MS = 150;        // the view rests this long after the mouse is up
const WHEEL_REST_MS = 250;  // ... or after the last wheel event
const DOLLY_STEPS = 20;     // a wheel step moves 1/20 of the starting distance

const nav = {
  base: null,        // the real job the moves start from: {id, spec, view, width, height}
  view: null,        // the camera now: {position, target, up, vfov}
  origin: 0,         // the distance to the target the moves started at: dolly steps and limits
  ours: new Set(),   // real jobs the moves submitted: the origin carries on through them
  previews: new Set(),  // preview jobs made here: kept out of the job list
  posting: null,     // a preview's POST while in flight (a promise of its answer)
  preview: null,     // the live preview's id
  previewView: null, // the view it renders
  drag: null,
  moving: false,     // the view changed and has not rested yet
  gen: 0,            // counts changes: a rest acts only if none came after it
  work: Promise.resolve(),  // the requests, one after another
  pumping: false,
  restTimer: null,
  wheelAcc: 0,

  // Whether the shown picture has a view to move from.
  available() { return !!(viewer.id && this.base && this.view); },

  // The viewer opened a job: a preview, the job a rest or a reset submitted (keep), or another one.
  onShow(id, preview, keep) {
    if (preview) return;
    if (keep) {
      if (id) this.ours.add(id);
    } else {
      abandonMoves();
      this.base = null;
      this.view = null;
    }
    showView();
  },

  // A status of the shown job: a real job's view is where the next moves start.
  onStatus(s, preview) {
    if (!preview && s.view && s.id === viewer.id) {
      const fresh = !this.base || this.base.id !== s.id;
      this.base = { id: s.id, spec: s.spec, view: s.view, width: s.width, height: s.height };
      if (fresh && !this.moving) {
        this.view = s.view;
        if (!this.ours.has(s.id) || !(this.origin > 0)) this.origin = distance(s.view);
      }
    }
    showView();
    tools.showMouse();
  },

  wheel(e) {
    if (!this.available()) return;
    this.wheelAcc += wheelPixels(e) / 100;  // a notch is 100 px in Chromium and Firefox
    const steps = Math.trunc(this.wheelAcc);
    if (steps) {
      this.wheelAcc -= steps;
      change(dollyView(this.view, steps));
    }
    if (this.moving && !this.drag) scheduleRest(WHEEL_REST_MS);
  },
};

// ---------- vectors ----------

const vadd = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const vsub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const vscale = (a, k) => [a[0] * k, a[1] * k, a[2] * k];
const vcross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const vlen = (a) => Math.hypot(a[0], a[1], a[2]);
const vnorm = (a) => vscale(a, 1 / vlen(a));
const clamp = (x, lo, hi) => Math.max(lo, Math.min(hi, x));

function distance(view) { return vlen(vsub(view.position, view.target)); }

// The camera's up for a direction to the camera, with world +Y up (the course's compute_position).
function orbitUp(toCamera) {
  const right = vnorm(vcross([0, 1, 0], toCamera));
  return vnorm(vcross(toCamera, right));
}

// Orbit by a drag of (fx, fy) image widths and heights: a whole width or height turns by pi,
// the azimuth around world +Y, the polar angle from +Y kept inside (0, pi).
function orbitView(v, fx, fy) {
  const off = vsub(v.position, v.target);
  const r = vlen(off);
  const theta = Math.atan2(off[0], off[2]) - Math.PI * fx;
  const phi = clamp(Math.acos(clamp(off[1] / r, -1, 1)) - Math.PI * fy, POLE_EPS, Math.PI - POLE_EPS);
  const dir = [r * Math.sin(phi) * Math.sin(theta), r * Math.cos(phi), r * Math.sin(phi) * Math.cos(theta)];
  return { ...v, position: vadd(v.target, dir), up: orbitUp(dir) };
}

// Pan camera and target by a drag of (ux, uy) image heights: an image pixel is
// distance / screen_distance, screen_distance = (height / 2) / tan(vfov / 2). The scene follows the pointer.
function panView(v, ux, uy) {
  const back = vnorm(vsub(v.position, v.target));
  const right = vnorm(vcross(v.up, back));
  const up = vcross(back, right);
  const k = 2 * distance(v) * Math.tan((v.vfov * Math.PI) / 360);
  const d = vadd(vscale(right, -ux * k), vscale(up, uy * k));
  return { ...v, position: vadd(v.position, d), target: vadd(v.target, d) };
}

// Dolly by `steps` (positive: away), each 1/20 of the starting distance, within [1/20, 10] of it.
function dollyView(v, steps) {
  const off = vsub(v.position, v.target);
  const d0 = nav.origin > 0 ? nav.origin : vlen(off);
  const r = clamp(vlen(off) + (steps * d0) / DOLLY_STEPS, d0 / DOLLY_STEPS, 10 * d0);
  return { ...v, position: vadd(v.target, vscale(vnorm(off), r)) };
}

// A view as the job's camera field.
function cameraOf(v) {
  return { position: [...v.position], target: [...v.target], up: [...v.up], vfov: v.vfov };
}

// ---------- previews and the job at rest ----------

function queue(fn) {
  nav.work = nav.work.then(fn).catch((e) => console.warn('camera move:', e));
  return nav.work;
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// DELETE cancels a live job and deletes a finished one: asked until the job is gone.
async function deleteJob(id) {
  for (let i = 0, wait = 40; i < 300; ++i) {
    const r = await api(`/api/jobs/${id}`, { method: 'DELETE' });
    if (!r) return false;
    if (r.status === 404 || (r.ok && r.data && r.data.state === 'deleted')) return true;
    if (!r.ok) return false;
    await sleep(wait);
    wait = Math.min(250, wait * 1.5);
  }
  return false;
}

async function dropPreview() {
  const id = nav.preview;
  if (!id) return;
  nav.preview = null;
  nav.previewView = null;
  await deleteJob(id);
}

// The shown job's scene and settings at a quarter of its size (16 px a side at least), a few spp;
// denoised at preview quality where the job is denoised (no final-quality pass, no noise estimate).
function previewSpec(view) {
  const { spec, width, height } = nav.base;
  const k = Math.min(1, Math.max(0.25, PREVIEW_MIN / Math.min(width, height)));
  const preview = { ...spec, width: Math.max(1, Math.round(width * k)), height: Math.max(1, Math.round(height * k)),
    spp: PREVIEW_SPP, adaptive: false, target_error: 0, time_limit: 0, camera: cameraOf(view) };
  if (preview.denoise === 'final') preview.denoise = 'preview';
  return preview;
}

// Keeps one preview of the latest view: the stale one goes before the next is submitted, so
// there is never more than one live.
function kickPreviews() {
  if (nav.pumping) return;
  nav.pumping = true;
  queue(async () => {
    try {
      while (nav.moving && nav.base && nav.previewView !== nav.view) {
        const view = nav.view;
        await dropPreview();
        if (!nav.moving) break;
        // The job list waits on this: a list fetched meanwhile may hold the preview before its id is known.
        nav.posting = postJson('/api/jobs', previewSpec(view), { 'Idempotency-Key': randomKey() }).then((res) => {
          if (res && res.ok) nav.previews.add(res.data.id);
          return res;
        });
        const r = await nav.posting.finally(() => { nav.posting = null; });
        nav.previewView = view;
        if (!r || !r.ok) {
          viewer.note(`No preview of this view: ${apiError(r).message}`, 'error');
          break;
        }
        nav.preview = r.data.id;
        viewer.show(r.data.id, { preview: true });
      }
    } finally {
      nav.pumping = false;
    }
  });
}

function change(view) {
  nav.view = view;
  nav.gen += 1;
  clearTimeout(nav.restTimer);
  if (!nav.moving) {
    nav.moving = true;
    supersede();
  }
  showView();
  kickPreviews();
}

// The job the last rest submitted shows an old view now: it stops, so that the previews need not
// wait for the renderer. It stays in the list, cancelled, with what it had rendered.
function supersede() {
  const st = viewer.feed && viewer.feed.status;
  if (st && nav.ours.has(st.id) && !viewer.preview && !FINAL.has(st.state)) {
    const id = st.id;
    queue(() => api(`/api/jobs/${id}`, { method: 'DELETE' }));
  }
}

function scheduleRest(ms) {
  clearTimeout(nav.restTimer);
  nav.restTimer = setTimeout(rest, ms);
}

// The view rests: the preview goes, and the job with the form's settings and this camera comes.
function rest() {
  if (!nav.moving || (nav.drag && nav.drag.moved)) return;
  const gen = nav.gen, view = nav.view;
  nav.moving = false;
  showView();
  queue(async () => {
    if (gen !== nav.gen) return;
    await dropPreview();
    if (gen !== nav.gen || !nav.base) return;
    setFormCamera({ scene: nav.base.spec.scene, camera: cameraOf(view) });
    await submitFromForm(nav.base.spec.scene);
  });
}

// The form's job of `scene` (the moves' scene, whatever the form had), shown keeping the picture.
async function submitFromForm(scene) {
  if ($('#f-scene').value !== scene && state.scenes.some((s) => s.name === scene)) {
    $('#f-scene').value = scene;
    showSceneSummary();
  }
  const { spec, errors } = readSpec();
  if (Object.keys(errors).length) {
    showClientErrors(errors);
  } else if (await postJob(spec, { keep: true })) {
    return;
  }
  viewer.note('The view was not rendered: the form has an error. Mend it and press Render.', 'error');
}

// Stops the moves under way (another job opened): their preview goes.
function abandonMoves() {
  clearTimeout(nav.restTimer);
  nav.drag = null;
  if (nav.moving || nav.preview) {
    nav.gen += 1;
    nav.moving = false;
    queue(dropPreview);
  }
}

// Back to the scene's own framing: the form's settings without a camera field.
function resetView() {
  if (!nav.base) return;
  const scene = nav.base.spec.scene;
  clearTimeout(nav.restTimer);
  nav.gen += 1;
  nav.moving = false;
  setFormCamera(null);
  queue(async () => {
    await dropPreview();
    await submitFromForm(scene);
  });
}

// The camera of the picture on screen, under it; Reset view where there is one to reset.
function showView() {
  const st = viewer.feed && viewer.feed.status;
  let text = '';
  if (nav.moving) text = `Moving the camera ${fmtCamera(nav.view)}: previews at a quarter of the size, ${PREVIEW_SPP} spp.`;
  else if (st && st.spec && st.spec.camera) text = `Camera ${fmtCamera({ ...st.spec.camera, vfov: st.spec.camera.vfov || (st.view && st.view.vfov) })}.`;
  else if (st && st.view) text = `The scene's own framing, ${fmtCamera(st.view)}.`;
  $('#v-view').textContent = text;
  $('#viewer').dataset.nav = nav.moving ? 'moving' : 'rest';
  $('#v-reset-view').disabled = !nav.base || !(nav.moving || formCamera || (st && st.spec && st.spec.camera));
}

function initCamera() {
  const wrap = $('#v-wrap');
  wrap.addEventListener('pointerdown', (e) => {
    if (tools.mouseMode() !== 'camera' || !nav.available() || (e.button !== 0 && e.button !== 2)) return;
    const r = $('#v-canvas').getBoundingClientRect();
    nav.drag = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey, view: nav.view, w: r.width, h: r.height, moved: false };
  });
  wrap.addEventListener('pointermove', (e) => {
    const d = nav.drag;
    if (!d) return;
    const dx = e.clientX - d.x, dy = e.clientY - d.y;
    if (!d.moved && Math.abs(dx) + Math.abs(dy) <= 3) return;  // still a click
    if (!d.moved) wrap.setPointerCapture(e.pointerId);  // a drag now: it may leave the image
    d.moved = true;
    tools.dragged = true;
    change(d.pan ? panView(d.view, dx / d.h, dy / d.h) : orbitView(d.view, dx / d.w, dy / d.h));
  });
  const end = () => {
    const d = nav.drag;
    nav.drag = null;
    if (d && d.moved) scheduleRest(REST_MS);
  };
  wrap.addEventListener('pointerup', end);
  wrap.addEventListener('pointercancel', end);
  wrap.addEventListener('contextmenu', (e) => { if (tools.mouseMode() === 'camera') e.preventDefault(); });
  $('#v-reset-view').addEventListener('click', resetView);
}
