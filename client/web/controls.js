// The phone page's input and controls: touches (one finger drags the fluid, two orbit and zoom),
// tilt as gravity, the menu's controls, sharing links, the screen's wake lock, a hidden tab and
// resizing. Loaded after app.js, whose state and sending it uses.

// ---- input ---------------------------------------------------------------------------------

const pointerIds = new Map();  // the browser's pointer id → ours, below 16

function normalised(event) {
  const bounds = page.canvas.getBoundingClientRect();  // the page may be scrolled or offset
  const scale = page.canvas.width / bounds.width;
  const px = (event.clientX - bounds.left) * scale, py = (event.clientY - bounds.top) * scale;
  const f = state.lastFrame || viewport();
  const rect = frameRect(f.width, f.height);
  const clamp = (v) => Math.min(1, Math.max(0, v));
  return { x: clamp((px - rect.x) / rect.w), y: clamp((py - rect.y) / rect.h) };
}

// While no frame has come for kStallMs (a stalled network), each finger's moves and the tilt wait
// here, the newest replacing the one waiting, and go out every kReleaseHeldMs: held up by the
// network, two fingers' 120 moves a second would arrive together, past the server's input rate
// (ServerLimits.max_input_events_per_second), and end the stream.
const kStallMs = 500, kReleaseHeldMs = 250;
const heldInputs = new Map();  // our pointer id, or 'tilt' → the message

// No frame for kStallMs, or for twice the recent frames' interval where they come slower (a
// throttled viewer), up to 2 s: moves held 2 s at most arrive within the server's rate.
function stalled() {
  const n = frameTimes.length;
  const interval = n >= 2 ? (frameTimes[n - 1] - frameTimes[0]) / (n - 1) : 0;
  return performance.now() - lastFrameAt > Math.min(2000, Math.max(kStallMs, 2 * interval));
}

function sendInput(key, fields) {
  heldInputs.delete(key);  // replaced by this one
  if (stalled())
    heldInputs.set(key, fields);
  else send(fields, true);
}

setInterval(() => {
  for (const fields of heldInputs.values()) send(fields, true);
  heldInputs.clear();
}, kReleaseHeldMs);

function pointer(event, phase) {
  let id = pointerIds.get(event.pointerId);
  if (id === undefined) {
    if (phase !== 'DOWN') return;
    const used = new Set(pointerIds.values());
    const ids = state.rules ? state.rules.pointerIds : 0;  // none before the Welcome
    for (id = 0; id < ids && used.has(id); id++);
    if (id === ids) return;
    pointerIds.set(event.pointerId, id);
  }
  const at = normalised(event);
  const fields = { pointer: { pointerId: id, phase, x: at.x, y: at.y } };
  if (phase === 'MOVE') {
    sendInput(id, fields);
  } else {
    heldInputs.delete(id);  // where it went down or up says where it is
    send(fields, true);
  }
  if (phase === 'UP' || phase === 'CANCEL') {
    pointerIds.delete(event.pointerId);
    lastMove.delete(event.pointerId);
  }
}

page.canvas.addEventListener('pointerdown', (e) => {
  page.canvas.setPointerCapture(e.pointerId);
  pointer(e, 'DOWN');
});
// Moves at most 60 a second per finger, and for all of them together at most half the server's
// input rate (Welcome.limits): a hand on the screen, 10 fingers' 600 a second, would pass it and
// end the stream.
const lastMove = new Map();
function moveIntervalMs() {
  const rate = state.limits ? state.limits.maxInputEventsPerSecond : 0;
  return rate ? Math.max(16, 2000 * pointerIds.size / rate) : 16;
}
page.canvas.addEventListener('pointermove', (e) => {
  if (!pointerIds.has(e.pointerId)) return;
  const now = performance.now();
  if (now - (lastMove.get(e.pointerId) || 0) < moveIntervalMs()) return;
  lastMove.set(e.pointerId, now);
  pointer(e, 'MOVE');
});
page.canvas.addEventListener('pointerup', (e) => pointer(e, 'UP'));
page.canvas.addEventListener('pointercancel', (e) => pointer(e, 'CANCEL'));
page.canvas.addEventListener('contextmenu', (e) => e.preventDefault());

