// The phone page: shows a fluidcast session's frames on a full-screen canvas and sends touches,
// tilt and commands back. It speaks proto/fluidcast/v1/fluidcast.proto (read here by protobufjs)
// in binary WebSocket frames on /ws, with the same rules as the gRPC Stream.
'use strict';

const page = {
  canvas: document.getElementById('view'),
  status: document.getElementById('status'),
  stats: document.getElementById('stats'),
  panel: document.getElementById('panel'),
};
const context = page.canvas.getContext('2d');

// What the browser test (tests/browser) and a curious person can read.
const state = window.fluidcast = {
  connected: false,
  frames: 0,
  fps: 0,
  latencyMs: [],  // touch-to-photon, the last 100
  bitrateKbps: 0,
  sessionId: '',  // names the session (logs); opens nothing
  viewerId: 0,
  access: null,   // Welcome.access: whether this viewer controls the fluid, and its keys
  lastFrame: null,  // sequence, sim time, size, renderer, timings
  reconnects: 0,
  tilt: null,       // the last gravity sent
  rules: null,      // what inputs may be (Welcome.rules): the menus, pointer ids, the tilt range
  limits: null,     // the server's limits (Welcome.limits): the largest frame it draws
  mode: 'stream',   // or 'local': simulated in this page (?local, or after the network dropped)
  handoffs: 0,      // times the page continued a streamed fluid by itself
  handoffGapMs: 0,  // the last one's gap: from the last frame streamed to the first drawn here
  local: null,      // local mode's figures: fps, stepMs, speed, particles, scene, solver
  streamed: null,   // the newest state streamed (while asked for): centre of mass (m), time (s)
  // Drops the connection as a lost network would (for tests, and to try the reconnect).
  drop: () => { if (socket) socket.close(); },
};

let types = null;      // protobufjs message types
let socket = null;
let nextEventId = 1;
const sentAt = new Map();  // event id → time sent
let token = localStorage.getItem('fluidcast.token') || '';
// ?scene=pool&particles=2000&renderer=ssfr&adaptive=0 in the address: what a new session
// starts with, and how this viewer wants it.
const query = new URLSearchParams(location.search);
// ?particles=N is a whole number above 0; anything else leaves the count to the server, and says so.
const askedParticles = query.get('particles');
const particlesInAddress = /^[0-9]{1,10}$/.test(askedParticles || '') &&
    Number(askedParticles) > 0 && Number(askedParticles) < 2 ** 32 ? Number(askedParticles) : 0;
let addressProblem = askedParticles !== null && particlesInAddress === 0
    ? `"particles=${askedParticles}" in the address is not a number of particles: the server ` +
      'chose how many.'
    : '';
