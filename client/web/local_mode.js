// Local mode: a fluid simulated in this page by the project's own solver (wasm/local_fluid.js, the
// server's CPU solvers in WebAssembly) on its own thread (local_worker.js) and drawn by LocalView
// on the page's. One finger drags the fluid, two
// orbit and zoom, tilt turns gravity — as on a server's stream. No server is needed once the page
// is loaded; it also runs from a file or any static host.
'use strict';

// Particles the page simulates at most, and its default: a phone's one thread at 60 frames/s.
const kMaxLocalParticles = 8000;
const kDefaultLocalParticles = 3000;
// The drawing adapts its size to what a frame costs: when the browser takes more than
// kDrawingTooSlowMs to come back after a drawn frame (drawing, compositing) it draws fewer pixels
// (down to a quarter of the screen's along each side, the browser scaling them up), under
// kDrawingRoomMs more again. Software WebGL on a CPU pays for every pixel; a phone's GPU stays at
// full size.
const kDrawingTooSlowMs = 16, kDrawingRoomMs = 8, kMinRenderScale = 0.25;

// Threads the solver steps with (its worker and the threaded build's pool): Web Workers share the
// module's memory only on a cross-origin isolated page (the server's pages are; a file is not);
// the threaded build takes at most its own limit (client/wasm). Two cores are left to the
// browser, which draws and composites on its own threads: on two cores shared with them
// (headless Chromium, software WebGL), two solver threads took a 1000-particle step from 2.5 ms
// to 36 ms, while under node, with the cores free, 2000 particles went from 5.8 to 4.1 ms.
const kSolverCores = self.crossOriginIsolated ? Math.max(1, (navigator.hardwareConcurrency || 1) - 2) : 1;

function loadScript(source) {
  return new Promise((resolve, reject) => {
    const script = document.createElement('script');
    script.src = source;
    script.onload = resolve;
    script.onerror = () => reject(new Error('the page could not load ' + source));
    document.head.append(script);
  });
}

// The mean of positions given as x, y, z, x, y, z… (m): the water's centre of mass.
function centreOfMass(positions) {
  const count = positions.length / 3;
  const centre = [0, 0, 0];
  for (let i = 0; i < positions.length; i++) centre[i % 3] += positions[i] / count;
  return centre;
}

// The solver, on its own thread (local_worker.js) where the page can start a worker, else on the
// page's; `newest` holds the newest positions it sent.
class LocalFluid {
  // A fluid thread made ready before it is needed (a handoff must start within a frame or two).
  static prepare() {
    if (!LocalFluid.spare) {
      LocalFluid.spare = LocalFluid.open();
      LocalFluid.spare.catch(() => { LocalFluid.spare = null; });
    }
  }

  static take() {
    const fluid = LocalFluid.spare || LocalFluid.open();
    LocalFluid.spare = null;
    return fluid;
  }

  // Throws an Error saying what this browser lacks.
  static async open() {
    if (typeof WebAssembly === 'undefined') throw new Error('this browser has no WebAssembly');
    const source = kSolverCores > 1 ? 'wasm/local_fluid_mt.js' : 'wasm/local_fluid.js';
    let worker = null;
    try {
      worker = new Worker('local_worker.js');
    } catch (error) {  // a page from a file may not start workers: the solver runs here
      return LocalFluid.onThisThread(source);
    }
    const ready = await new Promise((resolve, reject) => {
      worker.onmessage = ({ data }) => (data.ready ? resolve(data.ready)
        : reject(new Error('the page could not start its solver: ' + data.failed)));
      worker.onerror = (event) => reject(new Error('the page could not start its solver: ' +
                                                   (event.message || 'local_worker.js failed')));
      worker.postMessage({ source, threads: kSolverCores });
    });
    worker.onerror = null;
    return new LocalFluid(worker, () => worker.terminate(), ready);
  }

  static async onThisThread(source) {
    if (!LocalFluid.module) {
      LocalFluid.module = Promise.all([loadScript(source), loadScript('local_worker.js')])
        .then(() => createLocalFluid());
    }
    const module = await LocalFluid.module;
    const channel = new MessageChannel();
    runLocalFluid(channel.port2, module);
    const ready = { threads: module._fluid_use_threads(kSolverCores),
                    scenes: module.UTF8ToString(module._fluid_scene_names()) };
    const fluid = new LocalFluid(channel.port1, () => channel.port1.postMessage({ op: 'stop' }), ready);
    return fluid;
  }

