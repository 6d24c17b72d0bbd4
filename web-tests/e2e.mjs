// End-to-end tests of the `spdcam serve` page in headless Chromium, as a person would use it.
// Usage: node e2e.mjs URL EXPECTED.json PHOTO TRUTH.csv ARTEFACT_DIR REPORT.html CLI.csv
// EXPECTED.json is `spdcam estimate --json PHOTO` (an array of one estimate), REPORT.html
// `spdcam estimate --report REPORT.html PHOTO` (opened offline from its file), CLI.csv
// `spdcam estimate -o CLI.csv PHOTO`. A photo where detection fails is made from PHOTO in
// the browser (see `noChartPhoto`).
import { chromium } from 'playwright-core';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { pathToFileURL } from 'node:url';

const [url, expectedPath, photoPath, truthPath, artefacts, reportPath, csvPath] = process.argv.slice(2);
if (!csvPath) {
  console.error('usage: node e2e.mjs URL EXPECTED.json PHOTO TRUTH.csv ARTEFACT_DIR REPORT.html CLI.csv');
  process.exit(2);
}
const expected = JSON.parse(readFileSync(expectedPath, 'utf8'))[0];
const results = [];

function check(condition, message) {
  if (!condition) throw new Error(message);
}

function close(a, b, tol, what) {
  check(Math.abs(a - b) <= tol, `${what}: ${a} shown, ${b} expected (tolerance ${tol})`);
}

async function test(name, body) {
  const started = Date.now();
  try {
    await body();
    results.push(true);
    console.log(`ok - ${name} (${Date.now() - started} ms)`);
  } catch (e) {
    results.push(false);
    console.log(`not ok - ${name}: ${e.stack || e}`);
  }
}

/** The SPD drawn for `entry` in the plot, as [wavelength, value] pairs (inverting the plot's
 *  mapping: x over the estimate's wavelength range, y over 0…1 in the plot box). */
async function plottedSpd(page, entry) {
  return page.evaluate((name) => {
    const line = [...document.querySelectorAll('#spd-plot polyline.spd')].find((l) => l.dataset.entry === name);
    if (!line) return null;
    return line.getAttribute('points').split(' ').map((p) => p.split(',').map(Number));
  }, entry);
}

const text = async (page, selector) => (await page.locator(selector).textContent()).trim();

/** Words of the command line that a person using the page cannot type. */
const COMMAND_LINE = /--[a-z]|spdcam (serve|estimate)|\bcargo\b/;

/** The metric cells of the CLI's report of the example: {key: shown text}. */
async function reportCells() {
  const tab = await context.newPage();
  await tab.goto(pathToFileURL(reportPath).href);
  const cells = await tab.evaluate(() => Object.fromEntries([...document.querySelectorAll('#estimate-1 table.metrics td[data-key]')]
    .map((td) => [td.dataset.key, td.textContent.trim()])));
  await tab.close();
  return cells;
}

/** The pages of a PDF, by pdfinfo (poppler-utils). */
function pdfPages(path) {
  const info = execFileSync('pdfinfo', [path], { encoding: 'utf8' });
  const m = info.match(/^Pages:\s+(\d+)/m);
  if (!m) throw new Error(`pdfinfo gave no page count: ${info}`);
  return Number(m[1]);
}

/** Prints `tab` to PDF on A4 and on Letter (the report's @page margins, Chromium's own
 *  print layout) and gives the page counts. */
async function printedPages(tab, label) {
  const counts = {};
  for (const format of ['A4', 'Letter']) {
    const path = join(artefacts, `${label}.${format}.pdf`);
    await tab.emulateMedia({ media: 'print' });
    await tab.pdf({ path, format, printBackground: true });
    counts[format] = pdfPages(path);
  }
  await tab.emulateMedia({ media: 'screen' });
  return counts;
}

/** For every metric the presentation marks not meaningful: the page shows no number for it,
 *  and its raw value appears nowhere in the text of `scope` (in any usual rounding). */
async function checkNotMeaningful(tab, scope, result) {
  const walked = await tab.evaluate((scope) => [...document.querySelectorAll(`${scope} tr.not-meaningful`)].map((tr) => ({
    key: tr.dataset.key || tr.querySelector('[data-key]').dataset.key,
    value: [...tr.querySelector('td').childNodes].filter((n) => n.nodeType === 3).map((n) => n.textContent).join('').trim(),
    reason: (tr.querySelector('.reason') || {}).textContent || '',
  })), scope);
  const wanted = result.presentation.groups.flatMap((g) => g.metrics).filter((m) => m.value === null).map((m) => m.key);
  check(JSON.stringify(walked.map((w) => w.key).sort()) === JSON.stringify(wanted.slice().sort()),
    `greyed ${walked.map((w) => w.key)}, not meaningful ${wanted}`);
  const all = await tab.locator(scope).innerText();
  for (const w of walked) {
    check(w.value === '—', `${w.key} shows '${w.value}' though not meaningful`);
    check(/not meaningful|not determinable|no colour temperature|not defined|undefined|cannot|no /.test(w.reason), `${w.key}: reason '${w.reason}'`);
    const raw = w.key === 'cri_r9' ? result.metrics.cri_r && result.metrics.cri_r[8] : result.metrics[w.key];
    if (typeof raw !== 'number') continue;
    const forms = new Set([raw.toFixed(1), raw.toFixed(2), raw.toPrecision(4)]);
    if (Math.abs(raw) >= 100) forms.add(raw.toFixed(0));
    for (const f of forms) {
      const re = new RegExp(`(^|[^0-9.])${f.replace('.', '\\.')}($|[^0-9])`);
      check(!re.test(all), `${w.key}'s value ${f} is shown though not meaningful`);
    }
  }
  return walked.length;
}

