// Denoising on the page (the server's Intel Open Image Denoise): the form's Denoise control, off
// and disabled with the server's reason when /api/health says it has no denoiser (a job asking for
// one would be refused), and for a denoised job the viewer's Raw / Denoised switch, its denoise
// facts (mode, pictures, time, the denoised noise estimate), its warning and its raw image links.
'use strict';

const denoiser = { available: null, description: '' };  // null: the server has not said yet

// What the viewer's canvas shows of a denoised job: 'denoised' or 'raw'. The user's pick, kept
// from job to job; a job without a denoised picture (yet) shows its raw one whatever the pick.
const denoiseView = { choice: 'denoised' };

// A denoising time: milliseconds under a second (a small picture takes a few).
function fmtDenoiseTime(s) { return s < 1 ? `${Math.round(s * 1000)} ms` : fmtSeconds(s); }

// Asks the server whether it can denoise, and sets the form's control by its answer.
async function checkDenoiser() {
  const r = await api('/api/health');
  if (!r || !r.ok || !r.data) return;
  const d = r.data.denoiser;
  denoiser.available = Boolean(d && d.available);  // a server that does not say predates denoising
  denoiser.description = d ? d.description : 'this server does not denoise';
  syncDenoiseControl();
}

// Where the server cannot denoise, the control is off and disabled, its reason beside it.
function syncDenoiseControl() {
  const select = $('#f-denoise'), note = $('#denoiser-note');
  const missing = denoiser.available === false;
  select.disabled = missing;
  note.hidden = !missing;
  note.textContent = missing ? `Denoising is not available on this server: ${denoiser.description.replace(/\.$/, '')}.` : '';
  select.title = missing ? note.textContent : '';
  if (missing && select.value !== 'off') {
    select.value = 'off';
    scheduleCheck();
  }
}

// ---------- the viewer ----------

// The denoise facts of a job's status `s` (its `denoise` is null for a job without), and its
// image links beside the viewer's PNG and EXR (`hasImage`: the job has a picture to give).
function showDenoise(s, hasImage) {
  const dn = s.denoise || null;
  $('#viewer').dataset.denoise = dn ? dn.mode : 'off';
  $('#v-denoise').hidden = !dn;
  // error_estimate is always the raw render's: said so where a denoised picture is beside it.
  $('#v-error-label').textContent = dn ? 'Raw error estimate' : 'Error estimate';
  $('#v-error-label').title = dn ? 'The raw render\'s relative MSE: denoising does not change it' : '';
  const noise = dn && Number.isFinite(dn.noise_estimate) ? dn.noise_estimate : null;
  $('#v-noise-box').hidden = noise === null;
  $('#v-noise-box').title = (dn && dn.noise_estimate_of) || '';
  $('#v-noise').textContent = fmtNum(noise, 3);
  $('#v-denoise-box').hidden = !dn;
  if (dn) {
    const frames = `${dn.frames} picture${dn.frames === 1 ? '' : 's'}`;
    const last = dn.seconds === null || dn.seconds === undefined ? ''
      : ` · last ${fmtDenoiseTime(dn.seconds)}${dn.spp ? ` at ${fmtNum(dn.spp, 3)} spp` : ''}`;
    $('#v-denoise-info').textContent = `${dn.mode} · ${frames}${last}`;
    $('#v-denoise-info').title = `${fmtDenoiseTime(dn.spent_seconds || 0)} denoising in all${dn.final ? '; the last is the finished image\'s' : ''}`;
  }
  const warning = $('#v-denoise-warning');
  warning.hidden = !(dn && dn.warning);
  warning.textContent = dn && dn.warning ? `Denoising failed: ${dn.warning}` : '';
  // image.png and image.exr are denoised once a denoised picture was made, raw until then.
  const denoised = dn && dn.frames > 0 ? 'Denoised ' : '';
  $('#v-png').textContent = `${denoised}PNG`;
  $('#v-exr').textContent = `${denoised}EXR`;
  for (const ext of ['png', 'exr']) {
    const a = $(`#v-raw-${ext}`);
    a.hidden = !dn;
    setLink(a, dn && hasImage ? dn.raw_images[ext] : null, `render-${s.id}-raw.${ext}`);
  }
  showPicture();
}

// Back to a job without denoising (another job opens, or the job is gone).
function resetDenoise() {
  $('#viewer').dataset.denoise = 'off';
  $('#viewer').dataset.picture = '';
  for (const sel of ['#v-denoise', '#v-denoise-warning', '#v-noise-box', '#v-denoise-box', '#v-raw-png', '#v-raw-exr'])
    $(sel).hidden = true;
  setLink($('#v-raw-png'), null);
  setLink($('#v-raw-exr'), null);
  $('#v-error-label').textContent = 'Error estimate';
  $('#v-png').textContent = 'PNG';
  $('#v-exr').textContent = 'EXR';
}

// The switch's state, and the line that says which picture the canvas shows.
function showPicture() {
  const feed = viewer.feed, dn = feed && feed.status && feed.status.denoise;
  const choice = denoiseView.choice;
  $('#v-show-denoised').setAttribute('aria-pressed', String(choice === 'denoised'));
  $('#v-show-raw').setAttribute('aria-pressed', String(choice === 'raw'));
  if (!dn) return;
  const has = Boolean(feed.denoised);
  let shown = 'raw', text;
  if (tools.active()) text = 'The raw render through the exposure and display tools (they work on its float pixels).';
  else if (choice === 'raw') text = 'Showing the raw render.';
  else if (!has && dn.warning) text = 'Showing the raw render: denoising failed (the warning below says why).';
  else if (!has && feed.ended) text = 'No denoised picture: the job ended before one was made. Showing the raw render.';
  else if (!has) text = 'Showing the raw render until the first pass ends and is denoised.';
  else {
    shown = 'denoised';
    text = feed.ended ? 'Showing the denoised image.'
      : `Showing the denoised picture${dn.spp ? ` of ${fmtNum(dn.spp, 3)} spp` : ''}; raw tiles paint over it until the next pass ends.`;
  }
  $('#v-picture').textContent = text;
  $('#viewer').dataset.picture = shown;
}

// The user picked what the canvas shows: repainted at once from the picture the feed keeps.
function setPictureChoice(choice) {
  denoiseView.choice = choice;
  const feed = viewer.feed;
  if (feed && feed.painted && !tools.active()) syncCanvas($('#v-canvas'), feed, null, choice);
  showPicture();
}

function initDenoise() {
  $('#v-show-denoised').addEventListener('click', () => setPictureChoice('denoised'));
  $('#v-show-raw').addEventListener('click', () => setPictureChoice('raw'));
  $('#v-compare-raw').addEventListener('click', () => viewer.id && compareRawDenoised(viewer.id));
}
