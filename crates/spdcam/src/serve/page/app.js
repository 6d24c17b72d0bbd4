// The spdcam page: uploads photos to the local API (docs/web-api.md), polls their jobs, and
// draws the photo with the chart's outline, the SPDs, the xy diagram and the details. Plain
// JavaScript, no library, nothing fetched from outside this server.
'use strict';

const SVG = 'http://www.w3.org/2000/svg';
const COLORS = ['#d62728', '#1f77b4', '#2ca02c', '#9467bd', '#ff7f0e', '#17becf', '#8c564b', '#e377c2'];
const POLL_MS = 80;

const state = { entries: [], selected: null, locus: null, reference: null, nextId: 1 };

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

/** Posts a photo as a job (with upload progress); resolves to the job id. */
function submit(entry, corners) {
  return new Promise((resolve, reject) => {
    const form = new FormData();
    form.append('photo', entry.file, entry.name);
    if (corners) form.append('corners', corners.map((p) => p.map((v) => v.toFixed(2)).join(',')).join(','));
    const xhr = new XMLHttpRequest();
    xhr.open('POST', 'api/jobs');
    xhr.responseType = 'json';
    xhr.upload.onprogress = (e) => {
      if (e.lengthComputable) setStatus(entry, `uploading ${Math.round((100 * e.loaded) / e.total)} %`);
    };
    xhr.onload = () => {
      const body = xhr.response || {};
      if (xhr.status === 202 && body.id) resolve(body.id);
      else reject(new Error(body.error || `the server answered ${xhr.status}`));
    };
    xhr.onerror = () => reject(new Error('the server cannot be reached'));
    xhr.send(form);
  });
}

/** Polls a job until it is done; resolves to the estimate's JSON. */
async function poll(entry, id) {
  for (;;) {
    await sleep(POLL_MS);
    const r = await fetch(`api/jobs/${encodeURIComponent(id)}`);
    const s = await r.json();
    if (!r.ok) throw new Error(s.error || `the server answered ${r.status}`);
    if (s.state === 'done') return s.result;
    if (s.state === 'failed') throw new Error(s.error);
    if (s.state === 'queued') setStatus(entry, s.ahead > 0 ? `waiting (${s.ahead} ahead)` : 'waiting');
    else setStatus(entry, `estimating… ${s.seconds.toFixed(1)} s`);
  }
}

async function run(entry, corners) {
  entry.error = null;
  entry.busy = true;
  setStatus(entry, 'uploading');
  try {
    const id = await submit(entry, corners);
    entry.result = await poll(entry, id);
    entry.corners = entry.result.photo ? entry.result.photo.corners.map((p) => p.slice()) : null;
  } catch (e) {
    entry.error = e.message;
    if (corners && entry.result) entry.corners = entry.result.photo.corners.map((p) => p.slice());
  }
  entry.busy = false;
  entry.status = '';
  render();
}

function setStatus(entry, text) {
  entry.status = text;
  const li = document.querySelector(`#list li[data-id="${entry.id}"] .status`);
  if (li) li.textContent = text;
}

// ---- adding photos --------------------------------------------------------------------

function addFiles(files) {
  let first = null;
  for (const file of files) {
    const entry = {
      id: state.nextId++, file, name: file.name || 'photo', url: URL.createObjectURL(file),
      color: COLORS[state.entries.length % COLORS.length], result: null, error: null,
      status: '', busy: false, visible: true, corners: null,
    };
    state.entries.push(entry);
    if (!first) first = entry;
    run(entry, null);
  }
  if (first) state.selected = first.id;
  render();
}