  constructor(port, close, ready) {
    this.port = port;
    this.close = close;
    this.threads = ready.threads;
    this.scenes = ready.scenes.split(',');
    this.newest = null;  // { positions, particles, time, stepMs, speed }
    this.calls = new Map();  // id → { resolve, reject }
    this.nextCall = 1;
    this.frameWaiters = [];
    port.onmessage = ({ data }) => this.receive(data);
    port.postMessage({ op: 'more' });
  }

  // Asks the solver's thread; resolves with its answer, rejects with its sentence.
  call(op, fields = {}) {
    const id = this.nextCall++;
    return new Promise((resolve, reject) => {
      this.calls.set(id, { resolve, reject });
      this.port.postMessage({ op, id, ...fields });
    });
  }

  // The same, for inputs that a gesture sends many of: a failure is said on the console.
  tell(op, fields) {
    this.call(op, fields).catch((error) => console.warn(`local fluid, ${op}: ${error.message}`));
  }

  nextFrame() { return new Promise((resolve) => this.frameWaiters.push(resolve)); }

  receive(message) {
    if (message.frame) {
      this.newest = message.frame;
      this.port.postMessage({ op: 'more' });
      for (const resolve of this.frameWaiters.splice(0)) resolve(message.frame);
      return;
    }
    const call = this.calls.get(message.reply);
    if (!call) return;
    this.calls.delete(message.reply);
    if (message.error !== undefined) call.reject(new Error(message.error));
    else call.resolve(message.value);
  }
}

class LocalMode {
  // Starts a fluid drawn on `canvas`; throws an Error saying what this browser lacks or what the
  // solver refused.
  static async start(canvas, { scene, solver, particles, iterations }) {
    return LocalMode.started(canvas, async (mode) => {
      if (iterations) await mode.fluid.call('iterations', { iterations });
      await mode.create(scene || 'dam_break', solver || 'pbf', particles || kDefaultLocalParticles);
    });
  }

  // Continues a fluid from a state (a Snapshot as the server sent it, decoded by protobufjs).
  static async startFrom(canvas, snapshot) {
    return LocalMode.started(canvas, (mode) => mode.load(snapshot));
  }

  // A mode made ready by `prepare`; one that fails gives back its drawing's WebGL objects and its
  // solver's thread before the error goes on.
  static async started(canvas, prepare) {
    const view = new LocalView(canvas);
    let fluid = null;
    try {
      fluid = await LocalFluid.take();
      const mode = new LocalMode(canvas, view, fluid);
      await prepare(mode);
      return await mode.begin();
    } catch (error) {
      view.release();
      if (fluid) fluid.close();
      throw error;
    }
  }

  constructor(canvas, view, fluid) {
    this.canvas = canvas;
    this.view = view;
    this.fluid = fluid;
    this.shape = null;  // the fluid's { particles, tank, spacing }
    this.camera = new LocalCamera();
    this.pausedHere = false;
    this.pointers = new Map();  // the browser's pointer id → { id, x, y, at, world }
    // centre: the water's centre of mass (m), and time, its simulated clock (s), both of the
    // newest positions the solver sent; the browser test follows them.
    this.stats = { fps: 0, stepMs: 0, speed: 1, particles: 0, scene: '', solver: '',
                   threads: fluid.threads, resolution: `${canvas.width}×${canvas.height}` };
    Object.defineProperties(this.stats, {  // worked out when read, not every frame
      centre: { enumerable: true, get: () => this.fluid.newest && centreOfMass(this.fluid.newest.positions) },
      time: { enumerable: true, get: () => this.fluid.newest && this.fluid.newest.time },
    });
    this.frameTimes = [];  // when each new state of the fluid was drawn, over two seconds
    this.drawn = null;     // the positions last drawn
    this.viewChanged = true;
    this.fullSize = { width: canvas.width, height: canvas.height };
    this.renderScale = 1;
    this.lastAdapted = 0;
    this.drewAt = 0;
    this.afterDrawingMs = [];  // from a drawn frame to the browser's next, since the last adaptation
  }

  // Draws the fluid's first positions (the handoff's gap ends there), then every new state.
  async begin() {
    this.camera.fit(this.tank(), this.canvas.width / this.canvas.height);
    this.listen();
    // The worker sends a new fluid's first positions before it answers `create` or `load`.
    if (!this.fluid.newest) await this.fluid.nextFrame();
    this.frame(performance.now());
    return this;
  }

