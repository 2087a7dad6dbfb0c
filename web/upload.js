// Scene upload: a file picker beside the scene list and drag-and-drop onto the page send the file
// to PUT /api/scenes/{name}; the server loads it before answering, so the page shows its summary
// (and selects it for the next job) or the loader's message.

const SCENE_TYPES = { dae: 'model/vnd.collada+xml', glb: 'model/gltf-binary', gltf: 'model/gltf+json' };

// "My Scene (2).dae" -> "My-Scene-2": the server's name rules (letters, digits, '_', '-', '.').
function sceneNameOf(fileName) {
  const base = fileName.replace(/\.[^.]*$/, '');
  return base.replace(/[^A-Za-z0-9_.-]+/g, '-').replace(/\.\.+/g, '.').replace(/^[^A-Za-z0-9]+|-+$/g, '').slice(0, 128);
}

function uploadNote(text, kind = '') {
  const el = $('#upload-status');
  el.textContent = text;
  el.dataset.kind = kind;
}

async function uploadScene(file) {
  const ext = (file.name.match(/\.([^.]+)$/) || [])[1];
  const type = SCENE_TYPES[(ext || '').toLowerCase()];
  const name = sceneNameOf(file.name);
  if (!type) return uploadNote(`${file.name}: a scene is a .dae, .glb or .gltf file.`, 'error');
  if (!name) return uploadNote(`${file.name}: the file name has no letters or digits to name the scene by.`, 'error');
  uploadNote(`Uploading ${file.name} (${(file.size / 1048576).toFixed(1)} MiB)…`);
  const r = await api(`/api/scenes/${encodeURIComponent(name)}`, { method: 'PUT', headers: { 'Content-Type': type }, body: file });
  if (!r || !r.ok) return uploadNote(`${file.name}: ${apiError(r).message}`, 'error');
  await loadScenes();
  $('#f-scene').value = name;
  onSceneChosen();  // its own lens, as a scene picked from the list
  uploadNote(`Scene '${name}' ${r.status === 201 ? 'uploaded' : 'replaced'}: selected for the next job.`, 'ok');
}

function initUpload() {
  $('#f-upload').addEventListener('change', (e) => {
    const file = e.target.files && e.target.files[0];
    if (file) uploadScene(file);
    e.target.value = '';  // the same file again is a new upload
  });
  // Dropped anywhere on the page: the browser would otherwise open the file in place of the page.
  const hasFiles = (e) => e.dataTransfer && [...e.dataTransfer.types].includes('Files');
  document.addEventListener('dragover', (e) => {
    if (!hasFiles(e)) return;
    e.preventDefault();
    document.body.classList.add('dropping');
  });
  document.addEventListener('dragleave', (e) => {
    if (e.relatedTarget === null) document.body.classList.remove('dropping');
  });
  document.addEventListener('drop', (e) => {
    if (!hasFiles(e)) return;
    e.preventDefault();
    document.body.classList.remove('dropping');
    const file = e.dataTransfer.files[0];
    if (file) uploadScene(file);
  });
}
