// The "New render" form: the job spec it reads, checking it with /api/jobs/check as the user types
// (errors beside their fields, in the form's own words), submitting it, the scene list, and keeping
// what the user set across reloads (localStorage; only "Reuse settings" copies a job's settings in).
'use strict';

// Form fields: name -> kind. The input of field F is #f-F and its error line is #err-F.
const FIELDS = {
  scene: 'select', max_depth: 'int', light_samples: 'int', aperture: 'num', focal_distance: 'num',
  spp: 'int', width: 'int', height: 'int', seed: 'int', time_limit: 'num', target_error: 'num', adaptive: 'bool',
  adaptive_tolerance: 'num', caustic_tracing: 'bool', denoise: 'select',
};

// The framing select sets two job fields (the API refuses both true): value -> fields, and what it does.
// The default is the API's and the CLI's: the course crop.
const FRAMINGS = {
  crop: { frame_scene: false, keep_fov: false, hint: 'As the course renders: a smaller image shows the centre of the view.' },
  scene: { frame_scene: true, keep_fov: false, hint: 'The course\'s view direction, zoomed so the scene fills the image.' },
  whole: { frame_scene: false, keep_fov: true, hint: 'The course\'s whole view, scaled to this size.' },
};
const FRAMING_FIELDS = ['frame_scene', 'keep_fov'];  // their errors show beside the select
const DEFAULT_FRAMING = 'crop';

// API field names without a label of their own, as the form speaks of them.
const FIELD_WORDS = {
  frame_scene: 'Fit the scene', keep_fov: 'Whole course view', camera: 'Camera', 'camera.position': 'Camera position',
  'camera.target': 'Camera target', 'camera.up': 'Camera up direction', 'camera.vfov': 'Camera field of view',
};

const FORM_KEY = 'render-form';

// The camera the next render is seen from: {scene, camera} once the view was moved on the image
// (camera.js) or a job's settings were reused; null = the scene's own framing.
let formCamera = null;

function framingOf(spec) {
  if (spec.frame_scene) return 'scene';
  return spec.keep_fov ? 'whole' : 'crop';
}

function showFramingHint() {
  const f = FRAMINGS[$('#f-framing').value];
  $('#framing-hint').textContent = f ? f.hint : '';
}

function input(name) { return document.getElementById(`f-${name}`); }

// A field's label as the form shows it ("Samples per pixel"), without its <small> note.
function fieldLabel(name) {
  if (FIELD_WORDS[name]) return FIELD_WORDS[name];
  const el = input(name);
  const label = el && (document.querySelector(`label[for="f-${name}"]`) || el.closest('label'));
  if (!label) return name;
  const copy = label.cloneNode(true);
  copy.querySelectorAll('small, input').forEach((x) => x.remove());
  return copy.textContent.trim() || name;
}

// An API message in the form's words: 'spp' must be ... -> Samples per pixel must be ...
function speakFields(message) {
  const names = [...Object.keys(FIELD_WORDS), ...Object.keys(FIELDS), 'framing'].sort((a, b) => b.length - a.length);
  const esc = (s) => s.replace(/[.*+?^${}()|[\]\\]/g, '\\$&');
  const alt = names.map(esc).join('|');
  // One pass, so that a label put in is not rewritten again ("adaptive" inside "Adaptive tolerance").
  const re = new RegExp(`'(${alt})'|(?<![\\w.'-])(${alt})(?![\\w.'-])`, 'g');
  return String(message).replace(/\s*\(--[a-z0-9-]+\)/g, '').replace(re, (m, quoted, bare, offset) => {
    const label = fieldLabel(quoted || bare);
    return offset === 0 ? label : label.charAt(0).toLowerCase() + label.slice(1);
  });
}

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
  const framing = FRAMINGS[$('#f-framing').value] || FRAMINGS[DEFAULT_FRAMING];
  for (const name of FRAMING_FIELDS) spec[name] = framing[name];
  if (formCamera && formCamera.scene === spec.scene) spec.camera = formCamera.camera;
  return { spec, errors };
}

function clearErrors() {
  document.querySelectorAll('#job-form .error').forEach((e) => { e.textContent = ''; });
  document.querySelectorAll('#job-form [aria-invalid]').forEach((e) => e.removeAttribute('aria-invalid'));
}