  get paused() { return this.pausedHere; }
  set paused(paused) {
    this.pausedHere = paused;
    this.fluid.tell('pause', { paused });
  }

  scenes() { return this.fluid.scenes; }

  // The size to draw at when the frame rate allows (device pixels, as the page fits them).
  resize(size) {
    this.fullSize = size;
    this.applyScale();
  }

  applyScale() {
    this.canvas.width = Math.max(1, Math.round(this.fullSize.width * this.renderScale));
    this.canvas.height = Math.max(1, Math.round(this.fullSize.height * this.renderScale));
    this.stats.resolution = `${this.canvas.width}×${this.canvas.height}`;
    this.viewChanged = true;
  }

  // Once a second: fewer pixels when drawing takes too long, more when there is room.
  adaptResolution(now) {
    if (!this.lastAdapted) this.lastAdapted = now;
    if (now - this.lastAdapted < 1000 || this.afterDrawingMs.length === 0) return;
    const drawingMs = this.afterDrawingMs.reduce((sum, ms) => sum + ms, 0) / this.afterDrawingMs.length;
    this.lastAdapted = now;
    this.afterDrawingMs = [];
    const before = this.renderScale;
    if (drawingMs > kDrawingTooSlowMs) {
      this.renderScale = Math.max(kMinRenderScale, this.renderScale * 0.75);
    } else if (drawingMs < kDrawingRoomMs) {
      this.renderScale = Math.min(1, this.renderScale * 1.25);
    }
    if (this.renderScale !== before) this.applyScale();
  }

  // Makes a fluid; rejects with the solver's sentence when it cannot.
  async create(scene, solver, particles) {
    const count = Math.min(kMaxLocalParticles, Math.max(1, particles));
    this.shape = await this.fluid.call('create', { scene, solver, particles: count });
    Object.assign(this.stats, { particles: count, scene, solver });
  }

  async load(snapshot) {
    const count = snapshot.positions.length / 3;
    if (!(count >= 1 && count <= kMaxLocalParticles)) {
      throw new Error(`${count} particles are more than this page simulates (${kMaxLocalParticles})`);
    }
    const g = snapshot.gravity || {};
    this.shape = await this.fluid.call('load', {
      scene: snapshot.scene, solver: snapshot.solver, time: snapshot.time,
      positions: Float32Array.from(snapshot.positions), velocities: Float32Array.from(snapshot.velocities),
      gravity: { x: g.x || 0, y: g.y === undefined ? -9.81 : g.y || 0, z: g.z || 0 } });
    Object.assign(this.stats, { particles: count, scene: snapshot.scene, solver: snapshot.solver });
  }

  // The fluid as a Snapshot (fluidcast.proto's fields), to hand back to a server.
  async exportState() {
    return { ...await this.fluid.call('export'), scene: this.stats.scene, solver: this.stats.solver };
  }

  // Stops simulating and drawing (the stream is back): its canvas's listeners and its drawing's
  // WebGL objects go with it, as the canvas serves the next local fluid.
  stop() {
    this.stopped = true;
    this.listening.abort();
    this.view.release();
    this.fluid.close();
  }

  reset() { return this.fluid.call('reset'); }
  resetView() {
    this.camera.fit(this.tank(), this.canvas.width / this.canvas.height);
    this.viewChanged = true;
  }

  tank() { return Float32Array.from(this.shape.tank); }

  // Gravity measured in the screen's axes (x right, y up, z out of the screen), turned into the
  // world through the camera, as the server does.
  tilt(gravity) {
    const { right, up, back } = this.camera.axes();
    const g = [0, 1, 2].map((k) => gravity.x * right[k] + gravity.y * up[k] + gravity.z * back[k]);
    this.fluid.tell('gravity', { x: g[0], y: g[1], z: g[2] });
  }

  // Where a finger at (x, y) of the frame (0 to 1) touches: on the tank's vertical mid-plane that
  // faces the camera most (across its depth, or across its length when seen from an end), kept
  // inside the tank.
  touchPoint(x, y) {
    const tank = this.tank();
    const { origin, direction } = this.camera.ray(x, y, this.canvas.width / this.canvas.height);
    const back = this.camera.axes().back;
    const axis = Math.abs(back[2]) >= Math.abs(back[0]) ? 2 : 0;
    const middle = 0.5 * (tank[axis] + tank[axis + 3]);
    const t = Math.abs(direction[axis]) > 1e-4 ? (middle - origin[axis]) / direction[axis] : 1;
    return [0, 1, 2].map((k) => Math.min(tank[k + 3], Math.max(tank[k], origin[k] + t * direction[k])));
  }

