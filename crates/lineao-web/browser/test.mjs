// Drives the lineao web page in Debian's headless Chromium (WebGPU on SwiftShader), as a user
// would: a built-in scene, a real file by ?url=, a file dropped on the page, bad files and bad
// URLs, a browser without WebGPU. Saves what the checks natively need into OUT:
//   OUT/<case>/<panel>/  the frame read back (lineao-web-check compares it with the CPU reference)
//   OUT/results.json     statuses, counts and times;  OUT/*.png  screenshots.
//
// usage: node test.mjs BASE_URL OUT LINEAO_BIN DATA_DIR WHOLE_BRAIN_TCK (served as wholebrain.tck)
import { chromium } from 'playwright-core';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import assert from 'node:assert/strict';

const [base, out, lineao, data, WHOLE_BRAIN] = process.argv.slice(2);
const STROKE = 'niivue+niivue/packages/niivue/demos/images/stroke.trk.gz';
const SMALL = 'niivue+niivue/packages/niivue/demos/images/tract.SLF1_R.tck';
const MNI = 'niivue+niivue/packages/niivue/demos/images/MNI152_2009_template.nii.gz';
const STROKEZ = 'niivue+niivue/packages/niivue/demos/images/strokez.nii.gz';
// Built beside `lineao` by the workspace's tests: the native numbers the page's are compared with.
const WEB_CHECK = path.join(path.dirname(lineao), 'lineao-web-check');
const results = {};
fs.mkdirSync(out, { recursive: true });

const chromiumArgs = [
  '--headless=new', '--no-sandbox', '--enable-unsafe-webgpu', '--use-webgpu-adapter=swiftshader',
  '--use-angle=swiftshader', '--enable-features=Vulkan', '--use-vulkan=swiftshader',
  // This machine's network is closed: no background connections, no first-run.
  '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync', '--disable-quic',
];
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', headless: false, args: chromiumArgs });
const context = await browser.newContext({ viewport: { width: 1280, height: 800 } });
const page = await context.newPage();
const log = [];
page.on('console', (m) => log.push(`[${m.type()}] ${m.text()}`));
page.on('pageerror', (e) => log.push(`[pageerror] ${e.message}`));

function info(file) {
  return JSON.parse(execFileSync(lineao, ['info', '--json', path.join(data, file)], { encoding: 'utf8' }));
}

const crashes = [];
page.on('pageerror', (e) => crashes.push(e.message));

/// Waits until the page's state is one of `states`; fails at once if the page crashed (a panic).
async function settle(states = ['ready', 'error'], timeout = 300_000) {
  const deadline = Date.now() + timeout;
  for (;;) {
    if (crashes.length) throw new Error(`the page crashed: ${crashes.join('; ')}`);
    const status = await page.evaluate(() => window.lineaoStatus);
    if (status && states.includes(status.state)) return status;
    if (Date.now() > deadline) throw new Error(`still ${JSON.stringify(status)} after ${timeout / 1000} s`);
    await new Promise((r) => setTimeout(r, 200));
  }
}

/// Opens the page at `query`; waits until it is ready (or in error), timing both.
async function open(query, states) {
  const start = Date.now();
  await page.goto(`${base}/${query}`);
  const status = await settle(states);
  return { status, ms: Date.now() - start };
}

/// Reads back panel `panel` and writes it where lineao-web-check reads it.
async function readback(name, panel) {
  // Base64 through the browser's own encoder: megabytes of floats as JSON numbers take minutes.
  const frame = await page.evaluate(async (p) => {
    const r = await window.lineaoReadback(p);
    const base64 = (a) => new Promise((resolve) => {
      const reader = new FileReader();
      reader.onload = () => resolve(reader.result.slice(reader.result.indexOf(',') + 1));
      reader.readAsDataURL(new Blob([a.buffer]));
    });
    return { meta: r.meta, nd: await Promise.all(r.nd.map(base64)), zoom: await base64(r.zoom), ao: await base64(r.ao) };
  }, panel);
  const dir = path.join(out, name, String(panel));
  fs.mkdirSync(dir, { recursive: true });
  fs.writeFileSync(path.join(dir, 'meta.json'), frame.meta);
  const bytes = (b64) => Buffer.from(b64, 'base64');
  frame.nd.forEach((level, j) => fs.writeFileSync(path.join(dir, `nd_${j}.f32`), bytes(level)));
  fs.writeFileSync(path.join(dir, 'zoom.f32'), bytes(frame.zoom));
  fs.writeFileSync(path.join(dir, 'ao.f32'), bytes(frame.ao));
  const aoBytes = bytes(frame.ao);
  const ao = new Float32Array(aoBytes.buffer, aoBytes.byteOffset, aoBytes.length / 4);
  return { dir, occluded: ao.filter((a) => a > 0.05).length };
}

