// The phone page in Debian's Chromium, headless, as a phone (touch, small screen), driven by
// playwright-core against the real server on loopback: frames arrive and the canvas shows them,
// a touch drag stirs the fluid, a dropped WebSocket reconnects and resumes the same session,
// over https at a phone's size Chromium's emulated motion sensors tilt the water, and local mode
// simulates and draws the fluid in the page (from the server and from a file). Screenshots go to
// test-output/browser_*.png.
//   node tests/browser/page_test.cjs
//   (env: FLUIDCAST_SERVER, FLUIDCAST_WEB_MODULES, FLUIDCAST_WEB_ROOT, CHROMIUM)
'use strict';

const { spawn } = require('child_process');
const fs = require('fs');
const path = require('path');
const { chromium } = require(path.join(process.env.FLUIDCAST_WEB_MODULES, 'playwright-core'));

const server = process.env.FLUIDCAST_SERVER;
const webRoot = process.env.FLUIDCAST_WEB_ROOT;  // the page's files, opened from a file too
const browserPath = process.env.CHROMIUM || '/usr/bin/chromium';
const out = 'test-output';
let failures = 0, passes = 0;

function check(ok, what) {
  console.log((ok ? 'ok   ' : 'FAIL ') + what);
  if (ok) passes++; else failures++;
}

function startServer(httpPort = 0) {
  return new Promise((resolve, reject) => {
    const state = fs.mkdtempSync(path.join(require('os').tmpdir(), 'fluidcast-page-'));
    // Every page here comes from one address (loopback): its sessions may take every slot. The
    // phone's pages reach it as phone.test, a name it is known by only when told.
    const child = spawn(server, ['--listen', '127.0.0.1', '--grpc-port', '0', '--http-port', String(httpPort),
                                 '--state-dir', state, '--max-sessions-per-address', '8',
                                 '--server-name', 'phone.test'],
                        { stdio: ['ignore', 'pipe', 'inherit'] });
    child.on('exit', () => fs.rmSync(state, { recursive: true, force: true }));
    let text = '';
    child.stdout.on('data', (chunk) => {
      text += chunk;
      const match = /http=127\.0\.0\.1:(\d+)/.exec(text);
      if (match) resolve({ child, port: Number(match[1]) });
    });
    child.on('exit', (code) => reject(new Error('fluidcast-server exited with ' + code)));
  });
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Stops a server started here and waits for it to exit, so that its state folder is gone before
// this process ends; one that has not shut down within 10 s is killed.
function stopServer(child) {
  if (child.exitCode !== null || child.signalCode !== null) return Promise.resolve();
  const exited = new Promise((resolve) => child.once('exit', resolve));
  child.kill('SIGTERM');
  const killer = setTimeout(() => child.kill('SIGKILL'), 10000);
  return exited.finally(() => clearTimeout(killer));
}

// The largest distance a reading (a number, or an array of coordinates) moves from `from` while
// `during` runs, sampled every 100 ms: a sloshing fluid's centre of mass passes back through
// where it was, so one reading after the fact could miss how far it went.
async function largestShift(read, from, during, distance = (a, b) => Math.abs(a - b)) {
  let sampling = true, largest = 0;
  const sampler = (async () => {
    while (sampling) {
      largest = Math.max(largest, distance(await read(), from));
      await sleep(100);
    }
  })();
  await during();
  sampling = false;
  await sampler;
  return largest;
}

async function waitFor(page, predicate, what, timeoutMs = 60000) {
  const start = Date.now();
  while (Date.now() - start < timeoutMs) {
    if (await page.evaluate(predicate)) return true;
    await sleep(100);
  }
  throw new Error('timed out waiting for ' + what);
}

// The canvas's pixels, as the person sees them.
async function pixels(page) {
  return page.evaluate(() => {
    const canvas = document.getElementById('view');
    const data = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
    return Array.from(data.filter((_, k) => k % 4 !== 3 && (k >> 2) % 7 === 0));
  });
}

// The local mode's WebGL canvas, through a 2D copy (it keeps its drawing buffer).
async function localPixels(page) {
  return page.evaluate(() => {
    const source = document.getElementById('local-view');
    const copy = document.createElement('canvas');
    copy.width = source.width;
    copy.height = source.height;
    const context2d = copy.getContext('2d');
    context2d.drawImage(source, 0, 0);
    const data = context2d.getImageData(0, 0, copy.width, copy.height).data;
    return Array.from(data.filter((_, k) => k % 4 !== 3 && (k >> 2) % 7 === 0));
  });
}

function spread(values) {
  const mean = values.reduce((s, v) => s + v, 0) / values.length;
  return Math.sqrt(values.reduce((s, v) => s + (v - mean) * (v - mean), 0) / values.length);
}

async function touchDrag(page, cdp, from, to, steps) {
  const point = (x, y) => [{ x, y, id: 1, radiusX: 4, radiusY: 4, force: 1 }];
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: point(from.x, from.y) });
  for (let k = 1; k <= steps; k++) {
    const x = from.x + (to.x - from.x) * k / steps, y = from.y + (to.y - from.y) * k / steps;
    await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: point(x, y) });
    await sleep(50);
  }
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
}

// How many event listeners the page's local-fluid canvas has (each local fluid adds its own and
// must take them away when it stops: the canvas serves every handoff).
async function localCanvasListeners(cdp) {
  const { result } = await cdp.send('Runtime.evaluate',
                                    { expression: "document.getElementById('local-view')" });
  const { listeners } = await cdp.send('DOMDebugger.getEventListeners', { objectId: result.objectId });
  await cdp.send('Runtime.releaseObject', { objectId: result.objectId });
  return listeners.length;
}

