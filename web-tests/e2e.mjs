// End-to-end tests of the `spdcam serve` page in headless Chromium, as a person would use it.
// Usage: node e2e.mjs URL EXPECTED.json PHOTO TRUTH.csv ARTEFACT_DIR [REPORT.html]
// EXPECTED.json is `spdcam estimate --json PHOTO` (an array of one estimate); REPORT.html,
// when given, is `spdcam estimate --report REPORT.html PHOTO`, opened offline from its file.
import { chromium } from 'playwright-core';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';

const [url, expectedPath, photoPath, truthPath, artefacts, reportPath] = process.argv.slice(2);
if (!artefacts) {
  console.error('usage: node e2e.mjs URL EXPECTED.json PHOTO TRUTH.csv ARTEFACT_DIR [REPORT.html]');
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

const profile = mkdtempSync(join(tmpdir(), 'spdcam-chromium-'));
// A fresh profile (--user-data-dir) each run, given as Playwright asks for it.
const context = await chromium.launchPersistentContext(profile, {
  executablePath: '/usr/bin/chromium',
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  viewport: { width: 1500, height: 1000 },
  acceptDownloads: true,
});
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

await test('an uploaded photo shows the SPD, xy, CCT and Duv of `spdcam estimate --json`', async () => {
  await page.goto(url);
  await page.setInputFiles('#files', photoPath);
  await page.waitForSelector('#cct');
  const c = expected.colorimetry;
  check(await text(page, '#xy-x') === c.xy[0].toFixed(4), `x ${await text(page, '#xy-x')} vs ${c.xy[0]}`);
  check(await text(page, '#xy-y') === c.xy[1].toFixed(4), `y ${await text(page, '#xy-y')} vs ${c.xy[1]}`);
  // CCT and Duv are given only near the Planckian locus (|Duv| <= 0.05), as the CLI does.
  const cct = c.cct === null ? 'none (far from the Planckian locus)' : `${c.cct.toFixed(0)} K`;
  const duv = c.duv === null ? '–' : (c.duv >= 0 ? '+' : '') + c.duv.toFixed(4);
  check(await text(page, '#cct') === cct, `CCT ${await text(page, '#cct')} vs ${c.cct}`);
  check(await text(page, '#duv') === duv, `Duv ${await text(page, '#duv')} vs ${c.duv}`);
  // Ra with its calibrated 95 % interval, as the JSON gives them.
  const ra = expected.metrics.cri_ra;
  const raHalf = expected.metric_uncertainty && expected.metric_uncertainty.cri_ra;
  check(raHalf && raHalf.half95 > 0, 'the CLI gives Ra an interval');
  const raShown = await text(page, '#metric-cri_ra');
  check(raShown === `${ra.toPrecision(4)} ± ${raHalf.half95.toPrecision(4)}`, `Ra shown as ${raShown}`);
  const points = await plottedSpd(page, expected.name);
  check(points && points.length === expected.spd.length, `plotted ${points && points.length} points`);
  const wl = expected.wavelength_nm;
  const [left, right, top, bottom] = [52, 628, 14, 294];
  points.forEach(([x, y], i) => {
    close(wl[0] + ((x - left) / (right - left)) * (wl[wl.length - 1] - wl[0]), wl[i], 1e-3, `wavelength ${i}`);
    close((bottom - y) / (bottom - top), expected.spd[i], 1e-4, `SPD at ${wl[i]} nm`);
  });
  // The point on the xy diagram.
  const dot = await page.locator('#xy-plot circle.xy-point').first().getAttribute('cx');
  close((Number(dot) - 44) / (388 - 44) * 0.8, c.xy[0], 1e-4, 'x on the diagram');
  // The CSV download carries the exact numbers.
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#download-csv')]);
  const csv = readFileSync(await download.path(), 'utf8').trim().split('\n');
  check(csv[0] === `wavelength_nm,${expected.name}`, `CSV header ${csv[0]}`);
  csv.slice(1).forEach((line, i) => {
    const [w, v] = line.split(',').map(Number);
    check(w === wl[i] && v === expected.spd[i], `CSV row ${i}: ${line}`);
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
  await page.mouse.move(cx + 15, cy + 10, { steps: 5 });
  await page.mouse.move(cx + 30, cy + 25, { steps: 5 });
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

await test('a file that is no image shows the CLI\'s error in the page', async () => {
  await page.setInputFiles('#files', { name: 'notes.txt', mimeType: 'text/plain', buffer: Buffer.from('these are notes, not a photo') });
  const error = page.locator('#list li .error').filter({ hasText: 'notes.txt' });
  await error.waitFor({ timeout: 30000 });
  const message = await error.textContent();
  check(message.includes('not an image'), message);
  // The earlier estimate is still there and the page still works.
  check(await page.locator('#spd-plot polyline.spd').count() >= 1, 'the earlier SPD vanished');
  await page.screenshot({ path: join(artefacts, 'error.png'), fullPage: true });
});

await test('several photos share one plot', async () => {
  await page.setInputFiles('#files', [photoPath, photoPath]);
  await page.waitForFunction(() => document.querySelectorAll('#spd-plot polyline.spd').length >= 3, null, { timeout: 30000 });
  check(await page.locator('#xy-plot circle.xy-point').count() >= 3, 'fewer than three xy points');
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
    check(await shown('cri_ra') === m.cri_ra.toFixed(1), `Ra ${await shown('cri_ra')}, expected ${m.cri_ra.toFixed(1)}`);
    check(await shown('tm30_rf') === m.tm30_rf.toFixed(1), `Rf ${await shown('tm30_rf')}, expected ${m.tm30_rf.toFixed(1)}`);
    check(await shown('tm30_rg') === m.tm30_rg.toFixed(1), `Rg ${await shown('tm30_rg')}, expected ${m.tm30_rg.toFixed(1)}`);
    check(await shown('cct_k') === m.cct_k.toFixed(0), `CCT ${await shown('cct_k')}, expected ${m.cct_k.toFixed(0)}`);
    check(await shown('gfc') === expected.truth.gfc.toFixed(4), `GFC ${await shown('gfc')}, expected ${expected.truth.gfc.toFixed(4)}`);
    const size = (selector) => tab.evaluate((sel) => {
      const r = document.querySelector(sel).getBoundingClientRect();
      return [r.width, r.height];
    }, selector);
    for (const selector of ['#estimate-1 svg.spd-plot', '#estimate-1 svg.tm30-cvg']) {
      const [w, h] = await size(selector);
      check(w > 0 && h > 0, `${selector} drawn ${w} × ${h}`);
    }
    check(await tab.locator('#estimate-1 svg.spd-plot polyline.spd').count() === 1, 'no SPD line');
    check(await tab.locator('#estimate-1 svg.tm30-cvg polygon.test').count() === 1, 'no TM-30 test polygon');
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

await context.close();
rmSync(profile, { recursive: true, force: true });
const passed = results.filter(Boolean).length;
const failed = results.length - passed;
console.log(`# screenshots in ${artefacts}`);
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