/// Drops a file of `bytes` named `name` on the page, as a user dragging it from a file manager.
async function drop(name, bytes) {
  await page.evaluate(async ([n, b64]) => {
    const data = await (await fetch(`data:application/octet-stream;base64,${b64}`)).arrayBuffer();
    const transfer = new DataTransfer();
    transfer.items.add(new File([data], n));
    const canvas = document.getElementById('lineao-canvas');
    canvas.dispatchEvent(new DragEvent('drop', { dataTransfer: transfer, bubbles: true, cancelable: true }));
  }, [name, Buffer.from(bytes).toString('base64')]);
}

async function check(name, fn) {
  // LINEAO_WEB_ONLY=text: only the checks whose name holds it (while working on one).
  if (process.env.LINEAO_WEB_ONLY && !name.includes(process.env.LINEAO_WEB_ONLY)) return;
  const start = Date.now();
  try {
    await fn();
    console.log(`ok   ${name} (${((Date.now() - start) / 1000).toFixed(1)} s)`);
  } catch (e) {
    console.log(`FAIL ${name}: ${e.stack || e}`);
    console.log(log.slice(-30).join('\n'));
    await page.screenshot({ path: path.join(out, `failed-${name.replace(/\W+/g, '-')}.png`) }).catch(() => {});
    await browser.close();
    process.exit(1);
  }
}

await check('a built-in scene: LineAO | SSAO on WebGPU, read back', async () => {
  const { status, ms } = await open('?scene=bundles&vertices=60000&compare=lineao,ssao');
  assert.equal(status.state, 'ready', status.message);
  assert.deepEqual(status.methods, ['lineao', 'ssao']);
  assert.match(status.adapter, /./);
  assert.ok(status.streamlines > 0 && status.vertices > 50000, JSON.stringify(status));
  results.scene = { status, ms, panels: [await readback('scene', 0), await readback('scene', 1)] };
  assert.ok(results.scene.panels.every((p) => p.occluded > 100), JSON.stringify(results.scene.panels));
});

await check('a real file by ?url=: counts as lineao info, screenshot, read back', async () => {
  const expected = info(STROKE);
  const { status, ms } = await open(`?url=data/${encodeURIComponent(STROKE)}&compare=lineao,ssao`);
  assert.equal(status.state, 'ready', status.message);
  assert.equal(status.streamlines, expected.streamlines);
  assert.equal(status.vertices, expected.vertices);
  await page.screenshot({ path: path.join(out, 'stroke-lineao-vs-ssao.png') });
  results.stroke = { status, ms, info: { streamlines: expected.streamlines, vertices: expected.vertices },
    panels: [await readback('stroke', 0), await readback('stroke', 1)] };
  const link = await page.evaluate(() => location.search);
  assert.match(link, /compare=lineao%2Cssao/, link);
  results.stroke.link = link;
});

await check('the link of a view opens that view', async () => {
  const { status } = await open(`?url=data/${encodeURIComponent(STROKE)}&method=ssao&preset=paper&orbit=60,20,0.8`);
  assert.equal(status.state, 'ready', status.message);
  assert.deepEqual(status.methods, ['ssao']);
  const link = await page.evaluate(() => location.search);
  assert.match(link, /method=ssao/);
  assert.match(link, /preset=paper/);
  assert.match(link, /orbit=60\.0%2C20\.0%2C0\.800/, link);
});

await check('GPU time per pass: the page\'s LineAO chain', async () => {
  // 200 000 vertices: under the viewer's preview threshold, so every frame is the full one.
  const { status } = await open('?scene=bundles&vertices=200000&method=lineao&timings');
  assert.equal(status.state, 'ready', status.message);
  // A view with timings is rendered four times (times are read a frame later, without waiting).
  await page.waitForFunction(() => window.lineaoStatus.frames >= 4 && window.lineaoStatus.gpuMs[0] != null, null,
    { timeout: 120_000 });
  const timed = await page.evaluate(() => window.lineaoStatus);
  results.timings = { size: timed.size, passes: timed.passes[0], sum: timed.gpuMs[0], adapter: timed.adapter };
});