const profile = mkdtempSync(join(tmpdir(), 'spdcam-chromium-'));
// A fresh profile (--user-data-dir) each run, given as Playwright asks for it.
const context = await chromium.launchPersistentContext(profile, {
  executablePath: '/usr/bin/chromium',
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  viewport: { width: 1500, height: 1000 },
  acceptDownloads: true,
});
/**
 * The example photo blurred (a Gaussian of 40 px): the patches' edges are gone, so no chart
 * is found, yet the chart is there, its patches flat in their middles, and its corners are
 * the sharp photo's. Made in the browser (canvas, JPEG) into a file. (A mirrored chart is
 * found by no one: its patches are not the chart's, and placed corners are refused.)
 */
async function noChartPhoto() {
  const tab = await context.newPage();
  await tab.goto(url);
  const data = await tab.evaluate(async () => {
    const img = new Image();
    img.src = 'example.jpg';
    await img.decode();
    const canvas = document.createElement('canvas');
    canvas.width = img.naturalWidth;
    canvas.height = img.naturalHeight;
    const ctx = canvas.getContext('2d');
    ctx.filter = 'blur(40px)';
    ctx.drawImage(img, 0, 0);
    return canvas.toDataURL('image/jpeg', 0.92).split(',')[1];
  });
  await tab.close();
  const path = join(artefacts, 'no-chart.jpg');
  writeFileSync(path, Buffer.from(data, 'base64'));
  return path;
}
const noChartPath = await noChartPhoto();

const page = await context.newPage();
const pageErrors = [];
page.on('pageerror', (e) => pageErrors.push(e.message));
// Nothing but the local server may be asked for.
const origin = new URL(url).origin;
const foreign = [];
page.on('request', (r) => {
  if (!r.url().startsWith(origin) && !r.url().startsWith('blob:') && !r.url().startsWith('data:')) foreign.push(r.url());
});

/** Opens the page in a new tab, clicks "Try the example photo" and waits for its SPD; the
 *  time taken is printed (a measurement, not a pass/fail condition: the goal is 2 s). */
async function timeExample(label) {
  const tab = await context.newPage();
  const t0 = Date.now();
  await tab.goto(url);
  await tab.click('#example');
  await tab.waitForSelector('#spd-plot polyline.spd');
  const ms = Date.now() - t0;
  console.log(`# page open → example SPD shown (${label}): ${ms} ms`);
  return tab;
}

await test('opening the page and trying the example shows its SPD and details', async () => {
  const tab = await timeExample('first tab of a fresh browser');
  check(await text(tab, '#xy-x') === expected.colorimetry.xy[0].toFixed(4), 'x of the example');
  await tab.screenshot({ path: join(artefacts, 'example.png'), fullPage: true });
  await tab.close();
  await (await timeExample('second tab')).close();
});

