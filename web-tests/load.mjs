// Load check of `spdcam serve`: N concurrent uploads of one photo to POST /api/estimate;
// every answer must be 200 with the same SPD. Prints the wall time and, given the server's
// process id (Linux), its peak resident memory (VmHWM).
// Usage: node load.mjs URL PHOTO [N=20] [SERVER_PID]
import { readFileSync } from 'node:fs';
import { basename } from 'node:path';

const [url, photo, n = '20', pid] = process.argv.slice(2);
if (!photo) {
  console.error('usage: node load.mjs URL PHOTO [N] [SERVER_PID]');
  process.exit(2);
}
const bytes = readFileSync(photo);
const count = Number(n);
const started = performance.now();
const answers = await Promise.all(Array.from({ length: count }, async (_, i) => {
  const form = new FormData();
  form.append('photo', new Blob([bytes], { type: 'image/jpeg' }), `${i}-${basename(photo)}`);
  const t0 = performance.now();
  const r = await fetch(new URL('api/estimate', url), { method: 'POST', body: form });
  return { status: r.status, body: await r.json(), ms: performance.now() - t0 };
}));
const wall = performance.now() - started;
const first = answers[0].body;
const bad = answers.filter((a, i) => a.status !== 200 || a.body.name !== `${i}-${basename(photo)}`
  || JSON.stringify(a.body.spd) !== JSON.stringify(first.spd));
const slowest = Math.max(...answers.map((a) => a.ms));
console.log(`${count} concurrent uploads of ${basename(photo)} (${(bytes.length / 1e6).toFixed(1)} MB): `
  + `${count - bad.length} correct, ${bad.length} wrong or failed; wall ${(wall / 1000).toFixed(2)} s, `
  + `slowest answer ${(slowest / 1000).toFixed(2)} s`);
if (first.colorimetry) console.log(`estimate: xy ${first.colorimetry.xy.map((v) => v.toFixed(4)).join(', ')}, CCT ${first.colorimetry.cct?.toFixed(0)} K`);
if (pid) {
  const status = readFileSync(`/proc/${pid}/status`, 'utf8');
  const peak = status.match(/VmHWM:\s+(\d+) kB/);
  if (peak) console.log(`server peak RSS: ${(Number(peak[1]) / 1024).toFixed(0)} MiB`);
}
for (const b of bad.slice(0, 3)) console.log(`bad answer: ${b.status} ${JSON.stringify(b.body).slice(0, 200)}`);
process.exit(bad.length ? 1 : 0);
