// Opens one large file in the page (headless Chromium, WebGPU on SwiftShader) by ?url=, as
// scripts/web-large.sh serves it, and says how it went: the status as it changes (bytes read,
// the first part on the GPU, the first picture, all of it on the GPU), the counts against
// `lineao info`, a screenshot. Too slow for the test command at a gigabyte; run once, stated in
// docs/web.md.
//
// usage: node large.mjs BASE_URL FILE_NAME INFO_JSON OUT_PNG [QUERY]
import { chromium } from 'playwright-core';
import fs from 'node:fs';
import assert from 'node:assert/strict';

const [base, name, infoJson, png, query = ''] = process.argv.slice(2);
const expected = JSON.parse(fs.readFileSync(infoJson, 'utf8'));
const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium',
  headless: false,
  args: [
    '--headless=new', '--no-sandbox', '--enable-unsafe-webgpu', '--use-webgpu-adapter=swiftshader',
    '--use-angle=swiftshader', '--enable-features=Vulkan', '--use-vulkan=swiftshader',
    '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync',
  ],
});
const page = await (await browser.newContext({ viewport: { width: 1280, height: 800 } })).newPage();
const crashes = [];
page.on('pageerror', (e) => crashes.push(e.message));
const start = Date.now();
await page.goto(`${base}/?url=${name}${query}`);
const timeout = Number(process.env.LINEAO_LARGE_TIMEOUT_S || 1800) * 1000;
let status;
let last = '';
for (;;) {
  if (crashes.length) throw new Error(`the page crashed: ${crashes.join('; ')}`);
  status = await page.evaluate(() => window.lineaoStatus);
  const now = status && `${status.state} complete=${status.complete} vertices=${status.vertices} frames=${status.frames}`;
  const read = status && status.bytesRead != null ? ` read ${(status.bytesRead / 2 ** 20).toFixed(0)} MiB` : '';
  if (now && now !== last) {
    console.log(`${((Date.now() - start) / 1000).toFixed(1)} s: ${now}${read}`);
    last = now;
  }
  if (status && ['ready', 'error'].includes(status.state)) break;
  if (Date.now() - start > timeout) break;
  await new Promise((r) => setTimeout(r, 1000));
}
console.log(JSON.stringify(status));
// SwiftShader may still be drawing the view again (its GPU times): the screenshot waits for it.
await page.screenshot({ path: png, timeout: 900_000 }).catch((e) => console.log(`no screenshot: ${e.message}`));
await browser.close();
assert.equal(status.state, 'ready', status.message);
assert.equal(status.complete, true);
assert.equal(status.streamlines, expected.streamlines);
assert.equal(status.vertices, expected.vertices);
console.log(`large: ${name} opened: ${status.vertices} vertices; first part on the GPU after ${status.firstMs} ms, ` +
  `first picture after ${status.firstPictureMs} ms, all on the GPU after ${status.loadMs} ms, ready after ${(Date.now() - start) / 1000} s`);