await test('an uploaded photo shows the SPD and xy of `spdcam estimate --json` and the metrics of its report', async () => {
  await page.goto(url);
  await page.setInputFiles('#files', photoPath);
  await page.waitForSelector('#metrics');
  const c = expected.colorimetry;
  check(await text(page, '#xy-x') === c.xy[0].toFixed(4), `x ${await text(page, '#xy-x')} vs ${c.xy[0]}`);
  check(await text(page, '#xy-y') === c.xy[1].toFixed(4), `y ${await text(page, '#xy-y')} vs ${c.xy[1]}`);
  // Every metric the same as in the CLI's report: the rounded value with its unit, or '—'.
  const cells = await reportCells();
  const keys = Object.keys(cells);
  check(keys.length >= 10, `the report shows ${keys.length} metrics`);
  for (const key of keys) {
    const shown = (await page.locator(`#metric-${key}`).evaluate((td) => td.firstChild.textContent)).trim();
    check(shown === cells[key], `${key}: the page shows '${shown}', the report '${cells[key]}'`);
  }
  // The groups in their order, with a line of explanation each.
  const groups = await page.locator('#metrics tr.group').allTextContents();
  check(JSON.stringify(groups) === JSON.stringify(['Colour', 'Colour rendering', 'Circadian and eye', 'Plants']), `groups ${groups}`);
  check(await page.locator('#metrics tr.metric .explain').count() === keys.length, 'a metric without explanation');
  const points = await plottedSpd(page, expected.name);
  check(points && points.length === expected.spd.length, `plotted ${points && points.length} points`);
  const wl = expected.wavelength_nm;
  const [left, right, top, bottom] = (await page.locator('#spd-plot').getAttribute('data-frame')).split(',').map(Number);
  const yTop = Number(await page.locator('#spd-plot').getAttribute('data-top'));
  check(yTop >= 1, `plot top ${yTop}`);
  points.forEach(([x, y], i) => {
    close(wl[0] + ((x - left) / (right - left)) * (wl[wl.length - 1] - wl[0]), wl[i], 1e-3, `wavelength ${i}`);
    close(((bottom - y) / (bottom - top)) * yTop, expected.spd[i], 1e-4, `SPD at ${wl[i]} nm`);
  });
  // The bands stay inside the frame, and the legend lies above it (it covers no curve).
  const inside = await page.evaluate(({ top, bottom }) => [...document.querySelectorAll('#spd-plot polygon.band')].every((p) => p.getAttribute('points').split(' ').every((q) => {
    const y = Number(q.split(',')[1]);
    return y >= top - 1e-6 && y <= bottom + 1e-6;
  })), { top, bottom });
  check(inside, 'a band leaves the plot frame');
  const legend = await page.evaluate(() => [...document.querySelectorAll('#spd-plot g.legend')].map((g) => [g.textContent, g.getBBox().y + g.getBBox().height]));
  check(legend.some(([t]) => t === '68 % band') && legend.some(([t]) => t === '95 % band'), `legend ${JSON.stringify(legend)}`);
  check(legend.every(([, b]) => b <= top), `the legend reaches into the frame: ${JSON.stringify(legend)}`);
  // The point on the u′v′ diagram: u′ = 4x / (−2x + 12y + 3).
  const u = await page.locator('#uv-plot circle.estimate-point').first().getAttribute('data-u');
  close(Number(u), 4 * c.xy[0] / (-2 * c.xy[0] + 12 * c.xy[1] + 3), 1e-4, 'u′ on the diagram');
  // The CSV download carries the exact numbers and the band columns of the CLI's -o CSV.
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#download-csv')]);
  const csv = readFileSync(await download.path(), 'utf8').trim().split('\n');
  const cli = readFileSync(csvPath, 'utf8').trim().split('\n');
  const n = expected.name;
  check(csv[0] === `wavelength_nm,${n},${n}_lower68,${n}_upper68,${n}_lower95,${n}_upper95`, `CSV header ${csv[0]}`);
  check(csv[0] === cli[0], `CSV header ${csv[0]}, the CLI's ${cli[0]}`);
  check(csv.length === cli.length, `${csv.length} CSV lines, the CLI ${cli.length}`);
  csv.slice(1).forEach((line, i) => {
    const v = line.split(',').map(Number);
    const want = cli[i + 1].split(',').map(Number);
    check(v[0] === wl[i] && v[1] === expected.spd[i], `CSV row ${i}: ${line}`);
    check(v[2] === expected.band68.lower[i] && v[5] === expected.band95.upper[i], `CSV bands row ${i}: ${line}`);
    want.forEach((w, k) => close(v[k], w, 1e-9, `CSV row ${i} column ${k}`));
  });
  const [json] = await Promise.all([page.waitForEvent('download'), page.click('#download-json')]);
  const saved = JSON.parse(readFileSync(await json.path(), 'utf8'));
  check(JSON.stringify(saved.spd) === JSON.stringify(expected.spd), 'JSON download differs from the CLI');
  const [png] = await Promise.all([page.waitForEvent('download'), page.click('#download-png')]);
  const bytes = readFileSync(await png.path());
  check(bytes.subarray(1, 4).toString() === 'PNG' && bytes.length > 2000, `PNG download of ${bytes.length} bytes`);
  await page.screenshot({ path: join(artefacts, 'estimate.png'), fullPage: true });
});

await test('a reference SPD is overlaid with GFC and RMSE equal to the CLI truth score', async () => {
  await page.setInputFiles('#reference', truthPath);
  await page.waitForSelector('#ref-gfc');
  check(await page.locator('#spd-plot polyline.reference').count() === 1, 'no reference line');
  close(Number(await text(page, '#ref-gfc')), expected.truth.gfc, 6e-4, 'GFC');
  close(Number(await text(page, '#ref-rmse')), expected.truth.rmse, 6e-4, 'RMSE');
  await page.screenshot({ path: join(artefacts, 'reference.png'), fullPage: true });
});

await test('dragging a corner re-runs the estimate with those corners', async () => {
  const before = await plottedSpd(page, expected.name);
  const handle = page.locator('#stage circle.handle[data-corner="0"]');
  await handle.scrollIntoViewIfNeeded();
  const box = await handle.boundingBox();
  check(box, 'no corner handle');
  const [cx, cy] = [box.x + box.width / 2, box.y + box.height / 2];
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  // A small move, the corner still on the chart's (a corner dragged off the chart is refused:
  // the patches inside are not the chart's).
  await page.mouse.move(cx + 4, cy + 3, { steps: 5 });
  await page.mouse.move(cx + 8, cy + 6, { steps: 5 });
  await page.mouse.up();
  await page.waitForFunction(() => {
    const m = document.getElementById('method');
    return m && m.textContent === 'your corners';
  }, null, { timeout: 30000 });
  const after = await plottedSpd(page, expected.name);
  check(JSON.stringify(before) !== JSON.stringify(after), 'the SPD did not change');
  check(await text(page, '#xy-x') !== '', 'no x shown');
  await page.screenshot({ path: join(artefacts, 'corners.png'), fullPage: true });
});