function showError(field, message) {
  message = speakFields(message);
  if (FRAMING_FIELDS.includes(field)) field = 'framing';
  if (field && field.startsWith('camera')) field = 'camera';
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
  for (const x of list) showError(x.field, prefix + speakFields(x.message));
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

// Posts a job and shows it; form errors go beside their fields. Resolves the new id, or null.
async function postJob(spec, showOptions = {}) {
  clearTimeout(checkTimer);
  ++checkSeq;  // a check still in flight must not overwrite what the submit says
  const r = await postJson('/api/jobs', spec, { 'Idempotency-Key': randomKey() });
  clearErrors();
  if (!r || !r.ok) {
    showApiErrors(apiError(r));
    return null;
  }
  viewer.show(r.data.id, showOptions);
  scheduleCheck();
  refreshJobs();
  return r.data.id;
}

async function submitJob(ev) {
  ev.preventDefault();
  const { spec, errors } = readSpec();
  if (Object.keys(errors).length) return showClientErrors(errors);
  const btn = $('#submit');
  btn.disabled = true;
  $('#check-state').textContent = '';
  try {
    if (await postJob(spec) && window.matchMedia('(max-width: 900px)').matches)
      $('#viewer').scrollIntoView({ behavior: 'smooth', block: 'start' });
  } finally {
    btn.disabled = false;
  }
}

function sceneSummary(name) {
  const sc = state.scenes.find((s) => s.name === name);
  return sc && sc.summary;
}

function showSceneSummary() {
  const s = sceneSummary($('#f-scene').value);
  const el = $('#scene-summary');
  const btn = $('#use-center');
  showWarnings($('#scene-warnings'), s && s.warnings);
  if (!s) { el.textContent = ''; btn.hidden = true; return; }
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

// A scene carries no lens of its own (neither the course's COLLADA nor glTF has one): a switch
// resets aperture and focal distance to the job defaults, what a job without them renders with.
function sceneLens() {
  const d = state.defaults || {};
  return { aperture: d.aperture, focal_distance: d.focal_distance };
}

// The user picked another scene: the lens settings of the last one do not carry over, nor its camera.
function onSceneChosen() {
  const lens = sceneLens();
  for (const [name, v] of Object.entries(lens)) if (v !== undefined) input(name).value = String(v);
  setFormCamera(null);
  showSceneSummary();
}

// The camera the next render uses (null: the scene's own framing), shown under the framing.
function setFormCamera(fc) {
  formCamera = fc && fc.camera ? fc : null;
  const line = $('#form-view');
  line.hidden = !formCamera;
  // One line, so that Render stays in a 800 px high window; the numbers in its tooltip.
  if (formCamera) line.title = `The next render's camera: ${fmtCamera(formCamera.camera)}`;
  saveForm();
  scheduleCheck();
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
  syncDenoiseControl();  // a job's denoise stays off where this server cannot denoise
  setFormCamera(spec.camera ? { scene: spec.scene, camera: spec.camera } : null);
}

// ---------- keeping the form ----------

function saveForm() {
  if (!state.formFilled) return;  // not before the defaults are in
  const values = {};
  for (const [name, kind] of Object.entries(FIELDS)) values[name] = kind === 'bool' ? input(name).checked : input(name).value;
  const saved = { values, framing: $('#f-framing').value, camera: formCamera };
  try { localStorage.setItem(FORM_KEY, JSON.stringify(saved)); } catch (e) { /* private mode: not kept */ }
}

function restoreForm() {
  let saved = null;
  try { saved = JSON.parse(localStorage.getItem(FORM_KEY) || 'null'); } catch (e) { saved = null; }
  if (!saved || !saved.values) return false;
  for (const [name, kind] of Object.entries(FIELDS)) {
    const v = saved.values[name];
    if (v === undefined) continue;
    if (kind === 'bool') input(name).checked = !!v;
    else if (name !== 'scene' || state.scenes.some((s) => s.name === v)) input(name).value = String(v);
  }
  if (FRAMINGS[saved.framing]) $('#f-framing').value = saved.framing;
  formCamera = saved.camera && saved.camera.scene === $('#f-scene').value ? saved.camera : null;
  return true;
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
    for (const [name, kind] of Object.entries(FIELDS)) {
      if (name === 'scene' || !(name in state.defaults)) continue;
      const el = input(name);
      if (kind === 'bool') el.checked = !!state.defaults[name];
      else el.value = String(state.defaults[name]);
      if (kind !== 'bool') el.placeholder = String(state.defaults[name]);
    }
    $('#f-framing').value = DEFAULT_FRAMING;
    restoreForm();
    state.formFilled = true;
    setFormCamera(formCamera);
    showFramingHint();
  }
  showSceneSummary();
  return true;
}

function initForm() {
  const form = $('#job-form');
  form.addEventListener('submit', submitJob);
  form.addEventListener('input', () => {
    saveForm();
    scheduleCheck();
  });
  form.addEventListener('change', (e) => {
    if (e.target.id === 'f-scene') onSceneChosen();
    if (e.target.id === 'f-framing') showFramingHint();
    saveForm();
    scheduleCheck();
  });
  $('#use-center').addEventListener('click', (e) => {
    input('focal_distance').value = e.currentTarget.dataset.value;
    flash(input('focal_distance'));
    saveForm();
    scheduleCheck();
  });
  $('#form-view-clear').addEventListener('click', () => setFormCamera(null));
}
