// Local mode's speed in headless Chromium (software WebGL on this machine's CPU): the page opened
// from its folder as a file (no server), a phone's viewport, for each case the frames per second,
// the solver's milliseconds a step and the simulation speed, averaged over the last of `seconds`.
//   node bench/page_local_bench.cjs WEB_ROOT [seconds]
//   (env: FLUIDCAST_WEB_MODULES: build/web/node_modules; CHROMIUM: /usr/bin/chromium)
'use strict';

const path = require('path');
const { chromium } = require(path.resolve(process.env.FLUIDCAST_WEB_MODULES, 'playwright-core'));

const [webRoot, secondsText] = process.argv.slice(2);
const seconds = Number(secondsText) || 10;
const cases = [
  { particles: 5000, iterations: 2, scale: 3 },
  { particles: 5000, iterations: 2, scale: 1 },
  { particles: 2000, iterations: 2, scale: 1 },
];
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

(async () => {
  const browser = await chromium.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
                                          headless: true, args: ['--no-sandbox'] });
  console.log('| particles | PBF iterations | viewport | fps | step ms | simulation speed |');
  console.log('| --- | --- | --- | --- | --- | --- |');
  for (const c of cases) {
    const context = await browser.newContext({ viewport: { width: 390, height: 844 },
                                               deviceScaleFactor: c.scale, isMobile: true,
                                               hasTouch: true });
    const page = await context.newPage();
    await page.goto(`file://${path.resolve(webRoot)}/index.html?local&scene=dam_break` +
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
})().catch((e) => { console.error(e); process.exit(1); });
