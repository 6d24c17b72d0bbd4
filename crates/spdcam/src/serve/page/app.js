// The spdcam page: uploads photos to the local API (docs/web-api.md), polls their jobs, and
// draws the photo with the chart's outline, the SPDs, the xy diagram and the details; the
// summary, verdict and metrics are the estimate's `presentation` (the same words and rounded
// numbers as the report). When no chart is found, the photo is shown large with zoom and pan
// to place its four corners by clicks. Plain JavaScript, no library, nothing fetched from
// outside this server.
'use strict';

const SVG = 'http://www.w3.org/2000/svg';
const COLORS = ['#d62728', '#1f77b4', '#2ca02c', '#9467bd', '#ff7f0e', '#17becf', '#8c564b', '#e377c2'];
const POLL_MS = 80;

const state = { entries: [], selected: null, reference: null, nextId: 1 };

const $ = (id) => document.getElementById(id);

function el(tag, attrs, parent, text) {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  if (parent) parent.appendChild(e);
  return e;
}

function html(tag, attrs, parent, text) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  if (parent) parent.appendChild(e);
  return e;
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// ---- talking to the server ------------------------------------------------------------

/** An error for a person: the server's plain `message` (never its command-line words) and
 *  its `code` (`no_chart` when the chart was not found, `not_the_chart` when what was found
 *  or placed is not the chart). */
function serverError(body, status) {
  const e = new Error(body.message || `The server answered ${status}; try again.`);
  e.code = body.code || null;
  return e;
}

/** Posts a photo as a job (with upload progress); resolves to the job id. */
function submit(entry, corners, chart) {
  return new Promise((resolve, reject) => {
    const form = new FormData();
    form.append('photo', entry.file, entry.name);
    if (corners) form.append('corners', corners.map((p) => p.map((v) => v.toFixed(2)).join(',')).join(','));
    if (chart) form.append('chart', chart);
    const light = $('light').value;
    if (light && light !== 'unknown') form.append('light', light);
    const xhr = new XMLHttpRequest();
    xhr.open('POST', 'api/jobs');
    xhr.responseType = 'json';
    xhr.upload.onprogress = (e) => {
      if (e.lengthComputable) setStatus(entry, `uploading ${Math.round((100 * e.loaded) / e.total)} %`);
    };
    xhr.onload = () => {
      const body = xhr.response || {};
      if (xhr.status === 202 && body.id) resolve(body.id);
      else reject(serverError(body, xhr.status));
    };
    xhr.onerror = () => reject(new Error('The server cannot be reached; is it still running?'));
    xhr.send(form);
  });
}

/** Polls a job until it is done; resolves to the estimate's JSON. */
async function poll(entry, id) {
  for (;;) {
    await sleep(POLL_MS);
    const r = await fetch(`api/jobs/${encodeURIComponent(id)}`);
    const s = await r.json();
    if (!r.ok) throw serverError(s, r.status);
    if (s.state === 'done') return s.result;
    if (s.state === 'failed') throw serverError(s, s.status);
    if (s.state === 'queued') setStatus(entry, s.ahead > 0 ? `waiting (${s.ahead} ahead)` : 'waiting');
    else setStatus(entry, `estimating… ${s.seconds.toFixed(1)} s`);
  }
}

async function run(entry, corners, chart) {
  entry.error = null;
  entry.errorCode = null;
  entry.busy = true;
  setStatus(entry, 'uploading');
  render();
  try {
    const id = await submit(entry, corners, chart);
    entry.result = placed(entry, await poll(entry, id));
    entry.jobId = id;
    entry.placing = null;
    entry.corners = entry.result.photo ? entry.result.photo.corners.map((p) => p.slice()) : null;
  } catch (e) {
    entry.error = e.message;
    entry.errorCode = e.code || null;
    // No chart found: the photo is shown large to place its corners (not for a TIFF, which
    // browsers cannot show). What was found or placed is not the chart: the same, with the
    // corners cleared to be placed again (the chart named, if it was) and the reason shown.
    const placeable = !/\.tiff?$/i.test(entry.name);
    if (e.code === 'no_chart' && placeable) entry.placing = entry.placing || { points: [], chart: null };
    if (e.code === 'not_the_chart' && placeable) entry.placing = { points: [], chart: entry.placing ? entry.placing.chart : null };
    if (corners && entry.result) entry.corners = entry.result.photo.corners.map((p) => p.slice());
  }
  entry.busy = false;
  entry.status = '';
  render();
}

/** A photo of several charts: the entry keeps its place's estimate (the first, or the place
 *  it already stands for) and each other place becomes an entry of its own beside it, sharing
 *  the photo; its estimate is the result the entry shows. */
function placed(entry, result) {
  const places = result.places;
  if (!places || places.length < 2) return result;
  if (entry.place) return places.find((p) => p.photo.place.number === entry.place) || places[0];
  entry.place = places[0].photo.place.number;
  entry.shown = places[0].name;
  let at = state.entries.indexOf(entry);
  for (const r of places.slice(1)) {
    const sibling = {
      ...entry, id: state.nextId++, color: COLORS[state.entries.length % COLORS.length],
      result: r, place: r.photo.place.number, shown: r.name,
      corners: r.photo.corners.map((p) => p.slice()), busy: false, status: '',
    };
    state.entries.splice(++at, 0, sibling);
  }
  return places[0];
}

function setStatus(entry, text) {
  entry.status = text;
  const li = document.querySelector(`#list li[data-id="${entry.id}"] .status`);
  if (li) li.textContent = text;
}