function setupInputs() {
  const drop = $('drop');
  $('files').addEventListener('change', (e) => { addFiles([...e.target.files]); e.target.value = ''; });
  drop.addEventListener('dragover', (e) => { e.preventDefault(); drop.classList.add('over'); });
  drop.addEventListener('dragleave', () => drop.classList.remove('over'));
  drop.addEventListener('drop', (e) => {
    e.preventDefault();
    drop.classList.remove('over');
    addFiles([...e.dataTransfer.files]);
  });
  $('example').addEventListener('click', async () => {
    const blob = await (await fetch('example.jpg')).blob();
    addFiles([new File([blob], 'sg-telelumen.jpg', { type: 'image/jpeg' })]);
  });
  $('reference').addEventListener('change', async (e) => {
    const file = e.target.files[0];
    if (!file) return;
    try {
      state.reference = { name: file.name, ...parseSpectralCsv(await file.text()) };
      $('reference-info').textContent = `${file.name}: ${state.reference.wl.length} values, ${state.reference.wl[0]}–${state.reference.wl[state.reference.wl.length - 1]} nm`;
      $('reference-info').className = '';
    } catch (err) {
      state.reference = null;
      $('reference-info').textContent = `${file.name}: ${err.message}`;
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
  renderStage();
  renderSpd();
  renderXy();
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
    html('span', { class: 'name' }, top, e.name);
    let status = e.status;
    if (!e.busy && e.result) status = e.result.colorimetry.cct ? `${fmt(e.result.colorimetry.cct, 0)} K` : 'estimated';
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

function renderStage() {
  const stage = $('stage');
  const e = selected();
  $('photo-title').textContent = e ? e.name : 'Photo';
  stage.replaceChildren();
  if (!e) { html('p', { class: 'placeholder' }, stage, 'No photo yet.'); return; }
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
  }
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

const SPD_BOX = { left: 52, right: 628, top: 14, bottom: 294 };

function renderSpd() {
  const svg = $('spd-plot');
  svg.replaceChildren();
  const shown = state.entries.filter((e) => e.result && e.visible);
  const wl = shown.length ? shown[0].result.wavelength_nm : [400, 700];
  const x0 = Math.min(...shown.map((e) => e.result.wavelength_nm[0]), wl[0]);
  const x1 = Math.max(...shown.map((e) => e.result.wavelength_nm[e.result.wavelength_nm.length - 1]), wl[wl.length - 1]);
  const { left, right, top, bottom } = SPD_BOX;
  const X = (w) => left + ((w - x0) / (x1 - x0)) * (right - left);
  const Y = (v) => bottom - v * (bottom - top);
  el('rect', { x: 0, y: 0, width: 640, height: 340, fill: '#fff' }, svg);
  for (let w = Math.ceil(x0 / 50) * 50; w <= x1; w += 50) {
    el('line', { x1: X(w), x2: X(w), y1: top, y2: bottom, stroke: '#eceef2' }, svg);
    el('text', { x: X(w), y: bottom + 16, 'text-anchor': 'middle', 'font-size': 12, fill: '#5b6475', 'font-family': 'sans-serif' }, svg, w);
  }
  for (let v = 0; v <= 1.0001; v += 0.25) {
    el('line', { x1: left, x2: right, y1: Y(v), y2: Y(v), stroke: '#eceef2' }, svg);
    el('text', { x: left - 6, y: Y(v) + 4, 'text-anchor': 'end', 'font-size': 12, fill: '#5b6475', 'font-family': 'sans-serif' }, svg, v.toFixed(2));
  }
  el('rect', { x: left, y: top, width: right - left, height: bottom - top, fill: 'none', stroke: '#9aa6bd' }, svg);
  el('text', { x: (left + right) / 2, y: 330, 'text-anchor': 'middle', 'font-size': 13, fill: '#1d2330', 'font-family': 'sans-serif' }, svg, 'wavelength (nm)');
  el('text', { x: 14, y: (top + bottom) / 2, transform: `rotate(-90 14 ${(top + bottom) / 2})`, 'text-anchor': 'middle', 'font-size': 13, fill: '#1d2330', 'font-family': 'sans-serif' }, svg, 'relative power');
  for (const e of shown) {
    const r = e.result;
    for (const [key, opacity] of [['band95', 0.12], ['band68', 0.22]]) {
      const b = band(r, key);
      if (!b) continue;
      const pts = r.wavelength_nm.map((w, i) => `${X(w).toFixed(2)},${Y(b.hi[i]).toFixed(2)}`)
        .concat(r.wavelength_nm.map((w, i) => `${X(w).toFixed(2)},${Y(b.lo[i]).toFixed(2)}`).reverse());
      el('polygon', { class: 'band', 'data-band': key, points: pts.join(' '), fill: e.color, 'fill-opacity': opacity, stroke: 'none' }, svg);
    }
    el('polyline', {
      class: 'spd', 'data-entry': e.name, fill: 'none', stroke: e.color, 'stroke-width': e.id === state.selected ? 2.5 : 1.6,
      points: r.wavelength_nm.map((w, i) => `${X(w).toFixed(3)},${Y(r.spd[i]).toFixed(3)}`).join(' '),
    }, svg);
  }
  const ref = state.reference;
  if (ref) {
    const m = Math.max(...ref.wl.map((w, i) => (w >= x0 && w <= x1 ? ref.v[i] : -Infinity)));
    const pts = ref.wl.map((w, i) => [w, ref.v[i]]).filter(([w]) => w >= x0 && w <= x1)
      .map(([w, v]) => `${X(w).toFixed(2)},${Y(v / m).toFixed(2)}`);
    el('polyline', { class: 'reference', fill: 'none', stroke: '#1d2330', 'stroke-dasharray': '5 4', 'stroke-width': 1.5, points: pts.join(' ') }, svg);
  }
  let ly = top + 14;
  for (const e of shown.slice(0, 8)) {
    el('line', { x1: right - 170, x2: right - 150, y1: ly - 4, y2: ly - 4, stroke: e.color, 'stroke-width': 2.5 }, svg);
    el('text', { x: right - 145, y: ly, 'font-size': 12, fill: '#1d2330', 'font-family': 'sans-serif' }, svg, e.name.slice(0, 24));
    ly += 16;
  }
  if (ref) {
    el('line', { x1: right - 170, x2: right - 150, y1: ly - 4, y2: ly - 4, stroke: '#1d2330', 'stroke-dasharray': '5 4' }, svg);
    el('text', { x: right - 145, y: ly, 'font-size': 12, fill: '#1d2330', 'font-family': 'sans-serif' }, svg, `reference: ${ref.name.slice(0, 16)}`);
  }
}

const XY_BOX = { left: 44, right: 388, top: 10, bottom: 392, xmax: 0.8, ymax: 0.9 };

function renderXy() {
  const svg = $('xy-plot');
  svg.replaceChildren();
  const { left, right, top, bottom, xmax, ymax } = XY_BOX;
  const X = (x) => left + (x / xmax) * (right - left);
  const Y = (y) => bottom - (y / ymax) * (bottom - top);
  el('rect', { x: 0, y: 0, width: 400, height: 420, fill: '#fff' }, svg);
  for (let v = 0; v <= 0.80001; v += 0.1) {
    el('line', { x1: X(v), x2: X(v), y1: top, y2: bottom, stroke: '#eceef2' }, svg);
    el('text', { x: X(v), y: bottom + 14, 'text-anchor': 'middle', 'font-size': 11, fill: '#5b6475', 'font-family': 'sans-serif' }, svg, v.toFixed(1));
  }
  for (let v = 0; v <= 0.90001; v += 0.1) {
    el('line', { x1: left, x2: right, y1: Y(v), y2: Y(v), stroke: '#eceef2' }, svg);
    el('text', { x: left - 5, y: Y(v) + 4, 'text-anchor': 'end', 'font-size': 11, fill: '#5b6475', 'font-family': 'sans-serif' }, svg, v.toFixed(1));
  }
  el('text', { x: (left + right) / 2, y: 418, 'text-anchor': 'middle', 'font-size': 12, 'font-family': 'sans-serif' }, svg, 'x');
  el('text', { x: 10, y: (top + bottom) / 2, 'font-size': 12, 'font-family': 'sans-serif' }, svg, 'y');
  if (state.locus) {
    const spectral = state.locus.spectral;
    el('polygon', { class: 'locus', points: spectral.map((p) => `${X(p[1]).toFixed(2)},${Y(p[2]).toFixed(2)}`).join(' '), fill: '#f7f3ea', stroke: '#1d2330', 'stroke-width': 1 }, svg);
    for (const p of spectral) {
      if (![460, 480, 500, 520, 540, 560, 580, 600, 620].includes(p[0])) continue;
      el('text', { x: X(p[1]) + (p[1] < 0.2 ? -6 : 6), y: Y(p[2]) + 4, 'text-anchor': p[1] < 0.2 ? 'end' : 'start', 'font-size': 10, fill: '#5b6475', 'font-family': 'sans-serif' }, svg, p[0]);
    }
    el('polyline', { class: 'planckian', points: state.locus.planckian.map((p) => `${X(p[1]).toFixed(2)},${Y(p[2]).toFixed(2)}`).join(' '), fill: 'none', stroke: '#8a5a00', 'stroke-width': 1 }, svg);
  }
  for (const e of state.entries.filter((en) => en.result && en.visible)) {
    const [x, y] = e.result.colorimetry.xy;
    el('circle', { class: 'xy-point', 'data-entry': e.name, cx: X(x), cy: Y(y), r: e.id === state.selected ? 5 : 4, fill: e.color, stroke: '#fff', 'stroke-width': 1 }, svg);
  }
}

function row(table, label, value, id) {
  const tr = html('tr', {}, table);
  html('th', {}, tr, label);
  const td = html('td', id ? { id } : {}, tr, value);
  return td;
}

/** Readable names of the lighting metrics' keys; other keys are shown as they are. */
const METRIC_LABELS = {
  cct_k: 'CCT (K)', duv: 'Duv', cri_ra: 'CRI Ra', tm30_rf: 'TM-30 Rf', tm30_rg: 'TM-30 Rg',
  mel_der: 'melanopic DER', sp_ratio: 'S/P ratio', ppf_per_lux: 'PPF per lux (µmol s⁻¹ m⁻² lx⁻¹)',
  blh_efficacy_w_per_lm: 'blue-light hazard efficacy (W/lm)', alpha_opic_der: 'α-opic DER',
  alpha_opic_elr_mw_per_lm: 'α-opic ELR (mW/lm)', reasons: 'not given:',
};

/** A metric's number as the page shows it. */
function metricNumber(v) {
  return Math.abs(v) >= 100 ? v.toFixed(0) : v.toPrecision(4);
}

/**
 * A metrics object (possibly nested) as table rows; lists (per-sample values) are left out.
 * `intervals` (the estimate's `metric_uncertainty`) adds "± half-width" (95 %) to top-level values.
 */
function metricRows(table, obj, prefix, intervals) {
  for (const [k, v] of Object.entries(obj)) {
    if (k === 'warnings') continue;
    const label = prefix ? `${prefix} ${METRIC_LABELS[k] || k}` : METRIC_LABELS[k] || k;
    if (v && typeof v === 'object' && !Array.isArray(v)) metricRows(table, v, label);
    else if (typeof v === 'number') {
      const half = !prefix && intervals && intervals[k] ? intervals[k].half95 : null;
      const shown = half != null ? `${metricNumber(v)} ± ${metricNumber(half)}` : metricNumber(v);
      row(table, label, shown, prefix ? undefined : `metric-${k}`);
    } else if (typeof v === 'string' || typeof v === 'boolean') row(table, label, String(v));
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
  if (r.verdict) html('p', { class: 'verdict', id: 'verdict' }, box, `Verdict: ${r.verdict}`);
  if (Array.isArray(r.reasons) && r.reasons.length) {
    const ul = html('ul', { class: 'warnings' }, box);
    r.reasons.forEach((t) => html('li', {}, ul, t));
  }
  const table = html('table', {}, box);
  const c = r.colorimetry;
  row(table, 'CIE 1931 x', fmt(c.xy[0], 4), 'xy-x');
  row(table, 'CIE 1931 y', fmt(c.xy[1], 4), 'xy-y');
  row(table, 'CCT', c.cct != null ? `${fmt(c.cct, 0)} K` : 'none (far from the Planckian locus)', 'cct');
  row(table, 'Duv', c.duv != null ? (c.duv >= 0 ? '+' : '') + fmt(c.duv, 4) : '–', 'duv');
  if (typeof r.expected_gfc === 'number') row(table, 'expected GFC', fmt(r.expected_gfc, 3), 'expected-gfc');
  if (typeof r.band_widening === 'number' && r.band_widening > 1) {
    // The light found explains this photo worse than the calibration photos: wider bands.
    row(table, 'bands widened', `${fmt(r.band_widening, 1)}×`, 'band-widening');
  }
  if (r.absolute) {
    // Approximate absolute levels from the photo's EXIF exposure (see the JSON's note).
    row(table, 'illuminance (approx.)', `${fmt(r.absolute.illuminance_lux, 0)} lx`, 'illuminance');
    if (r.absolute.ppfd_umol_m2_s != null) row(table, 'PPFD (approx.)', `${fmt(r.absolute.ppfd_umol_m2_s, 1)} µmol m⁻² s⁻¹`);
    if (r.absolute.melanopic_edi_lux != null) row(table, 'melanopic EDI (approx.)', `${fmt(r.absolute.melanopic_edi_lux, 0)} lx`);
  }
  if (r.photo) {
    row(table, 'chart', r.photo.chart);
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
  if (r.metrics && typeof r.metrics === 'object') {
    html('h2', {}, box, 'Lighting metrics');
    metricRows(html('table', { id: 'metrics' }, box), r.metrics, '', r.metric_uncertainty);
    if (r.metric_uncertainty) html('p', { class: 'note' }, box, '± : the 95 % interval of the metric, calibrated on held-out lamps.');
  }
  const warnings = ((r.photo && r.photo.warnings) || []).concat((r.metrics && r.metrics.warnings) || []);
  if (warnings.length) {
    html('h2', {}, box, 'Warnings');
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
  button('Report', 'download-report', () => save(new Blob([report(e)], { type: 'text/html' }), `${stem}.report.html`));
}

/** The SPD as spectral CSV, as `spdcam estimate --output` writes it. */
function spdCsv(r) {
  const lines = [`wavelength_nm,${r.name.includes(',') ? `"${r.name.replace(/"/g, '""')}"` : r.name}`];
  r.wavelength_nm.forEach((w, i) => lines.push(`${w},${r.spd[i]}`));
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

function escapeHtml(s) {
  return String(s).replace(/[&<>"]/g, (ch) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' }[ch]));
}

/** A one-page HTML report of an estimate: the details table, the plots, the warnings. */
function report(e) {
  const details = $('summary').querySelector('table');
  const metrics = $('metrics');
  const warnings = $('warnings');
  return `<!doctype html><html lang="en"><head><meta charset="utf-8"><title>spdcam: ${escapeHtml(e.name)}</title>
<style>body{font:14px sans-serif;max-width:900px;margin:20px auto;color:#1d2330}table{border-collapse:collapse}td,th{text-align:left;padding:2px 8px;border-bottom:1px solid #ddd}svg{width:48%;vertical-align:top}.warnings li{color:#8a5a00}</style></head>
<body><h1>The light in ${escapeHtml(e.name)}</h1>
<p>Estimated by spdcam (${escapeHtml(e.result.model)}) on ${escapeHtml(new Date().toISOString().slice(0, 10))}.</p>
${svgText($('spd-plot'))}${svgText($('xy-plot'))}
${details ? details.outerHTML : ''}${metrics ? `<h2>Lighting metrics</h2>${metrics.outerHTML}` : ''}
${warnings ? `<h2>Warnings</h2>${warnings.outerHTML}` : ''}</body></html>`;
}

async function start() {
  setupInputs();
  render();
  try {
    state.locus = await (await fetch('api/locus')).json();
  } catch (err) {
    state.locus = null;
  }
  renderXy();
}

start();