await check('the progressive GPU ray tracer gains rays; a debug view', async () => {
  let { status } = await open('?scene=bundles&vertices=30000&method=raytraced&rays=16');
  assert.equal(status.state, 'ready', status.message);
  assert.deepEqual(status.methods, ['raytraced']);
  await page.waitForFunction(() => window.lineaoStatus.raysPerPixel[0] >= 16, null, { timeout: 120_000 });
  ({ status } = await open('?scene=bundles&vertices=30000&debug-view=normals'));
  assert.equal(status.state, 'ready', status.message);
});

await check('File ▸ Save picture downloads the canvas as a PNG; M records a WebM movie of it', async () => {
  const { status } = await open('?scene=bundles&vertices=30000');
  assert.equal(status.state, 'ready', status.message);
  // The menu's item calls this; a download, as a user's browser saves it.
  let download = page.waitForEvent('download');
  await page.evaluate(() => window.lineaoSavePicture());
  const picture = path.join(out, 'saved-picture.png');
  await (await download).saveAs(picture);
  const png = fs.readFileSync(picture);
  assert.equal(png.subarray(1, 4).toString(), 'PNG');
  const size = [png.readUInt32BE(16), png.readUInt32BE(20)];
  const canvas = await page.evaluate(() => [document.getElementById('lineao-canvas').width,
    document.getElementById('lineao-canvas').height]);
  assert.deepEqual(size, canvas);
  // M, as a user presses it over the picture: recording; again: the movie downloads.
  await page.mouse.click(900, 400);
  download = page.waitForEvent('download');
  await page.keyboard.press('m');
  await new Promise((r) => setTimeout(r, 1500));
  await page.keyboard.press('m');
  const movie = path.join(out, 'recorded.webm');
  await (await download).saveAs(movie);
  const webm = fs.readFileSync(movie);
  // The EBML header of a WebM (Matroska) file.
  assert.equal(webm.readUInt32BE(0), 0x1a45dfa3, `not a WebM: ${webm.subarray(0, 8).toString('hex')}`);
  const last = await page.evaluate(() => window.lineaoLastMovie);
  assert.ok(last.size === webm.length && /webm/.test(last.type), JSON.stringify(last));
  results.recorded = { picture: size, movieBytes: webm.length, type: last.type };
});

await check('a file dropped on the page opens; a bad one is an error, and the page goes on; the file picker', async () => {
  await open('?scene=spiral&vertices=20000');
  const bad = Buffer.from('TRACK\0this is not a TrackVis header at all');
  await drop('bad.trk', bad);
  let status = await settle(['error']);
  assert.match(status.message, /bad\.trk/);
  assert.match(status.message, /byte|offset|expected/i, status.message);
  results.badDrop = status.message;
  const expected = info(SMALL);
  await drop('tract.SLF1_R.tck', fs.readFileSync(path.join(data, SMALL)));
  await page.waitForFunction(() => window.lineaoStatus.name === 'tract.SLF1_R.tck', null, { timeout: 120_000 });
  status = await settle();
  assert.equal(status.state, 'ready', status.message);
  assert.equal(status.streamlines, expected.streamlines);
  assert.equal(status.vertices, expected.vertices);
  assert.equal(status.colorRange, null, 'direction colours');
  // Its track scalar file dropped beside it: the lines coloured by its values.
  await drop('mni152.SLF1_R.tsf', fs.readFileSync(path.join(data, SMALL.replace('tract.SLF1_R.tck', 'mni152.SLF1_R.tsf'))));
  await page.waitForFunction(() => window.lineaoStatus.colorRange != null, null, { timeout: 120_000 });
  status = await settle();
  assert.equal(status.state, 'ready', status.message);
  assert.deepEqual(status.fields, ['tsf:mni152.SLF1_R.tsf']);
  assert.ok(status.colorRange[0] < status.colorRange[1], JSON.stringify(status.colorRange));
  // The file picker (File ▸ Open… clicks this input).
  await page.setInputFiles('#lineao-file', path.join(data, STROKE));
  await page.waitForFunction(() => window.lineaoStatus.name === 'stroke.trk.gz', null, { timeout: 120_000 });
  status = await settle();
  assert.equal(status.state, 'ready', status.message);
  assert.equal(status.vertices, info(STROKE).vertices);
});