// Tilt: the accelerometer's reading includes the reaction to gravity (up when still); gravity is
// its opposite, turned into screen axes for the screen's orientation.
let lastTiltSent = 0;
function onMotion(event) {
  const a = event.accelerationIncludingGravity;
  if (!a || a.x === null) return;
  const angle = ((screen.orientation && screen.orientation.angle) || window.orientation || 0) *
                Math.PI / 180;
  const c = Math.cos(angle), s = Math.sin(angle);
  // The sensor's axes are the device's (portrait); the screen's turn with its orientation.
  const gravity = { x: -(a.x * c - a.y * s), y: -(a.x * s + a.y * c), z: -a.z };
  const magnitude = Math.hypot(gravity.x, gravity.y, gravity.z);
  const now = performance.now();
  if (now - lastTiltSent < 50) return;  // 20 a second
  // Free fall, a first zero, or a shake past what the server takes: nothing. The server's range
  // holds for a fluid continued here too, whose state goes back to it.
  const range = state.rules && state.rules.tiltGravity;
  const within = range ? magnitude >= range.min && magnitude <= range.max : magnitude > 0.1;
  if (!within) return;
  const here = local || (handoff && handoff.mode);
  if (here) {
    lastTiltSent = now;
    state.tilt = gravity;
    here.tilt(gravity);
    return;
  }
  if (!state.access || !state.access.control) return;  // tilting is playing, not watching
  lastTiltSent = now;
  state.tilt = gravity;
  sendInput('tilt', { tilt: gravity });
}

// Why tilt cannot work in this browser, or '' when it can: browsers give motion sensors only to
// secure pages (https://, or this machine's own address).
function tiltUnavailable() {
  if (!window.isSecureContext) {
    return 'Tilt needs a secure page: open this one through https:// (the server prints the ' +
           'address when it has a certificate).';
  }
  if (typeof DeviceMotionEvent === 'undefined') return 'This browser has no motion sensors.';
  return '';
}

async function enableTilt() {
  const why = tiltUnavailable();
  if (why) {
    sayFor(why, 5000);
    return;
  }
  try {
    // iOS asks the person first, and only from a tap.
    if (typeof DeviceMotionEvent !== 'undefined' &&
        typeof DeviceMotionEvent.requestPermission === 'function') {
      const answer = await DeviceMotionEvent.requestPermission();
      if (answer !== 'granted') {
        say('Tilt needs permission for motion sensors.');
        return;
      }
    }
    window.addEventListener('devicemotion', onMotion);
    page.panel.querySelector('#tilt').textContent = 'Tilt on';
  } catch (error) {
    say('Tilt is not available here: ' + error.message);
  }
}

// ---- controls ------------------------------------------------------------------------------

function command(fields) { send({ command: fields }, true); }

// The scene and renderer menus offer what the server says it has (Welcome.rules): its scenes, and
// the renderers its device can draw.
function fillMenus(rules) {
  fillScenes(rules.scenes);
  const renderer = page.panel.querySelector('#renderer');
  renderer.replaceChildren(...rules.renderers.map((name) => new Option(name, name)));
  renderer.value = rules.renderers.includes(wanted.renderer) ? wanted.renderer : 'auto';
}

function fillScenes(names) {
  page.panel.querySelector('#scene').replaceChildren(
    ...names.map((name) => new Option(name.replace(/_/g, ' '), name)));
}

// A viewer that only watches sees no control that would change the fluid (its one finger orbits);
// one that plays may also share the link to play.
function showAccess(access) {
  document.body.classList.toggle('view-only', !access.control);
}

// The link that opens this session with `key`: shared through the system's sheet where there is
// one, else copied, else shown to copy by hand.
async function shareLink(kind, key) {
  const url = location.origin + location.pathname + location.search + '#' + kind + '=' + key;
  const what = kind === 'control' ? 'play with this fluid' : 'watch this fluid';
  try {
    if (navigator.share) {
      await navigator.share({ title: 'fluidcast', text: 'Come and ' + what, url });
      return;
    }
    if (navigator.clipboard && window.isSecureContext) {
      await navigator.clipboard.writeText(url);
      sayFor('Link copied: whoever opens it can ' + what + '.', 4000);
      return;
    }
  } catch (error) {
    if (error.name === 'AbortError') return;  // the person closed the share sheet
  }
  window.prompt('Whoever opens this link can ' + what + ':', url);
}