// Cuts the page's network (no WebSocket gets through until the page sets window.WebSocket back to
// window.RealWebSocket), drops its stream, and waits for the fluid to go on in the page (`what`).
async function dropNetwork(page, what) {
  const handoffs = await page.evaluate(() => window.fluidcast.handoffs);
  await page.evaluate(() => {
    window.RealWebSocket = window.RealWebSocket || WebSocket;
    window.WebSocket = function (url) {
      return new window.RealWebSocket(url.replace(/\/\/[^/]+\//, '//127.0.0.1:1/'));
    };
    window.fluidcast.drop();
  });
  await waitFor(page, `window.fluidcast.handoffs > ${handoffs} && ` +
                      `window.fluidcast.mode === 'local' && window.fluidcast.local.fps > 0`,
                what, 15000);
}

// Waits for the page to stream again once its network is back, then for a few frames (`what`);
// what it shows then.
async function streamingAgain(page, what) {
  await waitFor(page, () => window.fluidcast.mode === 'stream' && window.fluidcast.connected, what,
                30000);
  const frames = await page.evaluate(() => window.fluidcast.frames);
  await waitFor(page, `window.fluidcast.frames > ${frames + 2}`, 'frames: ' + what);
  return page.evaluate(() => ({ id: window.fluidcast.sessionId,
    time: window.fluidcast.lastFrame.simTime, control: window.fluidcast.access.control,
    status: document.getElementById('status').textContent }));
}

async function main() {
  fs.mkdirSync(out, { recursive: true });
  const { child, port } = await startServer();
  let restarted = null;  // the server started again on the same port (the handoff's return)
  const browser = await chromium.launch({ executablePath: browserPath, headless: true,
                                          args: ['--no-sandbox',
                                                 '--host-resolver-rules=MAP phone.test 127.0.0.1'] });
  try {
    const context = await browser.newContext({
      viewport: { width: 300, height: 400 }, deviceScaleFactor: 1, isMobile: true, hasTouch: true,
    });
    const page = await context.newPage();
    page.on('console', (m) => console.log('page: ' + m.text()));
    page.on('pageerror', (e) => { console.log('page error: ' + e.message); failures++; });
    // This page may not continue the fluid by itself (?handoff=0): when the server goes, it says so.
    await page.goto(`http://127.0.0.1:${port}/?scene=pool&particles=2000&renderer=ssfr&adaptive=0&handoff=0`);

    // Frames arrive and show.
    await waitFor(page, () => window.fluidcast.frames >= 5, 'five frames');
    const first = await pixels(page);
    check(spread(first) > 10, 'the canvas shows a picture, not a blank (spread ' +
          spread(first).toFixed(1) + ')');
    const state = await page.evaluate(() => ({ ...window.fluidcast, latencyMs: undefined }));
    check(state.fps > 0, `fps > 0 (${state.fps})`);
    check(state.lastFrame.width === 300 && state.lastFrame.height === 400,
          `frames at the canvas's size (${state.lastFrame.width}×${state.lastFrame.height})`);
    await page.screenshot({ path: path.join(out, 'browser_page.png') });
    const manifest = await page.evaluate(async () => {
      const link = document.querySelector('link[rel=manifest]');
      return (await fetch(link.href)).json();
    });
    check(manifest.name === 'fluidcast' && manifest.display === 'fullscreen',
          'a web-app manifest (installable, full screen)');
    // The menus offer what the server's Welcome says it has, the session's scene chosen.
    const menus = await page.evaluate(() => ({
      scenes: [...document.querySelectorAll('#scene option')].map((o) => o.value),
      scene: document.querySelector('#scene').value,
      renderers: [...document.querySelectorAll('#renderer option')].map((o) => o.value),
      renderer: document.querySelector('#renderer').value,
      rules: window.fluidcast.rules,
    }));
    check(JSON.stringify(menus.scenes) === JSON.stringify(menus.rules.scenes) &&
          menus.scenes.includes('pool') && menus.scene === 'pool',
          `the scene menu is the server's (${menus.scenes}; ${menus.scene} chosen)`);
    check(JSON.stringify(menus.renderers) === JSON.stringify(menus.rules.renderers) &&
          menus.renderer === 'ssfr',
          `the renderer menu is the device's (${menus.renderers}; ${menus.renderer} chosen)`);

    // A calm pool changes little by itself; a finger dragged through it changes it a lot. The
    // largest change from the picture before, over each span, is compared: the water sloshes back
    // through where it was.
    const meanDifference = (a, b) => a.reduce((sum, v, k) => sum + Math.abs(v - b[k]), 0) / a.length;
    await sleep(1500);
    const calmFrom = await pixels(page);
    const calm = await largestShift(() => pixels(page), calmFrom, () => sleep(4500), meanDifference);
    const cdp = await context.newCDPSession(page);
    const stirFrom = await pixels(page);
    // To and fro three times, quickly: the fluid on lavapipe runs in slow motion (a quarter of
    // real time here), and other tests may share the cores. In slow motion the finger's sphere
    // moves at the hand's speed in simulated time (largest image change 2.5–2.9 at 120 px/s,
    // 5.7–6.0 at 600, calm 1.0) and finishes the stroke after the finger lifts: each stroke is
    // given the time.
    const stirred = await largestShift(() => pixels(page), stirFrom, async () => {
      for (const [from, to] of [[60, 240], [240, 60], [60, 240]]) {
        await touchDrag(page, cdp, { x: from, y: 250 }, { x: to, y: 250 }, 6);
        await sleep(1500);
      }
    }, meanDifference);
    await page.screenshot({ path: path.join(out, 'browser_drag.png') });
    check(stirred > 1.5 * calm + 0.5,
          `a touch drag stirs the fluid (largest image change ${stirred.toFixed(2)} vs ` +
          `${calm.toFixed(2)} calm)`);
    const latencies = await page.evaluate(() => window.fluidcast.latencyMs.length);
    check(latencies > 0, `frames reflect the touches (${latencies} latency samples)`);

    // Reset view: a command the server takes (a refused one would end the stream and reconnect).
    const beforeReset = await page.evaluate(() => ({ frames: window.fluidcast.frames,
                                                     reconnects: window.fluidcast.reconnects }));
    await page.click('#menu');
    await page.click('#reset-view');
    await page.click('#menu');
    await waitFor(page, `window.fluidcast.frames > ${beforeReset.frames + 3}`, 'frames after reset view');
    check(await page.evaluate(() => window.fluidcast.reconnects) === beforeReset.reconnects,
          'reset view keeps the stream');

    // The WebSocket drops: the page reconnects and resumes the same session.
    const before = await page.evaluate(() => ({ id: window.fluidcast.sessionId,
                                                frames: window.fluidcast.frames }));
    await page.evaluate(() => window.fluidcast.drop());
    await waitFor(page, () => window.fluidcast.reconnects >= 1 && window.fluidcast.connected,
                  'a reconnect');
    await waitFor(page, `window.fluidcast.frames > ${before.frames + 3}`, 'frames after it');
    const after = await page.evaluate(() => window.fluidcast.sessionId);
    check(after === before.id, 'the same session after the reconnect');
    await page.screenshot({ path: path.join(out, 'browser_reconnected.png') });

    // "Share to watch": its link opens the session to watch only. The watcher sees no control
    // that would change the fluid, its one-finger drag turns its own view and its stream goes
    // on; the address bar of the page that made the session opens it to play.
    check(/^#control=[0-9a-f]{32}$/.test(await page.evaluate(() => location.hash)),
          "the creator's address opens the session to play");
    await page.evaluate(() => { navigator.clipboard.writeText = async (text) => { window.copiedLink = text; }; });
    await page.click('#menu');
    await page.click('#share-view');
    await page.click('#menu');
    await waitFor(page, () => window.copiedLink, 'the shared link');
    const creator = await page.evaluate(() => ({ link: window.copiedLink, session: window.fluidcast.sessionId,
                                                 viewKey: window.fluidcast.access.viewKey }));
    check(creator.link.endsWith('#view=' + creator.viewKey), 'Share to watch gives the view key\'s link');
    const watcher = await context.newPage();
    watcher.on('pageerror', (e) => { console.log('watcher error: ' + e.message); failures++; });
    await watcher.goto(creator.link);
    await waitFor(watcher, () => window.fluidcast.frames >= 3, 'frames for the watcher');
    const watching = await watcher.evaluate(() => ({ control: window.fluidcast.access.control,
                                                     session: window.fluidcast.sessionId }));
    check(!watching.control && watching.session === creator.session,
          'the link watches the same session, without control');
    await waitFor(watcher, () => document.getElementById('stats').textContent.includes('watching'),
                  'the stats to say it watches');
    await watcher.click('#menu');
    const visible = await watcher.evaluate(() => Object.fromEntries(
      ['scene', 'reset', 'pause', 'tilt', 'share-control', 'share-view', 'reset-view']
        .map((id) => [id, document.getElementById(id).offsetParent !== null])));
    await watcher.screenshot({ path: path.join(out, 'browser_watcher.png') });
    check(!visible.scene && !visible.reset && !visible.pause && !visible.tilt && !visible['share-control'] &&
          visible['share-view'] && visible['reset-view'],
          'a watcher is offered only what changes its own view (' + JSON.stringify(visible) + ')');
    await watcher.click('#menu');
    const watcherFrames = await watcher.evaluate(() => window.fluidcast.frames);
    await touchDrag(watcher, await context.newCDPSession(watcher), { x: 60, y: 250 }, { x: 240, y: 250 }, 20);
    await waitFor(watcher, `window.fluidcast.frames > ${watcherFrames + 3}`, 'frames after the watcher\'s drag');
    check(await watcher.evaluate(() => window.fluidcast.connected && window.fluidcast.reconnects === 0),
          "a watcher's drag turns its view, and its stream goes on");
    await watcher.close();

    // "Share to play": a second player's scene and pause show in the first page's menu, and the
    // first page's in the second's (ServerMessage.session), so that neither's Pause button lies.
    const controlKey = await page.evaluate(() => window.fluidcast.access.controlKey);
    const player = await context.newPage();
    player.on('pageerror', (e) => { console.log('player error: ' + e.message); failures++; });
    await player.goto(creator.link.replace('#view=' + creator.viewKey, '#control=' + controlKey));
    await waitFor(player, () => window.fluidcast.frames >= 3, 'frames for the second player');
    const sceneBefore = await page.evaluate(() => document.getElementById('scene').value);
    const otherScene = await player.evaluate(
      (current) => window.fluidcast.rules.scenes.find((name) => name !== current), sceneBefore);
    await player.click('#menu');
    await player.selectOption('#scene', otherScene);
    await player.click('#pause');
    await player.click('#menu');
    await waitFor(page, `document.getElementById('scene').value === '${otherScene}' && ` +
                  `document.getElementById('pause').textContent === 'Go on'`,
                  "the second player's scene and pause in the first page's menu", 20000);
    check(true, `the second player's scene (${otherScene}) and pause show in the first page`);
    await page.click('#menu');
    await page.selectOption('#scene', sceneBefore);
    await page.click('#pause');
    await page.click('#menu');
    await waitFor(player, `document.getElementById('scene').value === '${sceneBefore}' && ` +
                  `document.getElementById('pause').textContent === 'Pause'`,
                  "the first page's scene and its going on in the second player's menu", 20000);
    check(true, 'and the first page\'s in the second player\'s');
    await player.close();

    // The same page at a phone's size over HTTPS on an address that is not this machine's own
    // (phone.test, mapped to loopback: an origin that only https makes secure), with the server's
    // self-signed certificate accepted as a person would, and the phone's motion sensors emulated
    // by Chromium: tilt reaches the server and tips the water. Over plain http the same address
    // offers no tilt.
    const plain = await context.newPage();
    await plain.goto(`http://phone.test:${port}/?particles=1000`);
    // The controls are set up once the protocol has loaded: wait for the stream.
    await waitFor(plain, () => window.fluidcast.frames >= 1, 'frames over http on a LAN address');
    const insecure = await plain.evaluate(() => ({
      secure: window.isSecureContext, tilt: document.getElementById('tilt').textContent }));
    check(!insecure.secure && insecure.tilt === 'Tilt: needs https',
          `http on a LAN address: tilt says it needs https (${JSON.stringify(insecure)})`);
    await plain.close();
    const secureContext = await browser.newContext({
      viewport: { width: 390, height: 844 }, isMobile: true, hasTouch: true, ignoreHTTPSErrors: true,
    });
    const secure = await secureContext.newPage();
    secure.on('pageerror', (e) => { console.log('page error: ' + e.message); failures++; });
    await secure.goto(`https://phone.test:${port}/?scene=pool&particles=2000`);
    await waitFor(secure, () => window.fluidcast.frames >= 3, 'frames over https', 30000);
    const https = await secure.evaluate(() => ({
      secure: window.isSecureContext, protocol: location.protocol,
      tilt: document.getElementById('tilt').textContent,
    }));
    check(https.protocol === 'https:' && https.secure && https.tilt === 'Enable tilt',
          `https: a secure page with tilt offered (${JSON.stringify(https)})`);
    const sensors = await secureContext.newCDPSession(secure);
    const setAccelerometer = async (x, y, z) => {
      await sensors.send('Emulation.setSensorOverrideReadings',
                         { type: 'accelerometer', reading: { xyz: { x, y, z } } });
    };
    // Chromium fires devicemotion once all three of the motion sensors it reads have readings.
    for (const type of ['accelerometer', 'linear-acceleration', 'gyroscope']) {
      await sensors.send('Emulation.setSensorOverrideEnabled', { enabled: true, type });
      await sensors.send('Emulation.setSensorOverrideReadings',
                         { type, reading: { xyz: { x: 0, y: 0, z: 0 } } });
    }
    await setAccelerometer(0, 9.81, 0);  // upright: the reaction to gravity points up the screen
    await secure.click('#menu');
    await secure.click('#reset');
    await secure.click('#tilt');
    await secure.click('#menu');
    // The water's centre of mass, from the states the page keeps for a handoff: the image alone
    // cannot tell a tilt from the slosh of a reset fluid when the machine is loaded. Spans are
    // simulated time, not the clock's: on two loaded cores the fluid runs slower than real time.
    await waitFor(secure, () => window.fluidcast.streamed, 'a streamed state');
    const centreAfter = async (seconds) => {
      const from = await secure.evaluate(() => window.fluidcast.streamed.time);
      await waitFor(secure, `window.fluidcast.streamed.time >= ${from + seconds}`,
                    `${seconds} s of simulated time`, 120000);
      return secure.evaluate(() => window.fluidcast.streamed.centre);
    };
    const distance = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    const settling = await centreAfter(2.5);
    const level = await centreAfter(1.5);
    const stillness = distance(settling, level);
    await setAccelerometer(-9.81, 0, 0);  // turned on its side: gravity along the screen's +x
    const tiltedAt = Date.now();
    const tilted = distance(level, await centreAfter(5));
    const tiltWallSeconds = (Date.now() - tiltedAt) / 1000;
    await secure.screenshot({ path: path.join(out, 'browser_tilt.png') });
    const sent = await secure.evaluate(() => window.fluidcast.tilt);
    check(sent && Math.abs(sent.x - 9.81) < 0.2 && Math.abs(sent.y) < 0.2,
          `the emulated sensor's tilt is sent as gravity along the screen's x (${JSON.stringify(sent)})`);
    check(tilted > 3 * stillness + 0.02,
          `the tilt tips the water (its centre of mass moves ${(100 * tilted).toFixed(1)} cm, ` +
          `${(100 * stillness).toFixed(1)} cm in the 1.5 s before; the 5 simulated seconds took ` +
          `${tiltWallSeconds.toFixed(1)} s of the clock)`);
    await secureContext.close();

    // Local mode: the fluid simulated in the page by the solver in WebAssembly and drawn with
    // WebGL2, at a phone's size; a finger stirs it; the stats say it is local.
    const localContext = await browser.newContext({
      viewport: { width: 390, height: 844 }, isMobile: true, hasTouch: true });
    const localPage = await localContext.newPage();
    localPage.on('pageerror', (e) => { console.log('page error: ' + e.message); failures++; });
    await localPage.goto(`http://127.0.0.1:${port}/?local&particles=1000&scene=pool`);
    await waitFor(localPage, () => window.fluidcast.local && window.fluidcast.local.fps > 0,
                  'the local fluid drawing', 30000);
    const localStart = await localPixels(localPage);
    check(spread(localStart) > 10, 'local mode draws a picture (spread ' +
          spread(localStart).toFixed(1) + ')');
    // Fingers swept through the pool move its water by far more than it drifts alone in as long
    // (the drags take 3 s; a pool on two cores runs in slow motion). The water sloshes back and
    // forth after a sweep, so the centre of mass is followed, and its largest shift compared.
    const centreX = () => localPage.evaluate(() => window.fluidcast.local.centre[0]);
    await sleep(2000);
    const settled = await centreX();
    const drift = await largestShift(centreX, settled, () => sleep(4000));
    const localBefore = await centreX();
    const localCdp = await localContext.newCDPSession(localPage);
    const moved = await largestShift(centreX, localBefore, async () => {
      for (let pass = 0; pass < 2; pass++) {
        await touchDrag(localPage, localCdp, { x: 340, y: 480 }, { x: 50, y: 480 }, 30);
      }
      await sleep(1000);
    });
    await localPage.screenshot({ path: path.join(out, 'browser_local.png') });
    check(moved > Math.max(0.02, 3 * drift),
          `a finger moves the local fluid (its centre of mass by up to ${(100 * moved).toFixed(1)} ` +
          `cm; ${(100 * drift).toFixed(1)} cm alone)`);
    const localState = await localPage.evaluate(() => ({
      mode: window.fluidcast.mode, local: window.fluidcast.local,
      stats: document.getElementById('stats').textContent }));
    check(localState.mode === 'local' && localState.local.particles === 1000 &&
          localState.stats.startsWith('local'),
          `the stats say local (${JSON.stringify(localState.stats)})`);
    // The server's pages are cross-origin isolated: the solver may step on the cores the browser
    // leaves (all but two, up to 4; the threaded build itself: tests/wasm).
    const cores = await localPage.evaluate(() => ({
      isolated: self.crossOriginIsolated, cores: navigator.hardwareConcurrency }));
    const wanted = Math.max(1, Math.min(4, cores.cores - 2));
    check(cores.isolated && localState.local.threads === wanted,
          `cross-origin isolated, ${localState.local.threads} solver threads on ${cores.cores} cores`);
    // The same page from a file, no server: it runs.
    const fromFile = await localContext.newPage();
    fromFile.on('pageerror', (e) => { console.log('page error: ' + e.message); failures++; });
    await fromFile.goto('file://' + path.join(webRoot, 'index.html') + '?local&particles=500');
    await waitFor(fromFile, () => window.fluidcast.local && window.fluidcast.local.fps > 0,
                  'the local fluid from a file', 30000);
    check(spread(await localPixels(fromFile)) > 10 &&
          await fromFile.evaluate(() => window.fluidcast.local.threads) === 1,
          'from a file, with no server, it runs (on one thread: a file is not cross-origin isolated)');
    await localContext.close();

    // A session the server refuses (over its particle limit): the reason stays on the screen, in
    // plain words with the server's detail, and the page waits for "Retry now" instead of looping.
    const refused = await context.newPage();
    refused.on('pageerror', (e) => { console.log('page error: ' + e.message); failures++; });
    await refused.goto(`http://127.0.0.1:${port}/?particles=99999999`);
    await waitFor(refused, () => document.getElementById('retry') !== null, 'a refusal', 15000);
    await sleep(2000);
    const refusal = await refused.evaluate(() => ({
      text: document.getElementById('status').textContent,
      reconnects: window.fluidcast.reconnects,
    }));
    check(/limit/.test(refusal.text) && /99999999|99,999,999|particles/.test(refusal.text),
          `the refusal says why: "${refusal.text}"`);
    check(refusal.reconnects === 0, `a refusal is not retried by itself (${refusal.reconnects})`);
    await refused.screenshot({ path: path.join(out, 'browser_refused.png') });
    await refused.close();

    // A count in the address that is not one (it would wrap to 4294967291 on the wire): the page
    // says so in plain words and the server picks the count.
    const misread = await context.newPage();
    misread.on('pageerror', (e) => { console.log('page error: ' + e.message); failures++; });
    await misread.goto(`http://127.0.0.1:${port}/?particles=-5`);
    await waitFor(misread, () => window.fluidcast.connected, 'a session for particles=-5', 15000);
    const chosen = await misread.evaluate(() => ({
      text: document.getElementById('status').textContent,
      particles: window.fluidcast.particles,
    }));
    check(/particles=-5/.test(chosen.text) && /not a number of particles/.test(chosen.text),
          `a count that is not one is named: "${chosen.text}"`);
    check(chosen.particles > 0, `and the server chose one (${chosen.particles})`);
    await misread.screenshot({ path: path.join(out, 'browser_misread_count.png') });
    await misread.close();

    // A scene the server does not have, named in the address: said, and the server picks one
    // (asked for again, it would be refused again).
    const unknownScene = await context.newPage();
    unknownScene.on('pageerror', (e) => { console.log('page error: ' + e.message); failures++; });
    await unknownScene.goto(`http://127.0.0.1:${port}/?scene=nosuch&particles=500`);
    await waitFor(unknownScene, () => window.fluidcast.connected, 'a session for scene=nosuch', 15000);
    const chosenScene = await unknownScene.evaluate(() => ({
      text: document.getElementById('status').textContent, scene: window.fluidcast.scene }));
    check(/scene=nosuch/.test(chosenScene.text) && chosenScene.scene !== 'nosuch',
          `a scene the server lacks is named, and it chose one (${chosenScene.scene}): ` +
          `"${chosenScene.text}"`);
    await unknownScene.close();

    // A page streaming a small session keeps its state; when the server goes away it continues
    // the fluid itself within a frame or two, and when the server is back (restarted: it no
    // longer has the session) it hands the fluid back in a new session and streams again.
    const handing = await context.newPage();
    handing.on('pageerror', (e) => { console.log('page error: ' + e.message); failures++; });
    await handing.goto(`http://127.0.0.1:${port}/?particles=1000`);
    await waitFor(handing, () => window.fluidcast.frames >= 3, 'frames before the handoff');
    await sleep(1500);  // states come four times a second
    const streamed = await handing.evaluate(() => ({ id: window.fluidcast.sessionId,
                                                     time: window.fluidcast.lastFrame.simTime }));

    // A stalled network (nothing comes; what the page sends would arrive together once it moves
    // again): one StateRequest waits for its answer, and a finger's moves wait, the newest going
    // out 4 times a second, so that the server's rates (4 states, 400 inputs a second) are not
    // passed when they arrive and the stream goes on.
    await handing.evaluate(() => {
      window.stall = { states: 0, moves: 0, send, receive };
      send = (fields, isInput) => {
        if (fields.stateRequest) window.stall.states++;
        if (fields.pointer && fields.pointer.phase === 'MOVE') window.stall.moves++;
        return window.stall.send(fields, isInput);
      };
      receive = () => {};
    });
    await sleep(600);  // past the page's 500 ms without a frame
    const stallCdp = await context.newCDPSession(handing);
    await touchDrag(handing, stallCdp, { x: 200, y: 200 }, { x: 100, y: 200 }, 30);  // 20 moves a second
    await sleep(500);
    const stalled = await handing.evaluate(() => {
      send = window.stall.send;
      receive = window.stall.receive;
      return { states: window.stall.states, moves: window.stall.moves };
    });
    check(stalled.states <= 1 && stalled.moves >= 3 && stalled.moves <= 12,
          `while nothing comes, one state request waits (${stalled.states} sent) and a finger's ` +
          `30 moves go 4 a second (${stalled.moves} sent)`);
    // The network moves again: frames come (the server throttled the viewer while no
    // acknowledgement came), and the handoff below is timed from the newest.
    const framesAfterStall = await handing.evaluate(() => window.fluidcast.frames);
    await waitFor(handing, `window.fluidcast.frames > ${framesAfterStall + 2}`, 'frames after the stall');

    // The server goes away: the page that may not continue says so instead of a blank screen.
    child.kill('SIGTERM');
    await waitFor(handing, () => window.fluidcast.mode === 'local' && window.fluidcast.local &&
                                window.fluidcast.local.fps > 0, 'the fluid going on here', 15000);
    await sleep(1000);
    // Kept to see, once the fluid is handed back, that it gave back what it held.
    await handing.evaluate(() => { window.handedBack = handoff.mode; });
    const handingCdp = await context.newCDPSession(handing);
    const listenersWhileLocal = await localCanvasListeners(handingCdp);
    const during = await handing.evaluate(() => ({
      gap: window.fluidcast.handoffGapMs, particles: window.fluidcast.local.particles,
      stats: document.getElementById('stats').textContent,
      status: document.getElementById('status').textContent }));
    await handing.screenshot({ path: path.join(out, 'browser_handoff.png') });
    check(during.particles === 1000 && /network dropped/.test(during.stats) && during.status === '',
          `the server gone, the fluid goes on here (${JSON.stringify(during.stats)})`);
    check(during.gap < 2000, `within a frame or two of the last streamed one (gap ${during.gap.toFixed(0)} ms)`);
    // Meanwhile the controls act on the fluid here: Reset starts it again (the solver's thread
    // resets it and sends the new state: the clock goes back within a second or two).
    const localBeforeReset = await handing.evaluate(() => window.fluidcast.local.time);
    await handing.click('#menu');
    await handing.click('#reset');
    await handing.click('#menu');
    let localAfterReset = localBeforeReset;
    for (let k = 0; k < 50 && localAfterReset >= localBeforeReset; k++) {
      await sleep(100);
      localAfterReset = await handing.evaluate(() => window.fluidcast.local.time);
    }
    check(localAfterReset < localBeforeReset,
          `Reset acts on the fluid here (t = ${localBeforeReset.toFixed(2)} → ` +
          `${localAfterReset.toFixed(2)} s)`);
    // The fluid here runs a while after the Reset, so that the one handed back cannot be taken
    // for a new session's (a few frames in, well under a second): the server goes on from where
    // the page is when it comes back.
    await waitFor(handing, () => window.fluidcast.local.time > 2, 'the fluid here after Reset');
    const localAtRestart = await handing.evaluate(() => window.fluidcast.local.time);
    // What the fluid here last showed, and the first frame streamed after it.
    await handing.evaluate(() => {
      const end = endHandoff, show = showFrame;
      endHandoff = () => {
        if (handoff.mode) window.lastLocalTime = handoff.mode.stats.time;
        end();
      };
      showFrame = (frame) => {
        if (window.lastLocalTime !== undefined && window.firstBackTime === undefined) {
          window.firstBackTime = frame.simTime;
        }
        show(frame);
      };
    });
    restarted = await startServer(port);
    await waitFor(handing, () => window.fluidcast.mode === 'stream' && window.fluidcast.connected,
                  'streaming again', 30000);
    const framesBack = await handing.evaluate(() => window.fluidcast.frames);
    await waitFor(handing, `window.fluidcast.frames > ${framesBack + 2}`, 'frames again');
    const back = await handing.evaluate(() => ({ id: window.fluidcast.sessionId,
      particles: window.fluidcast.particles, time: window.fluidcast.lastFrame.simTime,
      width: window.fluidcast.lastFrame.width, height: window.fluidcast.lastFrame.height }));
    // The stream's canvas is hidden while the fluid goes on here: the size asked for is the screen's.
    check(back.width === 300 && back.height === 400,
          `streamed again at the screen's size (${back.width}×${back.height})`);
    check(back.id !== streamed.id && back.particles === 1000 && back.time >= localAtRestart,
          `the server back, the fluid goes back to it (new session, ${back.particles} particles, ` +
          `t = ${localAtRestart.toFixed(2)} s here → ${back.time.toFixed(2)} s there)`);
    const seam = await handing.evaluate(() => ({ here: window.lastLocalTime, there: window.firstBackTime }));
    check(seam.there >= seam.here - 1e-3,
          `the server goes on from what was last shown here, not from before it (t = ` +
          `${seam.here.toFixed(3)} s here → ${seam.there.toFixed(3)} s in its first frame)`);
    const listenersAfter = await localCanvasListeners(handingCdp);
    const released = await handing.evaluate(() => {
      const view = window.handedBack.view;
      return !view.gl.isProgram(view.depthProgram.program) && !view.gl.isBuffer(view.centres);
    });
    check(listenersWhileLocal > 0 && listenersAfter === 0 && released,
          `the fluid handed back leaves its canvas as it found it (listeners ${listenersWhileLocal} ` +
          `→ ${listenersAfter}, its WebGL objects ${released ? '' : 'not '}deleted)`);

    // Meanwhile the page that may not continue the fluid has said why it stopped.
    await waitFor(page, () => document.getElementById('status').textContent.length > 0,
                  'a message when the server is gone', 15000);
    const message = await page.evaluate(() => document.getElementById('status').textContent);
    check(/server|connection|reconnect/i.test(message), `it says why: "${message}"`);

    // A fluid paused on the server stays paused when it goes on here.
    await sleep(1500);  // states again
    await handing.click('#menu');
    await handing.click('#pause');
    await handing.click('#menu');
    await sleep(1500);  // states of the paused fluid
    const handoffsBeforePause = await handing.evaluate(() => window.fluidcast.handoffs);
    await stopServer(restarted.child);
    await waitFor(handing, `window.fluidcast.handoffs > ${handoffsBeforePause} && ` +
                           `window.fluidcast.mode === 'local'`, 'the paused fluid here', 15000);
    await sleep(500);
    const pausedAt = await handing.evaluate(() => window.fluidcast.local.time);
    await sleep(1500);
    const pausedLater = await handing.evaluate(() => window.fluidcast.local.time);
    check(pausedLater === pausedAt,
          `a paused fluid stays paused here (t = ${pausedAt.toFixed(3)} → ${pausedLater.toFixed(3)} s)`);
    restarted = await startServer(port);
    await waitFor(handing, () => window.fluidcast.mode === 'stream' && window.fluidcast.connected,
                  'streaming the paused fluid again', 30000);
    await sleep(1000);
    const backPausedAt = await handing.evaluate(() => window.fluidcast.lastFrame.simTime);
    await sleep(1000);
    const backPausedLater = await handing.evaluate(() => window.fluidcast.lastFrame.simTime);
    check(backPausedLater === backPausedAt,
          `and paused in the session it goes back to (t = ${backPausedAt.toFixed(3)} → ` +
          `${backPausedLater.toFixed(3)} s)`);
    // Going on again, for what follows.
    await handing.click('#menu');
    await handing.click('#pause');
    await handing.click('#menu');

    // The server back before the fluid here has started (a slow phone): the stream wins, and the
    // fluid here, once started, stops at once rather than covering the stream.
    await sleep(1500);  // states again
    const timeBeforeRace = await handing.evaluate(() => window.fluidcast.lastFrame.simTime);
    const handoffsBeforeRace = await handing.evaluate(() => window.fluidcast.handoffs);
    await handing.evaluate(() => {
      const start = window.realStartFrom = LocalMode.startFrom;
      window.releaseStart = null;
      LocalMode.startFrom = async (...args) => {  // held until the stream is back
        await new Promise((resolve) => { window.releaseStart = resolve; });
        return start(...args);
      };
    });
    await stopServer(restarted.child);
    restarted = await startServer(port);
    await waitFor(handing, () => window.fluidcast.connected, 'streaming again, the fluid here not started', 30000);
    const startHeld = await handing.evaluate(() => window.releaseStart !== null);
    await handing.evaluate(() => window.releaseStart && window.releaseStart());
    await sleep(3000);  // the fluid here starts, late
    const raced = await handing.evaluate(() => ({
      mode: window.fluidcast.mode, connected: window.fluidcast.connected,
      localHidden: document.getElementById('local-view').hidden,
      time: window.fluidcast.lastFrame.simTime }));
    const framesRaced = await handing.evaluate(() => window.fluidcast.frames);
    await sleep(1000);
    const framesLater = await handing.evaluate(() => window.fluidcast.frames);
    const handoffsAfterRace = await handing.evaluate(() => window.fluidcast.handoffs);
    check(startHeld && handoffsAfterRace === handoffsBeforeRace &&
          raced.mode === 'stream' && raced.connected && raced.localHidden &&
          framesLater > framesRaced && await localCanvasListeners(handingCdp) === 0,
          `a stream back before the fluid here started keeps the screen (${JSON.stringify(raced)}, ` +
          `frames ${framesRaced} → ${framesLater})`);
    check(raced.time >= timeBeforeRace,
          `and the server, restarted, goes on from the newest state streamed (t = ` +
          `${timeBeforeRace.toFixed(2)} s before → ${raced.time.toFixed(2)} s)`);

    // The network drops while the server stays up (a phone between networks): the fluid goes on
    // here, and then back into the session it left, which another device watches throughout.
    await sleep(1500);  // states again
    const left = await handing.evaluate(() => ({ id: window.fluidcast.sessionId,
                                                 viewKey: window.fluidcast.access.viewKey }));
    const onlooker = await context.newPage();
    onlooker.on('pageerror', (e) => { console.log('onlooker error: ' + e.message); failures++; });
    await onlooker.goto(`http://127.0.0.1:${port}/#view=${left.viewKey}`);
    await waitFor(onlooker, () => window.fluidcast.frames >= 3, 'frames for the onlooker');
    await handing.evaluate(() => { LocalMode.startFrom = window.realStartFrom; });  // as before the race
    await dropNetwork(handing, 'the fluid going on here while the network is down');
    // Reset here: the fluid handed back is one the session's clock can tell from its own (it
    // went on meanwhile, for the onlooker), and the onlooker's clock goes back once it is in.
    const localBeforeDropReset = await handing.evaluate(() => window.fluidcast.local.time);
    await handing.click('#menu');
    await handing.click('#reset');
    await handing.click('#menu');
    await waitFor(handing, `window.fluidcast.local.time < ${localBeforeDropReset}`, 'the Reset here');
    await onlooker.evaluate(() => {
      const show = showFrame;
      window.newestTime = 0;
      window.wentBack = 0;
      showFrame = (frame) => {
        if (frame.simTime < window.newestTime - 0.5) window.wentBack = window.newestTime - frame.simTime;
        window.newestTime = Math.max(window.newestTime, frame.simTime);
        show(frame);
      };
    });
    await sleep(1000);
    const localAtReturn = await handing.evaluate(() => {
      window.WebSocket = window.RealWebSocket;
      return window.fluidcast.local.time;
    });
    const rejoined = await streamingAgain(handing, 'streaming again once the network is back');
    check(rejoined.id === left.id && rejoined.time >= localAtReturn && rejoined.status === '',
          `the network back, the fluid goes back into the session it left (` +
          `${rejoined.id === left.id ? 'the same' : 'another'} session, t = ` +
          `${localAtReturn.toFixed(2)} s here → ${rejoined.time.toFixed(2)} s there, ` +
          `status "${rejoined.status}")`);
    await waitFor(onlooker, () => window.wentBack > 0, 'the onlooker\'s clock going back', 15000)
      .catch(() => {});  // said by the check below
    const onlooking = await onlooker.evaluate(() => ({ id: window.fluidcast.sessionId,
      reconnects: window.fluidcast.reconnects, wentBack: window.wentBack }));
    check(onlooking.id === rejoined.id && onlooking.reconnects === 0 && onlooking.wentBack > 0,
          `and the device watching it watches it still, its clock back to the fluid handed back ` +
          `(${JSON.stringify(onlooking)})`);

    // Away past the server's grace, the page's seat is forgotten (here: its resume key made one
    // the server never gave) while the onlooker keeps the session alive: the page takes a new
    // seat in the session it left with the session's key, its fluid with it.
    await sleep(1500);  // states again
    await dropNetwork(handing, 'the fluid going on here while the network is down again');
    const localAtSecondReturn = await handing.evaluate(() => {
      window.fluidcast.access.resumeKey = 'f'.repeat(32);
      window.WebSocket = window.RealWebSocket;
      return window.fluidcast.local.time;
    });
    const reseated = await streamingAgain(handing, 'streaming again, in a new seat');
    const stillOnlooking = await onlooker.evaluate(() => ({ id: window.fluidcast.sessionId,
      reconnects: window.fluidcast.reconnects }));
    check(reseated.id === left.id && reseated.control && reseated.time >= localAtSecondReturn &&
          reseated.status === '' && stillOnlooking.id === left.id && stillOnlooking.reconnects === 0,
          `its seat forgotten, the page takes a new one in the session it left, with its fluid (` +
          `${JSON.stringify(reseated)}, t = ${localAtSecondReturn.toFixed(2)} s here; the ` +
          `onlooker: ${JSON.stringify(stillOnlooking)})`);
    await onlooker.close();
    await handing.close();

  } finally {
    const stopped = Promise.all([stopServer(child), restarted && stopServer(restarted.child)]);
    await browser.close().finally(() => stopped);
  }
  console.log(`${passes} passed, ${failures} failed`);
  process.exit(failures === 0 ? 0 : 1);
}

main().catch((error) => {
  console.log('FAIL ' + error.message);
  console.log(`${passes} passed, ${failures + 1} failed`);
  process.exit(1);
});