// ---- adding photos --------------------------------------------------------------------

/** A file name as shown: without control or bidirectional formatting characters, which would
 * reorder the text around them (the server's rule for labels, multipart.rs `shown`). */
function shownName(name) {
  return (name || '').replace(/[\u0000-\u001f\u007f-\u009f\u061c\u200e\u200f\u2028\u2029\u202a-\u202e\u2066-\u2069]/g, '').trim();
}

function addFiles(files) {
  let first = null;
  for (const file of files) {
    const entry = {
      id: state.nextId++, file, name: shownName(file.name) || 'photo', url: URL.createObjectURL(file),
      color: COLORS[state.entries.length % COLORS.length], result: null, error: null, errorCode: null,
      status: '', busy: false, visible: true, corners: null, jobId: null, placing: null,
    };
    state.entries.push(entry);
    if (!first) first = entry;
    run(entry, null);
  }
  if (first) state.selected = first.id;
  render();
}

function setupInputs() {
  // The plot is drawn at the width it is shown: drawn again when that width changes.
  let plotWidth = 0;
  new ResizeObserver(([entry]) => {
    const width = Math.round(entry.contentRect.width);
    if (width !== plotWidth) { plotWidth = width; renderSpd(); }
  }).observe($('spd-plot'));
  const drop = $('drop');
  $('files').addEventListener('change', (e) => { addFiles([...e.target.files]); e.target.value = ''; });
  drop.addEventListener('dragover', (e) => { e.preventDefault(); drop.classList.add('over'); });
  drop.addEventListener('dragleave', () => drop.classList.remove('over'));
  drop.addEventListener('drop', (e) => {
    e.preventDefault();
    drop.classList.remove('over');
    addFiles([...e.dataTransfer.files]);
  });
  // Another kind of light named: every photo already estimated is estimated again with it,
  // the chart found again where it was detected, else at the corners placed.
  $('light').addEventListener('change', () => {
    for (const e of state.entries) {
      if (!e.result || e.busy) continue;
      const detected = e.result.photo && e.result.photo.method === 'detected';
      run(e, detected ? null : e.corners);
    }
  });
  $('example').addEventListener('click', async () => {
    const blob = await (await fetch('example.jpg')).blob();
    addFiles([new File([blob], 'cc24-led.jpg', { type: 'image/jpeg' })]);
  });
  $('reference').addEventListener('change', async (e) => {
    const file = e.target.files[0];
    if (!file) return;
    try {
      state.reference = { name: shownName(file.name), ...parseSpectralCsv(await file.text()) };
      $('reference-info').textContent = `${state.reference.name}: ${state.reference.wl.length} values, ${state.reference.wl[0]}–${state.reference.wl[state.reference.wl.length - 1]} nm`;
      $('reference-info').className = '';
    } catch (err) {
      state.reference = null;
      $('reference-info').textContent = `${shownName(file.name)}: ${err.message}`;
      $('reference-info').className = 'error';
    }
    render();
  });
}

/** A spectral CSV: the first numeric column is the wavelength (nm), the second the value. */
function parseSpectralCsv(text) {
  const wl = [];
  const v = [];
  text.split(/\r?\n/).forEach((line, i) => {
    const cells = line.split(/[,;\t ]+/).filter((c) => c !== '');
    if (cells.length < 2) return;
    const a = Number(cells[0]);
    const b = Number(cells[1]);
    if (!Number.isFinite(a) || !Number.isFinite(b)) {
      if (wl.length > 0) throw new Error(`line ${i + 1}: '${line.slice(0, 40)}' is not two numbers`);
      return; // a header
    }
    if (wl.length && a <= wl[wl.length - 1]) throw new Error(`line ${i + 1}: wavelengths must increase`);
    wl.push(a);
    v.push(b);
  });
  if (wl.length < 2) throw new Error('no rows of wavelength, value found');
  return { wl, v };
}