function setupControls() {
  const scene = page.panel.querySelector('#scene');
  const renderer = page.panel.querySelector('#renderer');
  page.panel.querySelector('#adaptive').checked = wanted.adaptive;
  // Each control acts on the fluid simulated here when there is one (local mode, or after the
  // network dropped), else on the server's; a failure here is said, the fluid stays as it was.
  const act = (hereAction, serverAction) => () => {
    const fluid = local || (handoff && handoff.mode);
    if (!fluid) return serverAction();
    Promise.resolve().then(() => hereAction(fluid)).catch((error) => sayFor(error.message, 5000));
  };
  scene.onchange = act((fluid) => fluid.create(scene.value, fluid.stats.solver, fluid.stats.particles),
                       () => command({ scene: scene.value }));
  renderer.onchange = () => { wanted.renderer = renderer.value; command({ quality: quality() }); };
  const jpeg = page.panel.querySelector('#quality');
  jpeg.onchange = () => { wanted.quality = Number(jpeg.value); command({ quality: quality() }); };
  const adaptive = page.panel.querySelector('#adaptive');
  adaptive.onchange = () => { wanted.adaptive = adaptive.checked; command({ quality: quality() }); };
  page.panel.querySelector('#reset').onclick =
    act((fluid) => fluid.reset(), () => command({ reset: true }));
  page.panel.querySelector('#reset-view').onclick =
    act((fluid) => fluid.resetView(), () => command({ resetView: true }));
  page.panel.querySelector('#pause').onclick = () => {
    showPaused(!paused);
    act((fluid) => { fluid.paused = paused; }, () => command({ pause: paused }))();
  };
  // Switching reloads the page in the other mode (?local), keeping the other parameters.
  const mode = page.panel.querySelector('#mode');
  mode.textContent = local ? 'Stream from the server' : 'Simulate here';
  mode.onclick = () => {
    const next = new URLSearchParams(location.search);
    if (local) next.delete('local');
    else next.set('local', '');
    location.search = next.toString();
  };
  page.panel.querySelector('#share-view').onclick = () => shareLink('view', state.access.viewKey);
  page.panel.querySelector('#share-control').onclick =
    () => shareLink('control', state.access.controlKey);
  const tilt = page.panel.querySelector('#tilt');
  tilt.onclick = enableTilt;
  if (tiltUnavailable()) {
    tilt.textContent = 'Tilt: needs https';
    tilt.title = tiltUnavailable();
  }
  const fullscreen = page.panel.querySelector('#fullscreen');
  fullscreen.hidden = !document.fullscreenEnabled;  // an iPhone's Safari has none
  fullscreen.onclick = () => {
    if (document.fullscreenElement) document.exitFullscreen();
    else document.documentElement.requestFullscreen().catch((e) => say(e.message));
  };
  page.panel.querySelector('#toggle-stats').onclick = (e) => {
    page.stats.hidden = !page.stats.hidden;
    e.target.textContent = page.stats.hidden ? 'Show stats' : 'Hide stats';
  };
  document.getElementById('menu').onclick = () => { page.panel.hidden = !page.panel.hidden; };
}

function fitCanvas() {
  const scale = window.devicePixelRatio || 1;
  page.canvas.width = Math.round(page.canvas.clientWidth * scale);
  page.canvas.height = Math.round(page.canvas.clientHeight * scale);
}

// The screen stays on while frames come (secure pages only; elsewhere it sleeps as set).
let wakeLock = null;
async function keepAwake() {
  if (wakeLock || !('wakeLock' in navigator) || document.hidden) return;
  try {
    wakeLock = await navigator.wakeLock.request('screen');
    wakeLock.addEventListener('release', () => { wakeLock = null; });
  } catch (error) {
    wakeLock = null;  // refused (battery saver): not worth a message
  }
}

// A hidden tab streams nothing: the stream closes, and the session waits (the server's resume
// grace, or longer while another device watches it) for the tab to come back and resume it.
let hiddenPause = false;
document.addEventListener('visibilitychange', () => {
  if (local) {  // the browser stops animating a hidden page, and the fluid with it
    if (!document.hidden) keepAwake();  // the lock went with the page
    return;
  }
  if (document.hidden) {
    hiddenPause = true;
    clearTimeout(retryTimer);  // no retry in the background either
    if (socket) {
      socket.closedForHidden = true;
      socket.close();
    }
  } else if (hiddenPause) {
    hiddenPause = false;
    retryNow();  // or, while the hidden tab's socket is still closing, its close reconnects
  }
});

let resizeTimer = 0;
window.addEventListener('resize', () => {
  if (local || (handoff && handoff.mode)) fitLocalCanvas();
  if (local) return;
  fitCanvas();
  clearTimeout(resizeTimer);
  resizeTimer = setTimeout(() => command({ viewport: viewport() }), 250);
});