let wanted = {
  quality: 0, renderer: query.get('renderer') || '', adaptive: query.get('adaptive') !== '0',
  scene: query.get('scene') || '', particles: particlesInAddress,
};
let paused = false;
let local = null;  // the LocalMode when this page simulates the fluid itself (?local)
let retryDelayMs = 500;
// A stream ended by an answer that changes what the next Hello asks (a token, a new session, an
// address's mistake dropped) is asked again after this, with no "dropped" message meanwhile.
const kAskAgainMs = 100;
let retryTimer = 0;
let giveUp = false;
// Why the last stream ended, in words for the person holding the phone, when the server said:
// what the close that follows shows, instead of a bare "dropped".
let endReason = '';
// Why the server did not give our session back, when it did not: the next one is new.
let sessionLost = '';
// This connection's Hello puts the fluid here back into the session it left (until its Welcome or
// its close).
let handingBack = false;
let askedViewport = null;  // the size the last Hello asked for
// A shared link's key (#view=… or #control=…, in the fragment so that it never reaches a server's
// logs): the session this page joins, and whether it may play or only watch.
let joinKey = (/^#(?:view|control)=([0-9a-f]{32})$/.exec(location.hash) || [])[1] || '';
const kServerDefaultQuality = 80;  // Quality.jpeg_quality 0 (fluidcast.proto)

// The server's status codes in plain words; its own sentence, written for protocol developers,
// follows as the detail.
const plainWords = {
  RESOURCE_EXHAUSTED: 'The server is at one of its limits',
  INVALID_ARGUMENT: 'The server could not use what this page asked for',
  FAILED_PRECONDITION: 'The server could not use what this page asked for',
  PERMISSION_DENIED: 'This link lets you watch, not play',
  UNAVAILABLE: 'The server is shutting down or restarting',
  INTERNAL: 'The server ran into a problem',
  DEADLINE_EXCEEDED: 'Paused: nobody touched the fluid for a while',
};

// Shows `text` in the middle of the screen (nothing: hides it), with a "Retry now" button when
// `retry` is set.
function say(text, retry = false) {
  page.status.textContent = text;
  if (retry && text) {
    const button = document.createElement('button');
    button.id = 'retry';
    button.textContent = 'Retry now';
    button.onclick = retryNow;
    page.status.append(document.createElement('br'), button);
  }
}

// Shows `text` for `ms`, then hides it unless something else is shown by then.
function sayFor(text, ms) {
  say(text);
  setTimeout(() => { if (page.status.textContent === text) say(''); }, ms);
}

function retryNow() {
  clearTimeout(retryTimer);
  giveUp = false;
  endReason = '';
  retryDelayMs = 500;
  if (!socket) connect();
}

// While no frames come, the figures of the last ones would mislead (while the fluid goes on
// here, the overlay shows its figures instead, and a failed retry must not blank them).
function clearStats() {
  state.fps = 0;
  state.bitrateKbps = 0;
  state.latencyMs = [];
  frameTimes = [];
  bytesWindow = [];
  if (state.mode === 'stream') page.stats.textContent = '';
}

// ---- protocol ------------------------------------------------------------------------------

async function loadProtocol() {
  if (typeof protobuf === 'undefined') {
    throw new Error('the page could not load protobufjs from the server (/vendor/protobuf.min.js)');
  }
  const root = await protobuf.load('fluidcast.proto');
  return {
    ClientMessage: root.lookupType('fluidcast.v1.ClientMessage'),
    ServerMessage: root.lookupType('fluidcast.v1.ServerMessage'),
  };
}

function send(fields, isInput) {
  if (!socket || socket.readyState !== WebSocket.OPEN) return 0;
  // Until the Welcome only the Hello goes: anything before it would end the stream, and what was
  // asked meanwhile (a size) is asked again at the Welcome.
  if (!fields.hello && !state.connected) return 0;
  const message = Object.assign({}, fields);
  if (isInput) {
    message.eventId = nextEventId++;
    sentAt.set(message.eventId, performance.now());
    if (sentAt.size > 200) sentAt.delete(sentAt.keys().next().value);  // frames stopped coming
  }
  // fromObject turns enum names ('DOWN') into their numbers.
  socket.send(types.ClientMessage.encode(types.ClientMessage.fromObject(message)).finish());
  return message.eventId || 0;
}

// The frame size to ask for: the streamed canvas's, or the local one's while the fluid goes on here
// (the hidden one has no size).
function viewport() {
  return pixelSize(page.canvas.hidden ? document.getElementById('local-view') : page.canvas);
}

// Device pixels, capped: a phone's 3× screen does not need 3× the pixels streamed or drawn, and
// no frame is larger than the server draws (its limits, once it has said them).
function pixelSize(element) {
  const cssWidth = element.clientWidth, cssHeight = element.clientHeight;
  const limits = state.limits;
  const scale = Math.min(window.devicePixelRatio || 1, 2,
                         Math.max(cssWidth, cssHeight) > 0 ? 1920 / Math.max(cssWidth, cssHeight) : 1,
                         Math.min(cssWidth, cssHeight) > 0 ? 1080 / Math.min(cssWidth, cssHeight) : 1,
                         limits && cssWidth > 0 ? limits.maxWidth / cssWidth : 1,
                         limits && cssHeight > 0 ? limits.maxHeight / cssHeight : 1);
  return { width: Math.max(1, Math.round(cssWidth * scale)),
           height: Math.max(1, Math.round(cssHeight * scale)) };
}

function quality() {
  return { jpegQuality: wanted.quality, renderer: wanted.renderer, adaptive: wanted.adaptive };
}

// Back to the session left: this page's own seat, or, where the server has forgotten that (away
// past its grace) while others still watch, a new seat with the session's key.
function wayBack(access) {
  return { key: access.resumeKey, sessionKey: access.control ? access.controlKey : access.viewKey };
}

function connect() {
  giveUp = false;
  const scheme = location.protocol === 'https:' ? 'wss:' : 'ws:';
  socket = new WebSocket(scheme + '//' + location.host + '/ws');
  const opened = socket;
  socket.binaryType = 'arraybuffer';
  say(state.access || joinKey ? 'Reconnecting…' : 'Connecting…');
  socket.onopen = async () => {
    const hello = { token, quality: quality() };
    if (handoff && handoff.mode) {
      // The fluid went on here: it goes back into the session it left (whoever else watches that
      // stays with it) or, once the server no longer has that, into a new one. It stops here
      // while its state goes over, so that the server goes on from where it was last shown.
      handoff.mode.paused = true;
      const carried = await handoff.mode.exportState();
      if (socket !== opened) return;  // closed meanwhile; a new connection says its own Hello
      if (state.access) {
        hello.resume = { ...wayBack(state.access), state: carried };
        handingBack = true;
      } else {
        hello.create = { state: carried };
      }
    } else if (state.access) {
      hello.resume = wayBack(state.access);
    } else if (handoff) {
      // The session is gone and the fluid here has not started yet: the newest state streamed.
      hello.create = { state: handoff.snapshot };
    } else if (joinKey) {
      hello.join = joinKey;  // a shared link
    } else {
      hello.create = { scene: wanted.scene, particles: wanted.particles };
    }
    hello.viewport = viewport();  // as it is now, after a state that took a while to export
    askedViewport = hello.viewport;
    send({ hello }, false);
  };
  socket.onmessage = (event) => receive(new Uint8Array(event.data));
  socket.onclose = () => {
    state.connected = false;
    socket = null;
    heldInputs.clear();  // a new stream starts with no finger down
    handingBack = false;  // ended() has read it: the server's end comes before the close
    if (handoff && handoff.mode) handoff.mode.paused = paused;  // not handed back: it goes on here
    clearInterval(stateTimer);
    clearStats();
    if (hiddenPause) return;
    if (opened.closedForHidden) {  // the tab was shown again before this close came
      connect();
      return;
    }
    if (!giveUp && newestState && !handoff) startHandoff(newestState);
    if (giveUp) {
      if (endReason) say(endReason, true);
      return;
    }
    // The network dropped or the server went away: try again, resuming the session (or, while
    // the fluid goes on here, handing it back; the stats say so, the screen stays clear).
    if (retryDelayMs > kAskAgainMs) {
      say(handoff ? '' : (endReason || 'The connection dropped') + '; reconnecting in ' +
          (retryDelayMs / 1000).toFixed(1) + ' s…', !handoff);
    }
    endReason = '';
    retryTimer = setTimeout(() => { state.reconnects++; connect(); }, retryDelayMs);
    retryDelayMs = Math.min(retryDelayMs * 2, 8000);
  };
}

function receive(bytes) {
  const message = types.ServerMessage.decode(bytes);
  if (message.welcome) {
    state.connected = true;
    state.sessionId = message.welcome.sessionId;
    state.viewerId = message.welcome.viewerId;
    state.access = message.welcome.access;
    state.rules = message.welcome.rules;
    state.limits = message.welcome.limits;
    fillMenus(state.rules);
    showAccess(state.access);
    retryDelayMs = 500;
    lastFrameAt = performance.now();  // a new stream: its frames are not late yet
    keepAwake();
    // The address bar opens what this page may do: a reload comes back to the same fluid.
    joinKey = state.access.control ? state.access.controlKey : state.access.viewKey;
    history.replaceState(null, '', (state.access.control ? '#control=' : '#view=') + joinKey);
    handingBack = false;
    const handedBack = handoff !== null && handoff.mode !== null;
    if (sessionLost) {
      sayFor(sessionLost + (handedBack ? ': your fluid goes on in a new session, with a new link.'
                                       : ': this is a new session.'), 5000);
      sessionLost = '';
    } else if (addressProblem) {
      sayFor(addressProblem, 5000);
      addressProblem = '';
    } else {
      say('');
    }
    const size = viewport();  // turned or resized between the Hello and its Welcome
    if (size.width !== askedViewport.width || size.height !== askedViewport.height) {
      command({ viewport: size });
    }
    // The fluid handed back goes on as it was here, paused or not (a state carries no pause, and
    // the session it left may be paused).
    const pausedHere = paused;
    showSession(message.welcome.state);
    if (handoff) endHandoff();
    if (handedBack && pausedHere !== message.welcome.state.paused) {
      command({ pause: pausedHere });
      showPaused(pausedHere);
    }
    askForStates();
  } else if (message.session) {
    // Another scene or count, or a pause, from this page or another viewer: the menu and the Pause
    // button show it. A new fluid's states are asked for afresh (none kept from the old one), if
    // the page keeps states for its count.
    const another = message.session.particles !== state.particles ||
      message.session.scene !== state.scene || message.session.solver !== state.solver;
    showSession(message.session);
    if (another) askForStates();
  } else if (message.state) {
    stateAskedAt = 0;
    newestState = message.state;
    state.streamed = { centre: centreOfMass(newestState.positions), time: newestState.time };
  } else if (message.frame) {
    showFrame(message.frame);
  } else if (message.end) {
    ended(message.end.code, message.end.message);
  }
}

function ended(code, text) {
  if (code === 'UNAUTHENTICATED') {
    giveUp = true;
    const given = window.prompt('This server needs a token. ' + text, '');
    if (given !== null) {
      token = given;
      localStorage.setItem('fluidcast.token', token);
      giveUp = false;  // onclose reconnects
      retryDelayMs = kAskAgainMs;
    } else {
      say('No token given: ' + text, true);
    }
  } else if (code === 'INVALID_ARGUMENT' && !state.connected && droppedFromAddress(text)) {
    retryDelayMs = kAskAgainMs;  // onclose asks again without it
  } else if (code === 'NOT_FOUND' || (handingBack && code !== 'UNAVAILABLE' && code !== 'INTERNAL')) {
    // The session is gone (the server restarted, or nobody watched it past the grace), or it
    // would not take the fluid here back (its seats taken, say): start a new one, and say so.
    state.sessionId = '';
    state.viewerId = 0;
    state.access = null;
    joinKey = '';
    sessionLost = code === 'NOT_FOUND'
      ? 'That session has ended (the server may have restarted, or nobody watched it for a while)'
      : 'The session you left did not take your fluid back (' + text + ')';
    retryDelayMs = kAskAgainMs;
  } else {
    endReason = (plainWords[code] || 'The server ended the stream') + ' (' + text + ')';
    // Going away or a fault may pass; a limit or a request it cannot use would be refused again:
    // that waits for the person (Retry now).
    if (code !== 'UNAVAILABLE' && code !== 'INTERNAL') giveUp = true;
  }
}

// A scene or renderer in the address that this server does not have (its refusal of the Hello names
// the field) is dropped, the server choosing instead, and said, as a count that is not one is:
// asked for again, it would be refused again.
function droppedFromAddress(text) {
  const drop = (field, name) => {
    if (!wanted[name] || !text.includes(field)) return false;
    addressProblem = (addressProblem ? addressProblem + ' ' : '') +
        `"${name}=${wanted[name]}" in the address is not a ${name} this server ` +
        'has: it chose one.';
    wanted[name] = '';
    return true;
  };
  return drop('NewSession.scene', 'scene') || drop('Quality.renderer', 'renderer');
}

// ---- frames --------------------------------------------------------------------------------

let frameTimes = [];
let bytesWindow = [];
let pendingFrame = null;  // the newest frame not yet drawn: a newer one replaces it
let decoding = false;
let lastFrameAt = 0;  // when the newest frame came (performance.now())
const kFrameError = 'A frame could not be shown: ';

// Decodes off the main thread and draws, newest frame first; never a queue.
async function present(blob) {
  pendingFrame = blob;
  if (decoding) return;
  decoding = true;
  while (pendingFrame) {
    const next = pendingFrame;
    pendingFrame = null;
    try {
      const image = await createImageBitmap(next);
      draw(image);
      image.close();
      if (page.status.textContent.startsWith(kFrameError)) say('');
    } catch (error) {
      say(kFrameError + error.message);
    }
  }
  decoding = false;
}

function showFrame(frame) {
  const now = performance.now();
  lastFrameAt = now;
  send({ ack: { sequence: frame.sequence, clientReceiveTimeUs: Math.round(Date.now() * 1000) } },
       false);
  for (const [id, at] of sentAt) {
    if (id > frame.inputEventId) continue;
    state.latencyMs.push(now - at);
    sentAt.delete(id);
  }
  if (state.latencyMs.length > 100) state.latencyMs.splice(0, state.latencyMs.length - 100);
  frameTimes.push(now);
  bytesWindow.push([now, frame.jpeg.length]);
  while (frameTimes.length && now - frameTimes[0] > 2000) frameTimes.shift();
  while (bytesWindow.length && now - bytesWindow[0][0] > 2000) bytesWindow.shift();
  state.fps = frameTimes.length / 2;
  state.bitrateKbps = bytesWindow.reduce((sum, entry) => sum + entry[1], 0) * 8 / 2 / 1000;
  state.frames++;
  state.lastFrame = {
    sequence: frame.sequence, simTime: frame.simTime, width: frame.width, height: frame.height,
    renderer: frame.renderer, quality: frame.jpegQuality, timings: frame.timings || {},
    simSpeed: frame.simSpeed || 0,
  };
  present(new Blob([frame.jpeg], { type: 'image/jpeg' }));
  updateStats();
}

// Where the frame lies in the canvas (letterboxed, aspect kept): for drawing and for touches.
function frameRect(width, height) {
  const cw = page.canvas.width, ch = page.canvas.height;
  const scale = Math.min(cw / width, ch / height);
  const w = width * scale, h = height * scale;
  return { x: (cw - w) / 2, y: (ch - h) / 2, w, h };
}

function draw(image) {
  const rect = frameRect(image.width, image.height);
  context.fillStyle = '#111';
  context.fillRect(0, 0, page.canvas.width, page.canvas.height);
  context.drawImage(image, rect.x, rect.y, rect.w, rect.h);
}

function percentile(values, p) {
  if (!values.length) return 0;
  const sorted = values.slice().sort((a, b) => a - b);
  return sorted[Math.min(sorted.length - 1, Math.floor(p * sorted.length))];
}

// Simulated seconds per wall second, as the server measures them: below 1 the GPU's share for
// this fluid cannot keep up, and it runs in slow motion while the frames keep their rate.
function simSpeedText(speed) {
  if (!speed) return 'paused';
  const text = `${speed.toFixed(2)}× real time`;
  return speed < 0.95 ? `${text} (slow motion)` : text;
}

function updateStats() {
  if (page.stats.hidden) return;
  const f = state.lastFrame || {};
  const t = f.timings || {};
  // "—" until a touch has come back in a frame.
  const latency = (p) => state.latencyMs.length ? `${percentile(state.latencyMs, p).toFixed(0)} ms`
                                                : '—';
  const lowered = wanted.adaptive && f.quality < (wanted.quality || kServerDefaultQuality)
    ? ' (lowered to keep up)' : '';
  const watching = state.access && !state.access.control ? '  watching (a view-only link)' : '';
  page.stats.textContent =
    `${state.fps.toFixed(1)} fps  ${state.bitrateKbps.toFixed(0)} kbit/s${watching}\n` +
    `touch→photon p50 ${latency(0.5)}, p95 ${latency(0.95)}\n` +
    `${f.width}×${f.height} ${f.renderer} q${f.quality}${lowered}  ` +
    `t=${(f.simTime || 0).toFixed(2)} s\n` +
    `simulation ${simSpeedText(f.simSpeed)}\n` +
    `server: sim ${(t.simMs || 0).toFixed(1)} queue ${(t.queueMs || 0).toFixed(1)} ` +
    `render ${(t.renderMs || 0).toFixed(1)} read-back ${(t.readbackMs || 0).toFixed(2)} ` +
    `encode ${(t.encodeMs || 0).toFixed(1)} ms`;
}

function showSession(session) {
  state.particles = session.particles;
  state.scene = session.scene;
  state.solver = session.solver;
  page.panel.querySelector('#scene').value = session.scene;
  showPaused(session.paused);
}

// The fluid paused or going, as the Pause button says.
function showPaused(value) {
  paused = value;
  page.panel.querySelector('#pause').textContent = paused ? 'Go on' : 'Pause';
}

// ---- handoff -------------------------------------------------------------------------------
// While it streams a session of at most kHandoffParticles (?handoff=N; the server's
// InputRules.max_state_particles at most; 0: never), the page keeps the session's newest state;
// when the connection drops it continues that fluid here within a frame or two, retries, and
// when the server is back hands the fluid back into the session it left (or, once the server no
// longer has that, a new one) and streams again.
const kHandoffParticles =
  query.has('handoff') ? Number(query.get('handoff')) || 0 : kMaxLocalParticles;
const kStateEveryMs = 250;
// One StateRequest at a time: requests held up by a stalled network would arrive together, past
// the server's 4 a second, and end the stream. One with no answer for this long (none comes when
// the session grew past what a state carries) is asked again.
const kStateAnswerWaitMs = 5000;
let stateAskedAt = 0;  // when the unanswered one went; 0: none
let newestState = null;  // the session's, while streaming
let stateTimer = 0;
// { mode, snapshot, since, cancelled } while the page simulates after a drop
let handoff = null;
let statsTimer = 0;

function askForStates() {
  clearInterval(stateTimer);
  newestState = null;
  state.streamed = null;
  stateAskedAt = 0;
  // A watcher does not hand the fluid back: that would start a copy of someone else's session.
  const mine = state.access && state.access.control;
  const most = mine ? Math.min(kHandoffParticles, state.rules ? state.rules.maxStateParticles : 0) : 0;
  if (!(state.particles > 0 && state.particles <= most) || typeof WebAssembly === 'undefined') return;
  LocalFluid.prepare();  // ready before it is needed
  stateTimer = setInterval(() => {
    const now = performance.now();
    if (stateAskedAt && now - stateAskedAt < kStateAnswerWaitMs) return;
    stateAskedAt = now;
    send({ stateRequest: {} }, false);
  }, kStateEveryMs);
}

async function startHandoff(snapshot) {
  const lastStreamed = lastFrameAt || performance.now();
  // The stream may come back (a resume) before the fluid here has started: endHandoff() then
  // cancels it, and it is stopped as soon as it exists.
  const starting = { mode: null, snapshot, since: performance.now(), cancelled: false };
  handoff = starting;
  const canvas = document.getElementById('local-view');
  canvas.hidden = false;
  fitLocalCanvas();
  let mode;
  try {
    mode = await LocalMode.startFrom(canvas, snapshot);
  } catch (error) {
    if (starting.cancelled) return;
    canvas.hidden = true;
    handoff = null;
    console.log('cannot continue here: ' + error.message);
    return;
  }
  if (starting.cancelled) {
    mode.stop();
    return;
  }
  starting.mode = mode;
  if (paused) mode.paused = true;  // as the session was when the stream dropped
  page.canvas.hidden = true;
  state.mode = 'local';
  state.local = mode.stats;
  state.handoffs++;
  state.handoffGapMs = performance.now() - lastStreamed;
  statsTimer = setInterval(showLocalStats, 500);
}

function endHandoff() {
  if (handoff.mode) handoff.mode.stop();
  else handoff.cancelled = true;
  document.getElementById('local-view').hidden = true;
  page.canvas.hidden = false;
  fitCanvas();  // it had no size while hidden
  clearInterval(statsTimer);
  state.mode = 'stream';
  state.local = null;
  handoff = null;
}

// ---- local mode ----------------------------------------------------------------------------

async function startLocal() {
  document.body.classList.add('local');
  page.canvas.hidden = true;
  const canvas = document.getElementById('local-view');
  canvas.hidden = false;
  fitLocalCanvas();
  say('Starting the fluid here…');
  try {
    local = await LocalMode.start(canvas, { scene: wanted.scene, solver: query.get('solver') || '',
                                            particles: wanted.particles,
                                            iterations: Number(query.get('iterations')) || 0 });
  } catch (error) {
    say('This browser cannot simulate the fluid here: ' + error.message);
    return;
  }
  state.mode = 'local';
  state.local = local.stats;
  fillScenes(local.scenes());
  page.panel.querySelector('#scene').value = local.stats.scene;
  setupControls();
  say('');
  keepAwake();  // tilting is playing too: no touch keeps the screen on
  statsTimer = setInterval(showLocalStats, 500);
}

function fitLocalCanvas() {
  const canvas = document.getElementById('local-view');
  const size = pixelSize(canvas);
  const drawing = local || (handoff && handoff.mode);
  if (drawing) {
    drawing.resize(size);  // it draws at a fraction of it while frames are slow
  } else {
    canvas.width = size.width;
    canvas.height = size.height;
  }
}

function showLocalStats() {
  if (page.stats.hidden) return;
  const s = state.local;
  const why = handoff
    ? `local: the network dropped ${((performance.now() - handoff.since) / 1000).toFixed(0)} s ` +
      `ago (gap ${state.handoffGapMs.toFixed(0)} ms); simulating here, retrying`
    : 'local: simulated in this page';
  page.stats.textContent =
    `${why}\n${s.fps.toFixed(1)} fps at ${s.resolution}  ${s.particles} particles ` +
    `(${s.scene.replace(/_/g, ' ')}, ${s.solver})\n` +
    `step ${s.stepMs.toFixed(1)} ms on ${s.threads} thread${s.threads > 1 ? 's' : ''}  ` +
    `simulation ${paused ? 'paused' : simSpeedText(s.speed)}`;
}

// Once every script of the page has run (controls.js after this one).
document.addEventListener('DOMContentLoaded', async () => {
  try {
    if (query.has('local')) {
      await startLocal();
      return;
    }
    fitCanvas();
    types = await loadProtocol();
    setupControls();
    connect();
  } catch (error) {
    say('The page cannot start: ' + error.message);
  }
});