  listen() {
    this.listening = new AbortController();
    const options = { signal: this.listening.signal };
    const where = (event) => {
      const bounds = this.canvas.getBoundingClientRect();
      return { x: (event.clientX - bounds.left) / bounds.width,
               y: (event.clientY - bounds.top) / bounds.height };
    };
    this.canvas.addEventListener('pointerdown', (event) => {
      if (this.stopped) return;
      this.canvas.setPointerCapture(event.pointerId);
      const used = new Set([...this.pointers.values()].map((p) => p.id));
      let id = 0;
      while (used.has(id)) id++;
      const at = where(event);
      this.pointers.set(event.pointerId, { id, ...at });
      this.liftFingersIfTwo();
    }, options);
    this.canvas.addEventListener('pointermove', (event) => {
      const pointer = this.pointers.get(event.pointerId);
      if (!pointer) return;
      const at = where(event);
      if (this.pointers.size >= 2) {
        this.orbit(event.pointerId, at);
      } else {
        this.drag(pointer, at);
      }
      Object.assign(pointer, at);
    }, options);
    const up = (event) => {
      const pointer = this.pointers.get(event.pointerId);
      if (!pointer) return;
      // An up's own point is where the finger left the glass; a cancel's is not the hand's.
      if (event.type === 'pointerup' && this.pointers.size === 1) this.drag(pointer, where(event));
      this.fluid.tell('lift', { finger: pointer.id });
      this.pointers.delete(event.pointerId);
    };
    this.canvas.addEventListener('pointerup', up, options);
    this.canvas.addEventListener('pointercancel', up, options);
    this.canvas.addEventListener('contextmenu', (event) => event.preventDefault(), options);
  }

  liftFingersIfTwo() {
    if (this.pointers.size < 2) return;
    for (const pointer of this.pointers.values()) this.fluid.tell('lift', { finger: pointer.id });
  }

  // One finger: a sphere that follows it through the water, in simulated time no faster than
  // the hand moves (the solver's FingerCollider, as on the server).
  drag(pointer, at) {
    const world = this.touchPoint(at.x, at.y);
    const radius = Math.max(0.04, 4 * this.shape.spacing);
    this.fluid.tell('finger', { finger: pointer.id, at: world, radius });
  }

  // Two fingers: their mean movement orbits, their spread zooms.
  orbit(pointerId, at) {
    const [a, b] = [...this.pointers.entries()].slice(0, 2);
    if (!a || !b) return;
    const moved = a[0] === pointerId ? [a[1], b[1]] : [b[1], a[1]];
    const spreadBefore = Math.hypot(moved[0].x - moved[1].x, moved[0].y - moved[1].y);
    const spreadAfter = Math.hypot(at.x - moved[1].x, at.y - moved[1].y);
    this.camera.yaw -= (at.x - moved[0].x) * 90;
    this.camera.pitch += (at.y - moved[0].y) * 90;
    if (spreadBefore > 0.01 && spreadAfter > 0.01) this.camera.distance *= spreadBefore / spreadAfter;
    this.camera.clamp(this.tank());
    this.viewChanged = true;
  }

  // Each frame of the browser's: a new state of the fluid, or a new view of it, is drawn.
  frame(now) {
    if (this.stopped) return;
    requestAnimationFrame((t) => this.frame(t));
    if (this.drewAt) this.afterDrawingMs.push(now - this.drewAt);
    this.drewAt = 0;
    this.adaptResolution(now);  // before drawing: a resized canvas is blank until drawn
    const newest = this.fluid.newest;
    if (!newest || (newest === this.drawn && !this.viewChanged)) return;
    this.view.draw(newest.positions, newest.particles, 0.5 * this.shape.spacing, this.tank(),
                   this.camera);
    this.drewAt = now;
    this.viewChanged = false;
    if (newest !== this.drawn) {
      this.frameTimes.push(now);
      while (now - this.frameTimes[0] > 2000) this.frameTimes.shift();
    }
    this.drawn = newest;
    Object.assign(this.stats, { fps: this.frameTimes.length / 2, particles: newest.particles,
                                stepMs: newest.stepMs, speed: newest.speed });
  }
}