await check('an anatomy by ?volume= with ?slices=; a bad volume dropped is said, the tractogram stays', async () => {
  const query = `?url=data/${encodeURIComponent(STROKE)}&volume=data/${encodeURIComponent(MNI)}&slices=-,-,10`;
  let { status } = await open(query);
  // The volume may arrive after the tractogram's first frame: ready with its slice.
  await page.waitForFunction(() => window.lineaoStatus.slices && window.lineaoStatus.state === 'ready', null,
    { timeout: 120_000 });
  status = await page.evaluate(() => window.lineaoStatus);
  assert.deepEqual(status.anatomy, [193, 229, 193], JSON.stringify(status));
  assert.deepEqual(status.slices, [null, null, 10]);
  assert.equal(status.vertices, info(STROKE).vertices);
  await page.screenshot({ path: path.join(out, 'stroke-over-mni.png') });
  const link = await page.evaluate(() => location.search);
  assert.match(link, /volume=data%2F/, link);
  await drop('t1.nii.gz', Buffer.from([0x1f, 0x8b, 8, 0, 1, 2, 3]));
  status = await settle(['error']);
  assert.match(status.message, /t1\.nii\.gz/);
  assert.match(status.message, /without slices/, status.message);
  assert.equal(status.vertices, info(STROKE).vertices, 'the tractogram stays');
  results.anatomy = { link, badVolume: status.message };
});

await check('colour by a volume or a .tsf by ?color=volume: or tsf: (the range the command line uses); one that cannot be fetched is said', async () => {
  // niivue's tracts.layer.voxel demo: stroke.trk.gz coloured by the z-map sampled at its points.
  const z = `data/${STROKEZ}`;
  const url = `?url=data/${encodeURIComponent(STROKE)}`;
  // The volume held back a second and a half: meanwhile the status says it is being fetched.
  const held = (route) => new Promise((r) => setTimeout(r, 1500)).then(() => route.continue());
  await page.route('**/strokez.nii.gz', held);
  await page.goto(`${base}/${url}&color=volume:${encodeURIComponent(z)}`);
  await page.waitForFunction(() => /^fetching .*strokez\.nii\.gz/.test(window.lineaoStatus?.message ?? ''), null,
    { timeout: 30_000 });
  const fetching = await page.evaluate(() => window.lineaoStatus.message);
  let status = await settle();
  await page.unroute('**/strokez.nii.gz', held);
  assert.equal(status.state, 'ready', status.message);
  assert.equal(status.vertices, info(STROKE).vertices);
  assert.deepEqual(status.fields, [`volume:${z}`]);
  // The same f32 numbers natively, exactly (the page's status widens them to f64).
  const native = JSON.parse(execFileSync(WEB_CHECK,
    ['--color-range', path.join(data, STROKE), `volume:${path.join(data, STROKEZ)}`], { encoding: 'utf8' }));
  assert.deepEqual(status.colorRange.map(Math.fround), native.map(Math.fround),
    `page ${JSON.stringify(status.colorRange)}, native ${JSON.stringify(native)}`);
  await page.screenshot({ path: path.join(out, 'stroke-by-strokez.png') });
  const link = await page.evaluate(() => location.search);
  assert.match(link, /color=volume%3Adata%2F/, link);
  const range = status.colorRange;
  // A built-in scene waits for the volume too: its points are sampled as they arrive (it keeps
  // none to sample later).
  ({ status } = await open(`?scene=bundles&vertices=20000&color=volume:${encodeURIComponent(z)}`));
  assert.equal(status.state, 'ready', status.message);
  assert.deepEqual(status.fields, [`volume:${z}`]);
  // A .tck's track scalar file, likewise.
  const tsf = SMALL.replace('tract.SLF1_R.tck', 'mni152.SLF1_R.tsf');
  ({ status } = await open(`?url=data/${encodeURIComponent(SMALL)}&color=tsf:data/${encodeURIComponent(tsf)}`));
  assert.equal(status.state, 'ready', status.message);
  assert.deepEqual(status.fields, [`tsf:data/${tsf}`]);
  const nativeTsf = JSON.parse(execFileSync(WEB_CHECK,
    ['--color-range', path.join(data, SMALL), `tsf:${path.join(data, tsf)}`], { encoding: 'utf8' }));
  assert.deepEqual(status.colorRange.map(Math.fround), nativeTsf.map(Math.fround));
  // An address that fails: said, and the tractogram arrives whole in its own colours.
  ({ status } = await open(`${url}&color=volume:data/missing.nii.gz`, ['error']));
  assert.match(status.message, /missing\.nii\.gz: HTTP 404/, status.message);
  assert.match(status.message, /keep their colours/, status.message);
  await page.waitForFunction(() => window.lineaoStatus.complete === true, null, { timeout: 120_000 });
  status = await page.evaluate(() => window.lineaoStatus);
  assert.equal(status.vertices, info(STROKE).vertices, 'the tractogram is shown');
  assert.equal(status.colorRange, null, 'in its own colours');
  results.colourByVolume = { range, native, link, fetching, missing: status.message };
});