await test('naming the kind of light estimates the photos again with it', async () => {
  const tab = await context.newPage();
  await tab.goto(url);
  await tab.setInputFiles('#files', photoPath);
  await tab.waitForSelector('#metrics');
  const points = () => tab.evaluate(() => {
    const line = document.querySelector('#spd-plot polyline.spd');
    return line ? line.getAttribute('points') : null;
  });
  const before = await points();
  // The estimate the page holds, as its JSON download gives it.
  const saved = async () => {
    const [json] = await Promise.all([tab.waitForEvent('download'), tab.click('#download-json')]);
    return JSON.parse(readFileSync(await json.path(), 'utf8'));
  };
  check(!('light' in (await saved())), 'a kind of light before one was named');
  await tab.selectOption('#light', 'luminaire');
  const changed = (want, same) => tab.waitForFunction(({ w, s }) => {
    const line = document.querySelector('#spd-plot polyline.spd');
    return line && (line.getAttribute('points') === w) === s;
  }, { w: want, s: same }, { timeout: 30000 });
  await changed(before, false);
  check((await saved()).light === 'luminaire', 'the estimate was not told the kind');
  // Back to "don't know": the estimate without a kind again.
  await tab.selectOption('#light', 'unknown');
  await changed(before, true);
  check(!('light' in (await saved())), 'a kind of light after "don\'t know"');
  check(await points() === before, 'the SPD without a kind differs from the first');
  await tab.close();
});

await test('a file that is no image shows a plain error in the page', async () => {
  await page.setInputFiles('#files', { name: 'notes.txt', mimeType: 'text/plain', buffer: Buffer.from('these are notes, not a photo') });
  const error = page.locator('#list li').filter({ hasText: 'notes.txt' }).locator('.error');
  await error.waitFor({ timeout: 30000 });
  const message = await error.textContent();
  check(message === 'This file is not a photo the page can read: use a JPEG, PNG, TIFF or a camera raw file (DNG, CR2, CR3, NEF, ARW, RAF, …).', message);
  // The earlier estimate is still there and the page still works.
  check(await page.locator('#spd-plot polyline.spd').count() >= 1, 'the earlier SPD vanished');
  await page.screenshot({ path: join(artefacts, 'error.png'), fullPage: true });
});

await test('several photos share one plot', async () => {
  await page.setInputFiles('#files', [photoPath, photoPath]);
  await page.waitForFunction(() => document.querySelectorAll('#spd-plot polyline.spd').length >= 3, null, { timeout: 30000 });
  check(await page.locator('#uv-plot circle.estimate-point').count() >= 1, 'no point on the u′v′ diagram');
});

await test('a photo of three charts gives an entry per place and says how the places compare', async () => {
  const tab = await context.newPage();
  await tab.goto(url);
  await tab.setInputFiles('#files', join(dirname(photoPath), 'cc24-two-lights.jpg'));
  await tab.waitForFunction(() => document.querySelectorAll('#list li').length === 3 && !document.querySelector('#list li .status')?.textContent.includes('…'), null, { timeout: 60000 });
  const names = await tab.locator('#list li .name').allInnerTexts();
  check(JSON.stringify(names) === JSON.stringify([1, 2, 3].map((k) => `cc24-two-lights.jpg place ${k}`)), `entries ${names}`);
  await tab.waitForSelector('#across-places');
  const across = await text(tab, '#across-places');
  check(/The light across the 3 places/.test(across) && /the lights differ/.test(across), `comparison '${across}'`);
  check(/light level against the brightest place: place 1 \d+ %, place 2 100 %, place 3 \d+ %/.test(across), `levels '${across}'`);
  await tab.locator('#list li').nth(2).click();
  check((await text(tab, '#photo-title')) === 'cc24-two-lights.jpg place 3', 'the third place is not shown when chosen');
  await tab.close();
});