/** Linear interpolation of (xs, ys) at x; null outside the range. */
function interpolate(xs, ys, x) {
  if (x < xs[0] || x > xs[xs.length - 1]) return null;
  let i = 1;
  while (xs[i] < x) i++;
  const t = xs[i] === xs[i - 1] ? 0 : (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
  return ys[i - 1] + t * (ys[i] - ys[i - 1]);
}

/** GFC and RMSE of an estimate against the reference, both peak-normalised on the
 *  wavelengths they share (as spdcam's scores: Hernández-Andrés et al. 2001 for GFC). */
function scoreAgainstReference(result) {
  const ref = state.reference;
  if (!ref) return null;
  const pairs = [];
  result.wavelength_nm.forEach((w, i) => {
    const r = interpolate(ref.wl, ref.v, w);
    if (r !== null) pairs.push([result.spd[i], r]);
  });
  if (pairs.length < 3) return { error: 'the reference does not cover the estimate\'s wavelengths' };
  const me = Math.max(...pairs.map((p) => p[0]));
  const mr = Math.max(...pairs.map((p) => p[1]));
  if (!(me > 0) || !(mr > 0)) return { error: 'the reference has no positive value' };
  let dot = 0, ee = 0, rr = 0, sq = 0;
  for (const [e0, r0] of pairs) {
    const e = e0 / me, r = r0 / mr;
    dot += e * r; ee += e * e; rr += r * r; sq += (e - r) * (e - r);
  }
  return { gfc: Math.abs(dot) / Math.sqrt(ee * rr), rmse: Math.sqrt(sq / pairs.length), n: pairs.length };
}

// ---- drawing --------------------------------------------------------------------------

function render() {
  renderList();
  renderOverview();
  renderStage();
  renderSpd();
  renderUv();
  renderSummary();
}

function selected() {
  return state.entries.find((e) => e.id === state.selected) || null;
}

function fmt(v, digits) {
  return typeof v === 'number' && Number.isFinite(v) ? v.toFixed(digits) : '–';
}

function renderList() {
  const list = $('list');
  list.replaceChildren();
  for (const e of state.entries) {
    const li = html('li', { 'data-id': e.id }, list);
    if (e.id === state.selected) li.className = 'selected';
    li.addEventListener('click', () => { state.selected = e.id; render(); });
    const top = html('div', {}, li);
    html('span', { class: 'swatch', style: `background:${e.color}` }, top);
    html('span', { class: 'name' }, top, e.shown || e.name);
    let status = e.status;
    if (!e.busy && e.result) status = listStatus(e.result);
    html('div', { class: 'status' }, li, status);
    if (e.error) html('div', { class: 'error', role: 'alert' }, li, e.error);
    if (e.result) {
      const label = html('label', {}, li);
      const box = html('input', { type: 'checkbox' }, label);
      box.checked = e.visible;
      box.addEventListener('click', (ev) => ev.stopPropagation());
      box.addEventListener('change', () => { e.visible = box.checked; render(); });
      label.append(' on the plots');
    }
  }
}

/** A result in a few words for the list: its CCT when meaningful, and the verdict. */
function listStatus(r) {
  const p = r.presentation;
  if (!p) return 'estimated';
  const cct = p.groups.flatMap((g) => g.metrics).find((m) => m.key === 'cct_k');
  const parts = [];
  if (cct && cct.value !== null) parts.push(`${cct.value} K`);
  if (p.verdict) parts.push(p.verdict.label);
  return parts.join(' · ') || 'estimated';
}

function renderStage() {
  const stage = $('stage');
  const e = selected();
  const view = $('photo-view');
  view.classList.toggle('wide', Boolean(e && e.placing));
  $('photo-title').textContent = e ? e.shown || e.name : 'Photo';
  stage.replaceChildren();
  $('stage-tools').replaceChildren();
  if (!e) { html('p', { class: 'placeholder' }, stage, 'No photo yet.'); return; }
  if (e.placing) { renderPlacer(stage, e); return; }
  const photo = e.result && e.result.photo;
  if (e.error && !e.result) { html('p', { class: 'error' }, stage, e.error); return; }
  const img = html('img', { src: e.url, alt: e.name }, stage);
  const draw = (w, h) => {
    if (!photo) return;
    const svg = el('svg', { class: 'overlay', viewBox: `0 0 ${w} ${h}`, preserveAspectRatio: 'none' }, stage);
    drawOverlay(svg, e, photo, Math.max(w, h));
  };
  if (photo) {
    img.addEventListener('error', () => {
      // Browsers show no TIFF: draw the outline on a plain background of the photo's size.
      img.remove();
      const svg = el('svg', { class: 'overlay-bg', viewBox: `0 0 ${photo.width} ${photo.height}`, width: '100%' }, stage);
      el('rect', { width: photo.width, height: photo.height, fill: '#ddd' }, svg);
      drawOverlay(svg, e, photo, Math.max(photo.width, photo.height));
    });
    draw(photo.width, photo.height);
    if (!/\.tiff?$/i.test(e.name)) {
      const again = html('button', { type: 'button', id: 'place-corners' }, $('stage-tools'), 'Place the corners yourself');
      again.addEventListener('click', () => { e.placing = { points: [], chart: null }; render(); });
    }
  }
}

/** The charts a person can name for placed corners, [name, label] as the server lists
 *  them (`GET api/charts`), loaded when the page opens. */
let charts = [];
fetch('api/charts')
  .then((r) => r.json())
  .then((list) => { charts = list.map((c) => [c.name, c.label]); })
  .catch(() => { charts = []; });

/**
 * The photo large, with zoom (wheel or buttons) and pan (drag), where four clicks place the
 * chart's corners; then the chart is asked (never guessed) and the estimate made with both.
 * The view's transform is on `#placer` as data-scale, data-x, data-y (screen px per photo
 * px, and the photo's offset in the view).
 */
function renderPlacer(stage, e) {
  const p = e.placing;
  const tools = $('stage-tools');
  html('p', { class: 'instructions', id: 'placer-help' }, stage,
    p.points.length < 4
      ? `Click the chart's four outer corners, in any order (${p.points.length} of 4 placed). Scroll or use + and − to zoom, drag to move the photo.`
      : 'All four corners placed. Which chart is it?');
  const button = (label, id, action, parent) => {
    const b = html('button', { type: 'button', id }, parent || tools, label);
    b.addEventListener('click', action);
    return b;
  };
  const view = html('div', { id: 'placer', class: 'placer' }, stage);
  const inner = html('div', { class: 'placer-inner' }, view);
  const img = html('img', { src: e.url, alt: e.name, draggable: 'false' }, inner);
  const marks = el('svg', { class: 'placer-marks' }, inner);
  const apply = () => {
    const t = p.view;
    if (!t) return;
    inner.style.transform = `translate(${t.x}px, ${t.y}px) scale(${t.scale})`;
    view.dataset.scale = t.scale; view.dataset.x = t.x; view.dataset.y = t.y;
    drawMarks();
  };
  const drawMarks = () => {
    marks.replaceChildren();
    const t = p.view;
    if (!t) return;
    const r = 7 / t.scale;
    if (p.points.length > 1) {
      el(p.points.length === 4 ? 'polygon' : 'polyline', { points: orderCorners(p.points).map((q) => q.join(',')).join(' '), fill: 'none', stroke: '#ffeb3b', 'stroke-width': 2.5 / t.scale }, marks);
    }
    p.points.forEach((q, k) => {
      el('circle', { class: 'corner', cx: q[0], cy: q[1], r, fill: 'rgba(255,235,59,0.45)', stroke: '#000', 'stroke-width': 1.5 / t.scale }, marks);
      el('text', { x: q[0] + 1.6 * r, y: q[1] - 1.6 * r, 'font-size': 16 / t.scale, fill: '#ffeb3b', stroke: '#000', 'stroke-width': 0.6 / t.scale, 'font-family': 'sans-serif' }, marks, String(k + 1));
    });
  };
  const zoom = (factor, cx, cy) => {
    const t = p.view;
    const scale = Math.min(Math.max(t.scale * factor, t.fit / 2), 8);
    t.x = cx - ((cx - t.x) * scale) / t.scale;
    t.y = cy - ((cy - t.y) * scale) / t.scale;
    t.scale = scale;
    apply();
  };
  const fit = () => {
    const w = img.naturalWidth, h = img.naturalHeight;
    const scale = Math.min(view.clientWidth / w, view.clientHeight / h);
    p.view = { scale, fit: scale, x: (view.clientWidth - w * scale) / 2, y: (view.clientHeight - h * scale) / 2 };
    apply();
  };
  const ready = () => {
    // The photo at its own pixel size; the view's transform scales it.
    img.style.width = `${img.naturalWidth}px`;
    img.style.height = `${img.naturalHeight}px`;
    marks.setAttribute('viewBox', `0 0 ${img.naturalWidth} ${img.naturalHeight}`);
    marks.setAttribute('width', img.naturalWidth);
    marks.setAttribute('height', img.naturalHeight);
    if (p.view) apply(); else fit();
    view.dataset.ready = '1';
  };
  if (img.complete && img.naturalWidth) ready(); else img.addEventListener('load', ready);
  img.addEventListener('error', () => html('p', { class: 'error' }, stage, 'This photo cannot be shown in the browser, so its corners cannot be placed here.'));
  button('+', 'zoom-in', () => zoom(1.5, view.clientWidth / 2, view.clientHeight / 2));
  button('−', 'zoom-out', () => zoom(1 / 1.5, view.clientWidth / 2, view.clientHeight / 2));
  button('Fit', 'zoom-fit', fit);
  button('Undo last corner', 'undo-corner', () => { p.points.pop(); render(); }).disabled = p.points.length === 0;
  button('Cancel', 'cancel-corners', () => { e.placing = null; render(); });
  view.addEventListener('wheel', (ev) => {
    ev.preventDefault();
    const box = view.getBoundingClientRect();
    zoom(ev.deltaY < 0 ? 1.25 : 1 / 1.25, ev.clientX - box.left, ev.clientY - box.top);
  }, { passive: false });
  let drag = null;
  view.addEventListener('pointerdown', (ev) => {
    if (!p.view) return;
    view.setPointerCapture(ev.pointerId);
    drag = { x: ev.clientX, y: ev.clientY, tx: p.view.x, ty: p.view.y, moved: false };
  });
  view.addEventListener('pointermove', (ev) => {
    if (!drag) return;
    const dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
    if (Math.hypot(dx, dy) > 4) drag.moved = true;
    if (drag.moved) { p.view.x = drag.tx + dx; p.view.y = drag.ty + dy; apply(); }
  });
  view.addEventListener('pointerup', (ev) => {
    const d = drag;
    drag = null;
    if (!d || d.moved || p.points.length >= 4) return;
    const box = view.getBoundingClientRect();
    const t = p.view;
    const x = (ev.clientX - box.left - t.x) / t.scale;
    const y = (ev.clientY - box.top - t.y) / t.scale;
    if (x < 0 || y < 0 || x > img.naturalWidth || y > img.naturalHeight) return;
    p.points.push([x, y]);
    render();
  });
  if (p.points.length === 4) {
    const ask = html('fieldset', { class: 'chart-choice', id: 'chart-choice' }, stage);
    html('legend', {}, ask, 'Which chart is in the photo?');
    for (const [name, label] of charts) {
      const l = html('label', {}, ask);
      const radio = html('input', { type: 'radio', name: 'chart', value: name }, l);
      radio.checked = p.chart === name;
      radio.addEventListener('change', () => { p.chart = name; go.disabled = false; });
      l.append(` ${label}`);
    }
    const go = button('Estimate with these corners', 'estimate-corners', () => {
      if (!p.chart || e.busy) return;
      run(e, orderCorners(p.points), p.chart);
    }, ask);
    go.disabled = !p.chart || e.busy;
  }
  if (e.error && e.errorCode !== 'no_chart') html('p', { class: 'error', role: 'alert' }, stage, e.error);
}

/** Four points in order around their centre (so the outline does not cross itself). */
function orderCorners(points) {
  if (points.length < 3) return points;
  const cx = points.reduce((s, q) => s + q[0], 0) / points.length;
  const cy = points.reduce((s, q) => s + q[1], 0) / points.length;
  return points.slice().sort((a, b) => Math.atan2(a[1] - cy, a[0] - cx) - Math.atan2(b[1] - cy, b[0] - cx));
}

function drawOverlay(svg, entry, photo, size) {
  const corners = entry.corners || photo.corners;
  const outline = el('polygon', { points: corners.map((p) => p.join(',')).join(' '), fill: 'none', stroke: '#ffeb3b', 'stroke-width': size / 400 }, svg);
  const r = size / 220;
  for (const p of photo.patches) {
    const [cr, cg, cb] = p.rgb.map((v) => Math.round(v));
    el('circle', {
      cx: p.centre[0], cy: p.centre[1], r, fill: `rgb(${cr},${cg},${cb})`,
      stroke: p.clipped ? '#ff1744' : p.dark ? '#2979ff' : '#fff', 'stroke-width': r / 3,
    }, svg);
  }
  corners.forEach((c, k) => {
    const handle = el('circle', { class: 'handle', 'data-corner': k, cx: c[0], cy: c[1], r: size / 70, fill: 'rgba(255,235,59,0.35)', stroke: '#ffeb3b', 'stroke-width': size / 300 }, svg);
    handle.addEventListener('pointerdown', (ev) => {
      if (entry.busy) return;
      ev.preventDefault();
      handle.setPointerCapture(ev.pointerId);
      const pos = (ev2) => {
        const pt = svg.createSVGPoint();
        pt.x = ev2.clientX; pt.y = ev2.clientY;
        const q = pt.matrixTransform(svg.getScreenCTM().inverse());
        return [Math.min(Math.max(q.x, 0), photo.width - 1), Math.min(Math.max(q.y, 0), photo.height - 1)];
      };
      const move = (ev2) => {
        const [x, y] = pos(ev2);
        entry.corners = entry.corners || photo.corners.map((p) => p.slice());
        entry.corners[k] = [x, y];
        handle.setAttribute('cx', x); handle.setAttribute('cy', y);
        outline.setAttribute('points', entry.corners.map((p) => p.join(',')).join(' '));
      };
      const up = (ev2) => {
        handle.removeEventListener('pointermove', move);
        handle.removeEventListener('pointerup', up);
        move(ev2);
        run(entry, entry.corners);
      };
      handle.addEventListener('pointermove', move);
      handle.addEventListener('pointerup', up);
    });
  });
}

/** The uncertainty band `key` of a result, as {lo, hi} arrays, in whichever shape it comes. */
function band(result, key) {
  const b = result[key] ?? (result.uncertainty && result.uncertainty[key]);
  if (!b) return null;
  const pick = (o, a, c) => (Array.isArray(o[a]) && Array.isArray(o[c]) ? { lo: o[a], hi: o[c] } : null);
  if (!Array.isArray(b)) return pick(b, 'lower', 'upper') || pick(b, 'lo', 'hi') || pick(b, 'low', 'high') || pick(b, 'min', 'max');
  if (b.length === 2 && Array.isArray(b[0]) && b[0].length === result.spd.length) return { lo: b[0], hi: b[1] };
  if (b.length === result.spd.length && Array.isArray(b[0]) && b[0].length === 2) return { lo: b.map((p) => p[0]), hi: b.map((p) => p[1]) };
  return null;
}

/** The smallest size of the plot's text, in CSS pixels: the plot is drawn in the pixels it
 *  is shown at (its viewBox follows its width), so no width makes its text smaller. */
const PLOT_FONT = 12;

/** The plot's top value: 1, raised in steps of 0.25 to hold the shown bands and curves. */
function spdTop(shown) {
  let top = 1;
  for (const e of shown) {
    const b = band(e.result, 'band95');
    if (b) top = Math.max(top, ...b.hi.filter(Number.isFinite));
  }
  return Math.min(Math.ceil(top * 4 - 1e-9) / 4, 3);
}

function renderSpd() {
  const svg = $('spd-plot');
  svg.replaceChildren();
  const shown = state.entries.filter((e) => e.result && e.visible);
  const wl = shown.length ? shown[0].result.wavelength_nm : [400, 700];
  const x0 = Math.min(...shown.map((e) => e.result.wavelength_nm[0]), wl[0]);
  const x1 = Math.max(...shown.map((e) => e.result.wavelength_nm[e.result.wavelength_nm.length - 1]), wl[wl.length - 1]);
  // Drawn at the width it is shown (one viewBox unit a CSS pixel), so its text keeps its size
  // from a phone to a wide screen; redrawn when that width changes.
  const W = Math.max(260, Math.round(svg.getBoundingClientRect().width) || 640);
  const H = Math.round(Math.min(380, Math.max(260, W * 0.56)));
  svg.setAttribute('viewBox', `0 0 ${W} ${H}`);
  // The legend above the frame, in rows: it covers no curve.
  const items = shown.slice(0, 3).map((e) => ({ label: e.name.slice(0, 22), attrs: { stroke: e.color, 'stroke-width': 2.5 } }));
  if (shown.length > 3) items.push({ label: `… ${shown.length - 3} more`, attrs: { stroke: 'none' } });
  const ref = state.reference;
  if (ref) items.push({ label: `reference: ${ref.name.slice(0, 16)}`, attrs: { stroke: '#1d2330', 'stroke-dasharray': '5 4', 'stroke-width': 1.5 } });
  if (shown.some((e) => band(e.result, 'band95') || band(e.result, 'band68'))) {
    items.push({ label: '68 % band', attrs: { stroke: '#5b6475', 'stroke-opacity': 0.45, 'stroke-width': 10 } });
    items.push({ label: '95 % band', attrs: { stroke: '#5b6475', 'stroke-opacity': 0.22, 'stroke-width': 10 } });
  }
  const left = 58, right = W - 12, bottom = H - 40;
  const rowHeight = PLOT_FONT + 5;
  const placed = [];
  let lx = left, ly = PLOT_FONT + 2;
  for (const item of items) {
    const width = 30 + 0.62 * PLOT_FONT * item.label.length;
    if (lx + width > right && lx > left) { lx = left; ly += rowHeight; }
    placed.push({ ...item, x: lx, y: ly });
    lx += width + 10;
  }
  const top = ly + 12;
  svg.dataset.frame = [left, right, top, bottom].join(',');
  const yTop = spdTop(shown);
  svg.dataset.top = yTop;
  const X = (w) => left + ((w - x0) / (x1 - x0)) * (right - left);
  // Values are clamped to the frame: nothing is drawn above or below it.
  const Y = (v) => bottom - (Math.min(Math.max(v, 0), yTop) / yTop) * (bottom - top);
  const text = (attrs, content) => el('text', { 'font-size': PLOT_FONT, fill: '#5b6475', 'font-family': 'sans-serif', ...attrs }, svg, content);
  el('rect', { x: 0, y: 0, width: W, height: H, fill: '#fff' }, svg);
  const clip = el('clipPath', { id: 'spd-frame' }, el('defs', {}, svg));
  el('rect', { x: left, y: top, width: right - left, height: bottom - top }, clip);
  const step = right - left < 360 ? 100 : 50;
  for (let w = Math.ceil(x0 / step) * step; w <= x1; w += step) {
    el('line', { x1: X(w), x2: X(w), y1: top, y2: bottom, stroke: '#eceef2' }, svg);
    text({ x: X(w), y: bottom + 16, 'text-anchor': 'middle' }, w);
  }
  for (let v = 0; v <= yTop + 1e-9; v += 0.25) {
    el('line', { x1: left, x2: right, y1: Y(v), y2: Y(v), stroke: '#eceef2' }, svg);
    text({ x: left - 6, y: Y(v) + 4, 'text-anchor': 'end' }, v.toFixed(2));
  }
  el('rect', { x: left, y: top, width: right - left, height: bottom - top, fill: 'none', stroke: '#9aa6bd' }, svg);
  text({ x: (left + right) / 2, y: H - 8, 'text-anchor': 'middle', 'font-size': PLOT_FONT + 1, fill: '#1d2330' }, 'wavelength (nm)');
  text({ x: 14, y: (top + bottom) / 2, transform: `rotate(-90 14 ${(top + bottom) / 2})`, 'text-anchor': 'middle', 'font-size': PLOT_FONT + 1, fill: '#1d2330' }, 'relative power');
  const plot = el('g', { 'clip-path': 'url(#spd-frame)' }, svg);
  for (const e of shown) {
    const r = e.result;
    for (const [key, opacity] of [['band95', 0.12], ['band68', 0.24]]) {
      const b = band(r, key);
      if (!b) continue;
      const pts = r.wavelength_nm.map((w, i) => `${X(w).toFixed(2)},${Y(b.hi[i]).toFixed(2)}`)
        .concat(r.wavelength_nm.map((w, i) => `${X(w).toFixed(2)},${Y(b.lo[i]).toFixed(2)}`).reverse());
      el('polygon', { class: 'band', 'data-band': key, points: pts.join(' '), fill: e.color, 'fill-opacity': opacity, stroke: 'none' }, plot);
    }
    el('polyline', {
      class: 'spd', 'data-entry': e.name, fill: 'none', stroke: e.color, 'stroke-width': e.id === state.selected ? 2.5 : 1.6,
      points: r.wavelength_nm.map((w, i) => `${X(w).toFixed(3)},${Y(r.spd[i]).toFixed(3)}`).join(' '),
    }, plot);
  }
  if (ref) {
    const m = Math.max(...ref.wl.map((w, i) => (w >= x0 && w <= x1 ? ref.v[i] : -Infinity)));
    const pts = ref.wl.map((w, i) => [w, ref.v[i]]).filter(([w]) => w >= x0 && w <= x1)
      .map(([w, v]) => `${X(w).toFixed(2)},${Y(v / m).toFixed(2)}`);
    el('polyline', { class: 'reference', fill: 'none', stroke: '#1d2330', 'stroke-dasharray': '5 4', 'stroke-width': 1.5, points: pts.join(' ') }, plot);
  }
  for (const item of placed) {
    const g = el('g', { class: 'legend' }, svg);
    el('line', { x1: item.x, x2: item.x + 20, y1: item.y - 4, y2: item.y - 4, ...item.attrs }, g);
    el('text', { x: item.x + 25, y: item.y, 'font-size': PLOT_FONT, fill: '#1d2330', 'font-family': 'sans-serif' }, g, item.label);
  }
}

/** The CIE 1976 u′v′ diagram of the selected estimate: the server's SVG (the drawing its
 *  report shows). */
function renderUv() {
  const box = $('uv-plot');
  box.replaceChildren();
  const e = selected();
  const svgText = e && e.result && e.result.presentation && e.result.presentation.uv_diagram;
  if (!svgText) { html('p', { class: 'placeholder' }, box, 'The light\'s colour appears here.'); return; }
  // Parsed as inline SVG in an inert document: nothing in it runs.
  const svg = new DOMParser().parseFromString(svgText, 'text/html').body.firstElementChild;
  if (svg && svg.nodeName.toLowerCase() === 'svg') box.append(document.importNode(svg, true));
}

function row(table, label, value, id) {
  const tr = html('tr', {}, table);
  html('th', {}, tr, label);
  const td = html('td', id ? { id } : {}, tr, value);
  return td;
}

/** The summary at the top for the selected photo: the light in plain words, the verdict and
 *  what it means (the estimate's `presentation`, as the report says it). */
function renderOverview() {
  const box = $('overview');
  box.replaceChildren();
  const e = selected();
  if (!e) {
    html('p', { class: 'placeholder' }, box, 'Add a photo of a colour chart, or try the example: a summary of the light appears here.');
    return;
  }
  if (!e.result || !e.result.presentation) {
    if (e.placing) html('p', { id: 'plain-summary', class: 'error' }, box, e.error || 'Place the chart\'s corners on the photo.');
    else if (e.error) html('p', { id: 'plain-summary', class: 'error', role: 'alert' }, box, e.error);
    else html('p', { class: 'placeholder' }, box, 'Estimating…');
    return;
  }
  const p = e.result.presentation;
  html('p', { id: 'plain-summary', class: 'plain-summary' }, box, p.summary);
  meterReadings(box, p.meter);
  if (p.verdict) {
    const v = html('div', { class: `verdict ${p.verdict.label}`, id: 'verdict', 'data-verdict': p.verdict.label }, box);
    html('strong', {}, v, `Verdict: ${p.verdict.headline}`);
    v.append(` ${p.verdict.explanation}`);
    if (p.verdict.reasons.length) {
      const ul = html('ul', { class: 'reasons' }, v);
      p.verdict.reasons.forEach((t) => html('li', {}, ul, t));
    }
    if (p.verdict.glare) html('p', { class: 'glare', id: 'glare' }, v, p.verdict.glare);
  }
  html('p', { class: 'note', id: 'gfc-words' }, box, p.gfc);
  const lines = e.result.across_places_lines;
  if (lines) {
    const across = html('div', { class: 'across', id: 'across-places' }, box);
    html('strong', {}, across, `The light across the ${e.result.across_places.places.length} places of this photo`);
    const ul = html('ul', {}, across);
    lines.forEach((t) => html('li', {}, ul, t));
  }
}

/** What a colour meter's screen leads with: CCT and Δuv, or the dominant wavelength, purity
 *  and peak of a coloured light; the illuminance when the photo's exposure gives it. */
function meterReadings(box, meter) {
  if (!meter) return;
  const div = html('div', { class: `meter ${meter.kind}`, id: 'meter' }, box);
  const reading = (label, value, key) => {
    const r = html('div', { class: 'reading' }, div);
    html('div', { class: 'label' }, r, label);
    html('div', { class: 'value', 'data-key': key }, r, value);
  };
  meter.headline.forEach((r) => reading(r.label, r.value, r.key));
  if (meter.illuminance) reading('Illuminance', meter.illuminance, 'illuminance');
}

/** The film and TV numbers: R1–R15, SSI and the filter corrections. */
function filmTv(box, meter) {
  if (!meter || (!meter.r1_r15 && !meter.film_tv.length)) return;
  html('h3', {}, box, 'Film and TV');
  const table = html('table', { id: 'film-tv', class: 'film-tv' }, box);
  if (meter.r1_r15) row(table, 'R1–R15', meter.r1_r15.map((v) => (v === null ? '—' : v.toFixed(0))).join(' ') + (meter.r9_note ? `; ${meter.r9_note}` : ''), 'r1-r15');
  meter.film_tv.forEach((r) => row(table, r.label, r.value, `film-${r.key}`));
}

/** The grouped metrics of a presentation: a rounded value with ± (95 %) and a line of what it
 *  tells, or, when not meaningful for this light, no number but the reason (greyed). */
function metricGroups(box, presentation) {
  const table = html('table', { id: 'metrics', class: 'metrics' }, box);
  for (const group of presentation.groups) {
    const head = html('tr', { class: 'group' }, table);
    html('th', { colspan: 2 }, head, group.title);
    for (const m of group.metrics) {
      const tr = html('tr', { class: m.value === null ? 'metric not-meaningful' : 'metric', 'data-key': m.key }, table);
      const th = html('th', {}, tr, m.label);
      html('div', { class: 'explain' }, th, m.explanation);
      if (m.value !== null) {
        html('td', { id: `metric-${m.key}`, class: 'value' }, tr, m.unit ? `${m.value} ${m.unit}` : m.value);
      } else {
        const td = html('td', { id: `metric-${m.key}`, class: 'value' }, tr, '—');
        html('div', { class: 'reason' }, td, m.not_meaningful);
      }
    }
  }
}

function renderSummary() {
  const box = $('summary');
  box.replaceChildren();
  const e = selected();
  if (!e) { html('p', { class: 'placeholder' }, box, 'Results appear here.'); return; }
  if (e.error) html('p', { class: 'error', role: 'alert', id: 'summary-error' }, box, e.error);
  if (!e.result) {
    if (!e.error) html('p', { class: 'placeholder' }, box, 'Estimating…');
    return;
  }
  const r = e.result;
  if (r.presentation) {
    html('h3', {}, box, 'Lighting metrics');
    metricGroups(box, r.presentation);
    if (r.metric_uncertainty) html('p', { class: 'note' }, box, '± : the 95 % interval of the metric, calibrated on photos held out from training; numbers are rounded to what it supports, and not shown where it is too wide.');
    filmTv(box, r.presentation.meter);
  }
  html('h3', {}, box, 'Details');
  const table = html('table', { id: 'facts' }, box);
  const c = r.colorimetry;
  row(table, 'CIE 1931 x', fmt(c.xy[0], 4), 'xy-x');
  row(table, 'CIE 1931 y', fmt(c.xy[1], 4), 'xy-y');
  if (typeof r.expected_gfc === 'number') row(table, 'expected GFC', fmt(r.expected_gfc, 3), 'expected-gfc');
  if (typeof r.band_widening === 'number' && r.band_widening > 1) {
    // The light found explains this photo worse than the calibration photos: wider bands.
    row(table, 'bands widened', `${fmt(r.band_widening, 1)}×`, 'band-widening');
  }
  if (r.absolute) {
    // Approximate absolute levels from the photo's EXIF exposure (see the JSON's note).
    if (r.absolute.ppfd_umol_m2_s != null) row(table, 'PPFD (approx.)', `${fmt(r.absolute.ppfd_umol_m2_s, 1)} µmol m⁻² s⁻¹`);
    if (r.absolute.melanopic_edi_lux != null) row(table, 'melanopic EDI (approx.)', `${fmt(r.absolute.melanopic_edi_lux, 0)} lx`);
  }
  if (r.photo) {
    row(table, 'chart', (r.presentation && r.presentation.chart) || r.photo.chart, 'chart');
    row(table, 'found by', r.photo.method === 'corners' ? 'your corners' : 'detection', 'method');
    row(table, 'detection confidence', fmt(r.photo.confidence, 2));
    row(table, 'photo', `${r.photo.width} × ${r.photo.height} px`);
  }
  row(table, 'model', r.model);
  const score = scoreAgainstReference(r);
  if (score && score.error) row(table, 'reference', score.error);
  else if (score) {
    row(table, 'GFC against the reference', fmt(score.gfc, 4), 'ref-gfc');
    row(table, 'RMSE against the reference', fmt(score.rmse, 4), 'ref-rmse');
  }
  const warnings = (r.presentation && r.presentation.warnings) || [];
  if (warnings.length) {
    html('h3', {}, box, 'Warnings');
    const ul = html('ul', { class: 'warnings', id: 'warnings' }, box);
    warnings.forEach((w) => html('li', {}, ul, w));
  }
  const dl = html('div', { class: 'downloads' }, box);
  const stem = e.name.replace(/\.[^.]*$/, '') || 'estimate';
  const button = (label, id, action) => {
    const b = html('button', { type: 'button', id }, dl, label);
    b.addEventListener('click', action);
  };
  button('SPD as CSV', 'download-csv', () => save(new Blob([spdCsv(r)], { type: 'text/csv' }), `${stem}.spd.csv`));
  button('JSON', 'download-json', () => save(new Blob([JSON.stringify(r, null, 2)], { type: 'application/json' }), `${stem}.json`));
  button('Plot as PNG', 'download-png', () => svgToPng($('spd-plot'), 2).then((b) => save(b, `${stem}.spd.png`)));
  if (e.jobId) button('Report', 'download-report', () => downloadReport(e, `${stem}.report.html`));
}

/** Saves the server's report of the entry's estimate (the report `spdcam estimate --report`
 *  writes, for this photo only). */
async function downloadReport(e, name) {
  try {
    const r = await fetch(`api/jobs/${encodeURIComponent(e.jobId)}/report`);
    if (!r.ok) throw serverError(await r.json(), r.status);
    save(await r.blob(), name);
  } catch (err) {
    e.error = err.message;
    render();
  }
}

/** A CSV field, quoted when it must be. */
function csvField(s) {
  return /[",\n]/.test(s) ? `"${s.replace(/"/g, '""')}"` : s;
}

/** The SPD as spectral CSV, as `spdcam estimate --output` writes it: the estimate, then its
 *  bands' edges (`NAME_lower68`, `NAME_upper68`, `NAME_lower95`, `NAME_upper95`). */
function spdCsv(r) {
  const columns = [[r.name, r.spd]];
  const b68 = band(r, 'band68');
  const b95 = band(r, 'band95');
  if (b68 && b95) {
    columns.push([`${r.name}_lower68`, b68.lo], [`${r.name}_upper68`, b68.hi], [`${r.name}_lower95`, b95.lo], [`${r.name}_upper95`, b95.hi]);
  }
  const lines = [['wavelength_nm', ...columns.map(([name]) => csvField(name))].join(',')];
  r.wavelength_nm.forEach((w, i) => lines.push([w, ...columns.map(([, v]) => v[i])].join(',')));
  return lines.join('\n') + '\n';
}

function save(blob, name) {
  const a = html('a', { href: URL.createObjectURL(blob), download: name });
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

function svgText(svg) {
  const copy = svg.cloneNode(true);
  copy.setAttribute('xmlns', SVG);
  const box = svg.viewBox.baseVal;
  copy.setAttribute('width', box.width);
  copy.setAttribute('height', box.height);
  return new XMLSerializer().serializeToString(copy);
}

function svgToPng(svg, scale) {
  return new Promise((resolve, reject) => {
    const box = svg.viewBox.baseVal;
    const img = new Image();
    img.onload = () => {
      const canvas = html('canvas', { width: box.width * scale, height: box.height * scale });
      const ctx = canvas.getContext('2d');
      ctx.scale(scale, scale);
      ctx.drawImage(img, 0, 0);
      canvas.toBlob((b) => (b ? resolve(b) : reject(new Error('PNG encoding failed'))), 'image/png');
    };
    img.onerror = () => reject(new Error('the plot could not be drawn'));
    img.src = `data:image/svg+xml;charset=utf-8,${encodeURIComponent(svgText(svg))}`;
  });
}

async function start() {
  setupInputs();
  render();
}

start();