await check('a file arrives in pieces: drawn while it loads, kept by the page only up to hold=', async () => {
  // A whole brain of 2 M points (23 MB) written by `lineao convert --scene wholebrain`; the page
  // keeps at most 1 MiB of it (hold=1): it is decoded and drawn as it arrives, as a file over
  // the page's memory would be, and nothing of it is held.
  const expected = JSON.parse(execFileSync(lineao, ['info', '--json', WHOLE_BRAIN], { encoding: 'utf8' }));
  const start = Date.now();
  await page.goto(`${base}/?url=wholebrain.tck&hold=1`);
  let drawnWhileLoading = false;
  let status;
  const seen = [];
  for (;;) {
    if (crashes.length) throw new Error(`the page crashed: ${crashes.join('; ')}`);
    status = await page.evaluate(() => window.lineaoStatus);
    const key = status && `${status.state} complete=${status.complete} frames=${status.frames}`;
    if (key && !seen.at(-1)?.endsWith(key)) seen.push(`${Date.now() - start} ms: ${key}`);
    if (status && status.complete === false && status.frames > 0) drawnWhileLoading = true;
    if (status && ['ready', 'error'].includes(status.state)) break;
    if (Date.now() - start > 600_000) throw new Error(`still ${JSON.stringify(status)}`);
    await new Promise((r) => setTimeout(r, 100));
  }
  assert.equal(status.state, 'ready', status.message);
  assert.equal(status.streamlines, expected.streamlines);
  assert.equal(status.vertices, expected.vertices);
  assert.equal(status.complete, true);
  assert.equal(status.readable, false, 'a file past hold= is not kept');
  assert.ok(drawnWhileLoading, `frames were drawn before the file had all arrived: ${seen.join('; ')}`);
  results.streamed = { status, ms: Date.now() - start };
});

await check('a URL that fails: the HTTP status; a file read whole over the limit (a tractogram, a colour file): refused by its size', async () => {
  let { status } = await open('?url=data/no-such-file.trk');
  assert.equal(status.state, 'error');
  assert.match(status.message, /HTTP 404/, status.message);
  results.missing = status.message;
  ({ status } = await open('?url=too-large.trx'));
  assert.equal(status.state, 'error');
  assert.match(status.message, /too-large\.trx: \d+ MiB is more than this page can hold/, status.message);
  results.tooLarge = status.message;
  // A colour file is held whole whatever its format (a .tsf dropped beside its .tck too).
  ({ status } = await open('?scene=spiral&vertices=20000&color=tsf:too-large.tsf', ['error']));
  assert.match(status.message, /too-large\.tsf: \d+ MiB is more than this page can hold.*keep their colours/,
    status.message);
  results.tooLargeValues = status.message;
  ({ status } = await open('?method=lineoa'));
  assert.equal(status.state, 'error');
  assert.match(status.message, /lineoa/);
  results.badOption = status.message;
});

await check('a browser without WebGPU: the message, no blank canvas', async () => {
  const plain = await browser.newContext();
  const other = await plain.newPage();
  await other.addInitScript(() => { delete Object.getPrototypeOf(navigator).gpu; });
  await other.goto(`${base}/?scene=bundles`);
  await other.waitForFunction(() => window.lineaoStatus && window.lineaoStatus.state === 'error', null, { timeout: 30_000 });
  const { message, shown } = await other.evaluate(() => ({
    message: window.lineaoStatus.message,
    shown: document.body.classList.contains('failed') && document.getElementById('lineao-message').innerText,
  }));
  assert.match(message, /WebGPU/);
  assert.match(shown, /Chrome and Edge 113/);
  await other.screenshot({ path: path.join(out, 'no-webgpu.png') });
  await plain.close();
});

fs.writeFileSync(path.join(out, 'results.json'), JSON.stringify(results, null, 2));
await browser.close();
console.log(`browser: all checks passed; ${path.join(out, 'results.json')}`);
