// Local mode's speed in headless Chromium (software WebGL on this machine's CPU): the page served
// from its folder over http on loopback by a static server here, with the cross-origin isolation
// headers fluidcast-server sends (so the solver runs in its worker, as on a phone), a phone's
// viewport; for each case the new fluid states drawn per second, the solver's milliseconds a step
// and the simulation speed, averaged over the last of `seconds`; `file` as a third argument opens
// the page from a file instead (no worker: the solver steps on the page's thread).
//   node bench/page_local_bench.cjs WEB_ROOT [seconds] [file]
//   (env: FLUIDCAST_WEB_MODULES: build/web/node_modules; CHROMIUM: /usr/bin/chromium)
'use strict';

const fs = require('fs');
const http = require('http');
const path = require('path');
const { chromium } = require(path.resolve(process.env.FLUIDCAST_WEB_MODULES, 'playwright-core'));

const [webRoot, secondsText, from] = process.argv.slice(2);
const seconds = Number(secondsText) || 10;
const types = { '.html': 'text/html', '.js': 'text/javascript', '.css': 'text/css',
                '.proto': 'text/plain', '.webmanifest': 'application/manifest+json' };
const cases = [
  { particles: 5000, iterations: 2, scale: 3 },
  { particles: 5000, iterations: 2, scale: 1 },
  { particles: 2000, iterations: 2, scale: 1 },
];
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// The page's files as fluidcast-server serves them.
function serve(root) {
  const server = http.createServer((request, response) => {
    const file = path.join(root, decodeURIComponent(new URL(request.url, 'http://x').pathname));
    if (!file.startsWith(path.resolve(root)) || !fs.existsSync(file) || fs.statSync(file).isDirectory()) {
      response.writeHead(404).end();
      return;
    }
    response.writeHead(200, { 'Content-Type': types[path.extname(file)] || 'application/octet-stream',
                              'Cross-Origin-Opener-Policy': 'same-origin',
                              'Cross-Origin-Embedder-Policy': 'require-corp' });
    fs.createReadStream(file).pipe(response);
  });
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(server)));
}

(async () => {
  const root = path.resolve(webRoot);
  const server = from === 'file' ? null : await serve(root);
  const base = server ? `http://127.0.0.1:${server.address().port}/index.html`
                      : `file://${root}/index.html`;
  const browser = await chromium.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
                                          headless: true, args: ['--no-sandbox'] });
  console.log('| particles | PBF iterations | viewport | fps | step ms | simulation speed |');
  console.log('| --- | --- | --- | --- | --- | --- |');
  for (const c of cases) {
    const context = await browser.newContext({ viewport: { width: 390, height: 844 },
                                               deviceScaleFactor: c.scale, isMobile: true,
                                               hasTouch: true });
    const page = await context.newPage();
    await page.goto(`${base}?local&scene=dam_break` +
                    `&particles=${c.particles}&iterations=${c.iterations}`);
    await sleep(3000);
    const samples = [];
    for (let k = 0; k < seconds; k++) {
      await sleep(1000);
      samples.push(await page.evaluate(() => ({ ...window.fluidcast.local })));
    }
    const mean = (key) => samples.reduce((s, x) => s + x[key], 0) / samples.length;
    const size = await page.evaluate(() => {
      const canvas = document.getElementById('local-view');
      return `${canvas.width}×${canvas.height}`;
    });
    console.log(`| ${c.particles} | ${c.iterations} | 390×844 CSS px ×${c.scale} (${size}) | ` +
                `${mean('fps').toFixed(1)} | ${mean('stepMs').toFixed(2)} | ${mean('speed').toFixed(2)} |`);
    await context.close();
  }
  await browser.close();
  if (server) server.close();
})().catch((e) => { console.error(e); process.exit(1); });