await test('the summary says in plain words what the light is and how good the estimate is', async () => {
  const tab = await context.newPage();
  await tab.goto(url);
  await tab.click('#example');
  await tab.waitForSelector('#plain-summary.plain-summary');
  const summary = await text(tab, '#plain-summary');
  check(/light with an? [a-zA-Z ,()-]+ spectrum/.test(summary), `summary '${summary}'`);
  check(/good to about ±\d+ % of the spectrum's peak/.test(summary), `summary '${summary}'`);
  // The same words as the report, which has them from the same source.
  const report = await context.newPage();
  await report.goto(pathToFileURL(reportPath).href);
  check(await text(report, '#estimate-1 .summary') === summary, 'the report says otherwise');
  const verdict = await tab.locator('#verdict').getAttribute('data-verdict');
  check(verdict === expected.verdict, `verdict ${verdict}, the CLI ${expected.verdict}`);
  check((await text(tab, '#verdict')).startsWith('Verdict: '), 'no verdict headline');
  check(/goodness-of-fit coefficient/.test(await text(tab, '#gfc-words')), 'the GFC is not explained');
  // Above the photo and the plots.
  const [s, p] = await Promise.all(['#overview', '#plots'].map((sel) => tab.locator(sel).boundingBox()));
  check(s.y < p.y, 'the summary is not at the top');
  await tab.screenshot({ path: join(artefacts, 'summary.png') });
  await report.close();
  await tab.close();
});

await test('no metric shows a number where it is not meaningful, on the page and in the reports', async () => {
  const tab = await context.newPage();
  await tab.goto(url);
  await tab.click('#example');
  await tab.waitForSelector('#metrics');
  const result = await tab.evaluate(() => fetch('example.jpg').then((r) => r.blob()).then((b) => {
    const form = new FormData();
    form.append('photo', new File([b], 'cc24-led.jpg'));
    return fetch('api/estimate', { method: 'POST', body: form }).then((r) => r.json());
  }));
  const greyed = await checkNotMeaningful(tab, 'main', result);
  // A light far from the Planckian locus (the SG example, a purple LED mix): at least CCT
  // and Ra are greyed on the page, with no number of theirs anywhere.
  const sgPath = join(dirname(photoPath), 'sg-telelumen.jpg');
  const coloured = await context.newPage();
  await coloured.goto(url);
  await coloured.setInputFiles('#files', sgPath);
  await coloured.waitForSelector('#metrics');
  const form = new FormData();
  form.append('photo', new Blob([readFileSync(sgPath)]), 'sg-telelumen.jpg');
  const sgResult = await (await fetch(new URL('api/estimate', url), { method: 'POST', body: form })).json();
  const sgGreyed = await checkNotMeaningful(coloured, 'main', sgResult);
  check(sgGreyed >= 2, `${sgGreyed} metrics greyed for a coloured light`);
  await coloured.close();
  const cli = await context.newPage();
  await cli.goto(pathToFileURL(reportPath).href);
  check(await checkNotMeaningful(cli, '#estimate-1', result) === greyed, 'the CLI report greys other metrics');
  const [download] = await Promise.all([tab.waitForEvent('download'), tab.click('#download-report')]);
  const saved = join(artefacts, 'report-web-example.html');
  await download.saveAs(saved);
  const web = await context.newPage();
  await web.goto(pathToFileURL(saved).href);
  check(await checkNotMeaningful(web, '#estimate-1', result) === greyed, 'the web report greys other metrics');
  for (const t of [tab, cli, web]) await t.close();
});

await test('the report prints on one page on A4 and Letter, from the CLI and from the page', async () => {
  const cli = await context.newPage();
  await cli.goto(pathToFileURL(reportPath).href);
  const pages = await printedPages(cli, 'report-cli');
  check(pages.A4 === 1 && pages.Letter === 1, `the CLI report prints on ${JSON.stringify(pages)} pages`);
  // Nothing runs out of its column: the hue-bin and film/TV tables fit, R1–R15 drawn as 15
  // bars, or none for a light too far from white.
  await cli.emulateMedia({ media: 'print' });
  const overflow = await cli.evaluate(() => [...document.querySelectorAll('table')].filter((t) => t.scrollWidth > t.parentElement.clientWidth + 1).map((t) => t.className));
  await cli.emulateMedia({ media: 'screen' });
  check(overflow.length === 0, `tables wider than their column: ${overflow}`);
  // R9 has no bar where its interval is too wide: the caption gives the interval instead.
  const bars = await cli.locator('#estimate-1 svg.r-bars rect').count();
  const r9Note = /R9 not determinable from this photo \(between/.test(await cli.locator('#estimate-1').innerText());
  check(bars === 15 || (bars === 14 && r9Note) || bars === 0, `R1–R15: ${bars} bars`);
  await cli.close();
  // The page's report of one of two photos: that photo's name and curve only.
  const tab = await context.newPage();
  await tab.goto(url);
  const second = join(profile, 'second.jpg');
  writeFileSync(second, readFileSync(photoPath));
  await tab.setInputFiles('#files', [photoPath, second]);
  await tab.waitForFunction(() => document.querySelectorAll('#spd-plot polyline.spd').length === 2, null, { timeout: 60000 });
  await tab.locator('#list li').filter({ hasText: 'second.jpg' }).click();
  const [download] = await Promise.all([tab.waitForEvent('download'), tab.click('#download-report')]);
  check(download.suggestedFilename() === 'second.report.html', download.suggestedFilename());
  const saved = join(artefacts, 'report-web.html');
  await download.saveAs(saved);
  const web = await context.newPage();
  await web.goto(pathToFileURL(saved).href);
  check(await text(web, 'h1') === 'The light in second.jpg', `title ${await text(web, 'h1')}`);
  check(await web.locator('svg.spd-plot polyline.spd').count() === 1, 'the report plots another photo too');
  check(await web.locator('img.photo').count() === 1 && await web.locator('svg.tm30-cvg, [data-key="tm30_bins"]').count() >= 1, 'no photo or TM-30 part');
  check(await web.locator('.verdict').count() === 1, 'no verdict');
  const webPages = await printedPages(web, 'report-web');
  check(webPages.A4 === 1 && webPages.Letter === 1, `the page's report prints on ${JSON.stringify(webPages)} pages`);
  await web.screenshot({ path: join(artefacts, 'report-web.png'), fullPage: true });
  await web.close();
  await tab.close();
});

await test('a photo where no chart is found: shown large, four clicks, the chart asked, then estimated', async () => {
  const tab = await context.newPage();
  await tab.goto(url);
  await tab.setInputFiles('#files', noChartPath);
  await tab.waitForSelector('#placer[data-ready="1"]', { timeout: 60000 });
  const message = await text(tab, '#plain-summary');
  check(message.startsWith('No colour chart was found'), message);
  check(!COMMAND_LINE.test(message), message);
  const view = tab.locator('#placer');
  const box = await view.boundingBox();
  check(box.width > 700 && box.height > 350, `the photo is shown ${box.width} × ${box.height}`);
  // Zoom in around the middle and back out: the transform follows.
  const before = Number(await view.getAttribute('data-scale'));
  await tab.click('#zoom-in');
  check(Number(await view.getAttribute('data-scale')) > before, 'zoom in did nothing');
  await tab.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await tab.mouse.wheel(0, 300);
  await tab.click('#zoom-fit');
  // Pan: a drag moves the photo and places no corner.
  const x0 = Number(await view.getAttribute('data-x'));
  await tab.mouse.move(box.x + 200, box.y + 200);
  await tab.mouse.down();
  await tab.mouse.move(box.x + 260, box.y + 230, { steps: 6 });
  await tab.mouse.up();
  check(Number(await view.getAttribute('data-x')) > x0 + 50, 'the drag did not pan');
  check(await tab.locator('#placer circle.corner').count() === 0, 'the drag placed a corner');
  await tab.click('#zoom-fit');
  // Four clicks on the chart's corners (those the detection finds on the sharp photo).
  const toScreen = async ([px, py]) => {
    const [s, tx, ty] = await Promise.all(['data-scale', 'data-x', 'data-y'].map(async (a) => Number(await view.getAttribute(a))));
    const b = await view.boundingBox();
    return [b.x + tx + px * s, b.y + ty + py * s];
  };
  for (const [x, y] of expected.photo.corners) {
    const [cx, cy] = await toScreen([x, y]);
    await tab.mouse.click(cx, cy);
  }
  check(await tab.locator('#placer circle.corner').count() === 4, 'four corners not placed');
  // The photo is drawn where the clicks are mapped: its box is the transform's.
  const [imgBox, scale, tx] = [await tab.locator('#placer img').boundingBox(), Number(await view.getAttribute('data-scale')), Number(await view.getAttribute('data-x'))];
  const viewBox = await view.boundingBox();
  close(imgBox.width, expected.photo.width * scale, 1, 'the photo\'s drawn width');
  close(imgBox.x, viewBox.x + tx, 1, 'the photo\'s drawn left edge');
  await tab.waitForSelector('#chart-choice');
  check(await tab.locator('#estimate-corners').isDisabled(), 'the chart is guessed, not asked');
  await tab.screenshot({ path: join(artefacts, 'corners-placed.png') });
  await tab.check('input[name="chart"][value="colorchecker24"]');
  await tab.click('#estimate-corners');
  await tab.waitForFunction(() => {
    const m = document.getElementById('method');
    return m && m.textContent === 'your corners';
  }, null, { timeout: 60000 });
  check(await text(tab, '#chart') === 'ColorChecker 24', `chart ${await text(tab, '#chart')}`);
  check(await tab.locator('#spd-plot polyline.spd').count() === 1, 'no SPD');
  check(await tab.locator('#plain-summary.plain-summary').count() === 1, 'no summary');
  await tab.screenshot({ path: join(artefacts, 'corners-estimated.png'), fullPage: true });
  await tab.close();
});

await test('corners placed where no chart is: the page says why and asks for them again', async () => {
  // Issue 41: four clicks on an image with no chart gave a light and its numbers.
  const tab = await context.newPage();
  await tab.goto(url);
  const data = await tab.evaluate(() => {
    const canvas = document.createElement('canvas');
    canvas.width = 800;
    canvas.height = 600;
    const ctx = canvas.getContext('2d');
    const pixels = ctx.createImageData(800, 600);
    let seed = 41;
    for (let i = 0; i < pixels.data.length; i += 1) {
      seed = (seed * 1103515245 + 12345) % 2147483648;
      pixels.data[i] = i % 4 === 3 ? 255 : seed % 256;
    }
    ctx.putImageData(pixels, 0, 0);
    return canvas.toDataURL('image/png').split(',')[1];
  });
  const noise = join(artefacts, 'noise.png');
  writeFileSync(noise, Buffer.from(data, 'base64'));
  await tab.setInputFiles('#files', noise);
  await tab.waitForSelector('#placer[data-ready="1"]', { timeout: 60000 });
  const view = tab.locator('#placer');
  const place = async () => {
    for (const [px, py] of [[120, 100], [680, 110], [690, 500], [110, 480]]) {
      await tab.waitForSelector('#placer[data-ready="1"]');
      await view.scrollIntoViewIfNeeded();
      const [s, tx, ty] = await Promise.all(['data-scale', 'data-x', 'data-y'].map(async (a) => Number(await view.getAttribute(a))));
      const b = await view.boundingBox();
      await tab.mouse.click(b.x + tx + px * s, b.y + ty + py * s);
    }
  };
  await place();
  await tab.check('input[name="chart"][value="colorchecker24"]');
  await tab.click('#estimate-corners');
  await tab.waitForSelector('#stage p.error[role="alert"]', { timeout: 60000 });
  const why = await text(tab, '#stage p.error[role="alert"]');
  check(why.startsWith("These corners do not hold a ColorChecker 24: place them on the chart's four outer corners ("), why);
  check(!COMMAND_LINE.test(why), why);
  check((await text(tab, '#plain-summary')) === why, 'the summary does not say why');
  // No number: no SPD, no verdict; the corners cleared to be placed again, the chart kept.
  check(await tab.locator('#spd-plot polyline.spd').count() === 0, 'an SPD was drawn');
  check(await tab.locator('#verdict').count() === 0, 'a verdict was shown');
  await tab.waitForSelector('#placer[data-ready="1"]');
  check(await tab.locator('#placer circle.corner').count() === 0, 'the refused corners are still placed');
  await place();
  await tab.waitForFunction(() => document.querySelectorAll('#placer circle.corner').length === 4, null, { timeout: 10000 })
    .catch(() => check(false, 'the corners cannot be placed again'));
  check(await tab.isChecked('input[name="chart"][value="colorchecker24"]'), 'the chart named is forgotten');
  await tab.screenshot({ path: join(artefacts, 'not-the-chart.png') });
  await tab.close();
});

await test('every error message on the page is free of command-line words', async () => {
  const tab = await context.newPage();
  await tab.goto(url);
  const messages = [];
  // Not an image; no chart; larger than the server's limit (64 MB).
  const big = join(profile, 'big.jpg');
  writeFileSync(big, Buffer.alloc(65 << 20, 0xff));
  const notes = join(profile, 'notes.txt');
  writeFileSync(notes, 'not a photo');
  await tab.setInputFiles('#files', [notes, noChartPath, big]);
  await tab.waitForFunction(() => document.querySelectorAll('#list li .error').length === 3, null, { timeout: 120000 });
  messages.push(...await tab.locator('#list li .error').allTextContents());
  // The server's own answers, as the page receives them.
  const answers = await tab.evaluate(async () => {
    const form = (fields) => { const f = new FormData(); for (const [k, v] of fields) f.append(k, v); return f; };
    const photo = await (await fetch('example.jpg')).blob();
    const post = (fields) => fetch('api/jobs', { method: 'POST', body: form(fields) }).then((r) => r.json());
    return [
      await post([['photo', photo, 'p.jpg'], ['corners', '1,2,3']]),
      await post([['photo', photo, 'p.jpg'], ['chart', '/etc/passwd']]),
      await post([['other', 'x']]),
      await fetch('api/jobs/999999').then((r) => r.json()),
      await fetch('api/jobs/999999/report').then((r) => r.json()),
      await fetch('api/no/such/page').then((r) => r.json()),
    ];
  });
  for (const a of answers) {
    check(typeof a.message === 'string' && typeof a.error === 'string', JSON.stringify(a));
    messages.push(a.message);
  }
  check(messages.length === 9, `${messages.length} messages`);
  for (const m of messages) check(!COMMAND_LINE.test(m), `'${m}' names the command line`);
  check(messages.some((m) => m.includes('larger than this server accepts')), messages.join(' | '));
  await tab.screenshot({ path: join(artefacts, 'errors.png'), fullPage: true });
  await tab.close();
});

await test('the page asked for nothing outside the local server and raised no script error', async () => {
  check(foreign.length === 0, `requests elsewhere: ${foreign.join(', ')}`);
  check(pageErrors.length === 0, `script errors: ${pageErrors.join('; ')}`);
});

if (reportPath) {
  await test('the CLI report opens offline with its numbers, plots and photo', async () => {
    await context.setOffline(true);
    const tab = await context.newPage();
    const errors = [];
    const requests = [];
    tab.on('pageerror', (e) => errors.push(e.message));
    tab.on('request', (r) => {
      if (!r.url().startsWith('file:') && !r.url().startsWith('data:')) requests.push(r.url());
    });
    await tab.goto(pathToFileURL(reportPath).href, { waitUntil: 'load' });
    const shown = async (key) => (await tab.locator(`#estimate-1 [data-key="${key}"]`).first().textContent()).trim();
    const m = expected.metrics;
    const u = expected.metric_uncertainty;
    check(await shown('mel_der') !== '—' && (await shown('mel_der')).includes(' ± '), `melanopic DER ${await shown('mel_der')}`);
    close(Number((await shown('mel_der')).split(' ')[0]), m.mel_der, u.mel_der.half95 / 2, 'melanopic DER');
    check(await shown('gfc') === `GFC ${expected.truth.gfc.toFixed(4)}, RMSE ${expected.truth.rmse.toFixed(4)}`, `GFC ${await shown('gfc')}`);
    const size = (selector) => tab.evaluate((sel) => {
      const r = document.querySelector(sel).getBoundingClientRect();
      return [r.width, r.height];
    }, selector);
    for (const selector of ['#estimate-1 svg.spd-plot']) {
      const [w, h] = await size(selector);
      check(w > 0 && h > 0, `${selector} drawn ${w} × ${h}`);
    }
    check(await tab.locator('#estimate-1 svg.spd-plot polyline.spd').count() === 1, 'no SPD line');
    check(await tab.locator('#estimate-1 svg.spd-plot polyline.truth').count() === 1, 'no truth line');
    const legend = await tab.locator('#estimate-1 svg.spd-plot g.legend').allTextContents();
    check(JSON.stringify(legend) === JSON.stringify(['estimate', 'true spectrum', '68 % band', '95 % band']), `legend ${legend}`);
    const image = await tab.evaluate(() => {
      const img = document.querySelector('#estimate-1 img.photo');
      return img && img.complete ? img.naturalWidth : 0;
    });
    check(image > 0 && image <= 1200, `the photo is ${image} px wide`);
    await tab.screenshot({ path: join(artefacts, 'report.png'), fullPage: true });
    check(requests.length === 0, `the report asked for ${requests.join(', ')}`);
    check(errors.length === 0, `script errors: ${errors.join('; ')}`);
    await tab.close();
  });
}

await test('the page reads from 360 to 1,920 px: nothing spills out of its box, no command-line words', async () => {
  const input = page.locator('#files');
  const accept = (await input.getAttribute('accept')).split(',');
  check(accept[0] === 'image/*' && await input.getAttribute('capture') !== null, 'the file input offers no camera');
  check(['.dng', '.cr3', '.nef', '.arw'].every((e) => accept.includes(e)), `the file input does not offer raw files: ${accept}`);
  for (const width of [360, 768, 1400, 1920]) {
    // 360 px as a phone: a touch screen at twice the pixel density.
    const phone = width === 360;
    const ctx = await chromium.launch({ executablePath: '/usr/bin/chromium', args: ['--headless', '--no-sandbox', '--disable-gpu'] });
    const view = await ctx.newContext({ viewport: { width, height: phone ? 740 : 1000 }, isMobile: phone, hasTouch: phone, deviceScaleFactor: phone ? 2 : 1 });
    const tab = await view.newPage();
    await tab.goto(url);
    await tab.click('#example');
    await tab.waitForSelector('#metrics');
    const spills = await tab.evaluate(() => {
      const out = [];
      if (document.documentElement.scrollWidth > window.innerWidth + 1) out.push(`the page is ${document.documentElement.scrollWidth} px wide`);
      for (const section of document.querySelectorAll('main > section')) {
        const box = section.getBoundingClientRect();
        for (const el of section.querySelectorAll('*')) {
          const r = el.getBoundingClientRect();
          // Inside a drawing only the drawing's own box counts (its clipped parts report their full size).
          if (r.width === 0 || getComputedStyle(el).position === 'absolute' || (el.closest('svg') && el.closest('svg') !== el)) continue;
          if (r.right > box.right + 1 || r.left < box.left - 1) out.push(`${el.tagName.toLowerCase()}#${el.id}.${el.className && el.className.baseVal === undefined ? el.className : ''} (${Math.round(r.left)}–${Math.round(r.right)} in ${Math.round(box.left)}–${Math.round(box.right)})`);
        }
      }
      return out;
    });
    check(spills.length === 0, `${width} px: ${spills.slice(0, 5).join('; ')}`);
    // Every drawing's text at least 11 px high as shown (its font size times the drawing's
    // scale on screen).
    const small = await tab.evaluate(() => [...document.querySelectorAll('main svg text')].map((t) => {
      // The drawing's scale on screen, whatever the text's rotation.
      const m = t.getScreenCTM();
      const px = parseFloat(getComputedStyle(t).fontSize) * Math.hypot(m.a, m.b);
      return [t.textContent, Math.round(px * 10) / 10];
    }).filter(([, px]) => px < 11));
    check(small.length === 0, `${width} px: text below 11 px: ${JSON.stringify(small.slice(0, 5))}`);
    // From 1,400 px the metrics stand beside the photo, not below it.
    if (width >= 1400) {
      const [photo, details] = await Promise.all(['#photo-view', '#details'].map((sel) => tab.locator(sel).boundingBox()));
      check(details.x >= photo.x + photo.width && details.y < photo.y + photo.height,
        `${width} px: the metrics start at ${Math.round(details.y)} px, below the photo (${Math.round(photo.y)}–${Math.round(photo.y + photo.height)} px)`);
    }
    const words = await tab.locator('body').innerText();
    check(!COMMAND_LINE.test(words) && !/debug image|\(features? \d/.test(words), `${width} px: command-line words on the page`);
    await tab.screenshot({ path: join(artefacts, `width-${width}.png`), fullPage: true });
    await ctx.close();
  }
});

await context.close();
rmSync(profile, { recursive: true, force: true });
const passed = results.filter(Boolean).length;
const failed = results.length - passed;
console.log(`# screenshots in ${artefacts}`);
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
