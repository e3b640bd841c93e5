// Local mode: a fluid simulated in this page by the project's own solver (wasm/local_fluid.js, the
// server's CPU solvers in WebAssembly) and drawn by LocalView. One finger drags the fluid, two
// orbit and zoom, tilt turns gravity — as on a server's stream. No server is needed once the page
// is loaded; it also runs from a file or any static host.
'use strict';

// Particles the page simulates at most, and its default: a phone's one thread at 60 frames/s.
const kMaxLocalParticles = 8000;
const kDefaultLocalParticles = 3000;
// The most a frame spends stepping: beyond it the fluid runs in slow motion instead of the page
// missing its frames.
const kStepBudgetMs = 12;
// The drawing adapts its size to what a frame leaves it: when a frame spends more than
// kDrawingTooSlowMs outside the solver (drawing, the browser's compositing) it draws fewer pixels
// (down to a quarter of the screen's along each side, the browser scaling them up), under
// kDrawingRoomMs more again. Software WebGL on a CPU pays for every pixel; a phone's GPU stays at
// full size. (A slow solver is not helped by fewer pixels: it is not counted.)
const kDrawingTooSlowMs = 16, kDrawingRoomMs = 8, kMinRenderScale = 0.25;

// Threads the solver steps with: Web Workers share the module's memory only on a cross-origin
// isolated page (the server's pages are; a file is not); the threaded build takes at most its
// own limit (client/wasm). Two cores are left to the browser, which draws and composites on its own threads: on two cores
// shared with them (headless Chromium, software WebGL), two solver threads took a 1000-particle
// step from 2.5 ms to 36 ms, while under node, with the cores free, 2000 particles went from 5.8
// to 4.1 ms.
const kSolverCores = self.crossOriginIsolated ? Math.max(1, (navigator.hardwareConcurrency || 1) - 2) : 1;

// Loads the module (a classic script defining createLocalFluid) once: the threaded build where
// the page can use threads.
let localFluidModule = null;
function loadLocalFluid() {
  if (!localFluidModule) {
    const source = kSolverCores > 1 ? 'wasm/local_fluid_mt.js' : 'wasm/local_fluid.js';
    localFluidModule = new Promise((resolve, reject) => {
      const script = document.createElement('script');
      script.src = source;
      script.onload = () => createLocalFluid().then((module) => {
        module.threads = module._fluid_use_threads(kSolverCores);  // as many as the build has
        resolve(module);
      }, reject);
      script.onerror = () => reject(new Error('the page could not load ' + source));
      document.head.append(script);
    });
  }
  return localFluidModule;
}

// The mean of positions given as x, y, z, x, y, z… (m): the water's centre of mass.
function centreOfMass(positions) {
  const count = positions.length / 3;
  const centre = [0, 0, 0];
  for (let i = 0; i < positions.length; i++) centre[i % 3] += positions[i] / count;
  return centre;
}

class LocalMode {
  // Starts a fluid drawn on `canvas`; throws an Error saying what this browser lacks.
  static async start(canvas, { scene, solver, particles, iterations }) {
    const view = new LocalView(canvas);
    const mode = new LocalMode(canvas, view, await loadLocalFluid());
    if (iterations) mode.fluid._fluid_use_iterations(iterations);
    mode.create(scene || 'dam_break', solver || 'pbf', particles || kDefaultLocalParticles);
    mode.camera.fit(mode.tank(), canvas.width / canvas.height);
    mode.listen();
    mode.frame(performance.now());
    return mode;
  }

  // Continues a fluid from a state (a Snapshot as the server sent it, decoded by protobufjs).
  static async startFrom(canvas, snapshot) {
    const mode = new LocalMode(canvas, new LocalView(canvas), await loadLocalFluid());
    mode.load(snapshot);
    mode.camera.fit(mode.tank(), canvas.width / canvas.height);
    mode.listen();
    mode.frame(performance.now());
    return mode;
  }

  constructor(canvas, view, module) {
    this.canvas = canvas;
    this.view = view;
    this.fluid = module;
    this.camera = new LocalCamera();
    this.paused = false;
    this.pointers = new Map();  // the browser's pointer id → { id, x, y, at, world }
    // centre: the water's centre of mass (m), and time, its simulated clock (s), which the
    // browser test follows.
    this.stats = { fps: 0, stepMs: 0, speed: 1, particles: 0, scene: '', solver: '',
                   threads: module.threads, resolution: `${canvas.width}×${canvas.height}` };
    Object.defineProperties(this.stats, {  // read from the fluid when read, not every frame
      centre: { enumerable: true, get: () => this.centre() },
      time: { enumerable: true, get: () => this.fluid._fluid_time() },
    });
    this.frameTimes = [];
    this.simulated = [];  // [wall time, simulated seconds] over the last second
    this.last = 0;
    this.fullSize = { width: canvas.width, height: canvas.height };
    this.renderScale = 1;
    this.lastAdapted = 0;
    this.steppingMs = 0;  // spent stepping since the last adaptation
    this.framesSinceAdapted = 0;
  }

  // The size to draw at when the frame rate allows (device pixels, as the page fits them).
  resize(size) {
    this.fullSize = size;
    this.applyScale();
  }

  applyScale() {
    this.canvas.width = Math.max(1, Math.round(this.fullSize.width * this.renderScale));
    this.canvas.height = Math.max(1, Math.round(this.fullSize.height * this.renderScale));
    this.stats.resolution = `${this.canvas.width}×${this.canvas.height}`;
  }

  // Once a second: fewer pixels when drawing takes too long, more when there is room.
  adaptResolution(now) {
    this.framesSinceAdapted++;
    if (!this.lastAdapted) this.lastAdapted = now;
    if (now - this.lastAdapted < 1000) return;
    const frames = this.framesSinceAdapted;
    const drawingMs = (now - this.lastAdapted - this.steppingMs) / frames;
    this.lastAdapted = now;
    this.framesSinceAdapted = 0;
    this.steppingMs = 0;
    const before = this.renderScale;
    if (drawingMs > kDrawingTooSlowMs) {
      this.renderScale = Math.max(kMinRenderScale, this.renderScale * 0.75);
    } else if (drawingMs < kDrawingRoomMs) {
      this.renderScale = Math.min(1, this.renderScale * 1.25);
    }
    if (this.renderScale !== before) this.applyScale();
  }

  scenes() {
    return this.fluid.UTF8ToString(this.fluid._fluid_scene_names()).split(',');
  }

  // Makes a fluid; throws an Error with the solver's sentence when it cannot.
  create(scene, solver, particles) {
    const count = Math.min(kMaxLocalParticles, Math.max(1, particles));
    const error = this.fluid.ccall('fluid_create', 'string', ['string', 'string', 'number'],
                                   [scene, solver, count]);
    if (error) throw new Error(error);
    Object.assign(this.stats, { particles: count, scene, solver });
  }

  load(snapshot) {
    const count = snapshot.positions.length / 3;
    if (!(count >= 1 && count <= kMaxLocalParticles)) {
      throw new Error(`${count} particles are more than this page simulates (${kMaxLocalParticles})`);
    }
    const bytes = 4 * snapshot.positions.length;
    const positions = this.fluid._malloc(bytes), velocities = this.fluid._malloc(bytes);
    try {
      this.fluid.HEAPF32.set(snapshot.positions, positions / 4);
      this.fluid.HEAPF32.set(snapshot.velocities, velocities / 4);
      const error = this.fluid.ccall(
        'fluid_load', 'string', ['string', 'string', 'number', 'number', 'number', 'number', 'number'],
        [snapshot.scene, snapshot.solver, count, positions, velocities, count, snapshot.time]);
      if (error) throw new Error(error);
    } finally {
      this.fluid._free(positions);
      this.fluid._free(velocities);
    }
    const g = snapshot.gravity || { x: 0, y: -9.81, z: 0 };
    this.check(this.fluid._fluid_set_gravity(g.x || 0, g.y || 0, g.z || 0));
    Object.assign(this.stats, { particles: count, scene: snapshot.scene, solver: snapshot.solver });
  }

  // The fluid as a Snapshot (fluidcast.proto's fields), to hand back to a server.
  exportState() {
    const count = this.fluid._fluid_count();
    const floats = (pointer) => Array.from(new Float32Array(this.fluid.HEAPF32.buffer, pointer, 3 * count));
    const g = new Float32Array(this.fluid.HEAPF32.buffer, this.fluid._fluid_gravity(), 3);
    return { time: this.fluid._fluid_time(), gravity: { x: g[0], y: g[1], z: g[2] },
             scene: this.stats.scene, solver: this.stats.solver,
             positions: floats(this.fluid._fluid_positions()),
             velocities: floats(this.fluid._fluid_velocities()) };
  }

  // Stops simulating and drawing (the stream is back); touches on its canvas are ignored.
  stop() { this.stopped = true; }

  reset() { this.check(this.fluid._fluid_reset()); }
  resetView() { this.camera.fit(this.tank(), this.canvas.width / this.canvas.height); }

  check(error) {
    if (error) throw new Error(this.fluid.UTF8ToString(error));
  }

  tank() { return new Float32Array(this.fluid.HEAPF32.buffer, this.fluid._fluid_tank(), 6).slice(); }

  // Gravity measured in the screen's axes (x right, y up, z out of the screen), turned into the
  // world through the camera, as the server does.
  tilt(gravity) {
    const { right, up, back } = this.camera.axes();
    const g = [0, 1, 2].map((k) => gravity.x * right[k] + gravity.y * up[k] + gravity.z * back[k]);
    this.check(this.fluid._fluid_set_gravity(g[0], g[1], g[2]));
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
      this.pointers.set(event.pointerId, { id, ...at, at: performance.now(), world: null });
      this.liftFingersIfTwo();
    });
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
    });
    const up = (event) => {
      const pointer = this.pointers.get(event.pointerId);
      if (!pointer) return;
      this.check(this.fluid._fluid_lift_finger(pointer.id));
      this.pointers.delete(event.pointerId);
    };
    this.canvas.addEventListener('pointerup', up);
    this.canvas.addEventListener('pointercancel', up);
    this.canvas.addEventListener('contextmenu', (event) => event.preventDefault());
  }

  liftFingersIfTwo() {
    if (this.pointers.size < 2) return;
    for (const pointer of this.pointers.values()) this.check(this.fluid._fluid_lift_finger(pointer.id));
  }

  // One finger: a sphere that follows it through the water, with its speed in simulated time
  // (the solver moves it on at that speed until the next move; in slow motion a wall second is
  // less than a simulated one).
  drag(pointer, at) {
    const now = performance.now();
    const world = this.touchPoint(at.x, at.y);
    const seconds = Math.max(1e-3, (now - pointer.at) / 1000 * Math.max(0.05, this.stats.speed));
    const velocity = pointer.world
      ? world.map((w, k) => Math.max(-10, Math.min(10, (w - pointer.world[k]) / seconds)))
      : [0, 0, 0];
    const radius = Math.max(0.04, 4 * this.fluid._fluid_spacing());
    this.check(this.fluid._fluid_set_finger(pointer.id, ...world, ...velocity, radius));
    Object.assign(pointer, { at: now, world });
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
  }

  frame(now) {
    if (this.stopped) return;
    requestAnimationFrame((t) => this.frame(t));
    const wall = this.last ? Math.min(0.1, (now - this.last) / 1000) : 1 / 60;
    this.last = now;
    const stepping = performance.now();
    if (!this.paused) this.step(wall, now);
    this.steppingMs += performance.now() - stepping;
    this.adaptResolution(now);  // before drawing: a resized canvas is blank until drawn
    const count = this.fluid._fluid_count();
    const positions = new Float32Array(this.fluid.HEAPF32.buffer, this.fluid._fluid_positions(),
                                       3 * count);
    const radius = 0.5 * this.fluid._fluid_spacing();
    this.view.draw(positions, count, radius, this.tank(), this.camera);
    this.frameTimes.push(now);
    while (now - this.frameTimes[0] > 2000) this.frameTimes.shift();
    this.stats.fps = this.frameTimes.length / 2;
    this.stats.particles = count;
  }

  centre() {
    const count = this.fluid._fluid_count();
    return centreOfMass(new Float32Array(this.fluid.HEAPF32.buffer, this.fluid._fluid_positions(),
                                         3 * count));
  }

  // As many solver steps as the wall time asks, within the frame's budget: beyond it, slow motion.
  step(wall, now) {
    const dt = this.fluid._fluid_time_step();
    this.owed = Math.min((this.owed || 0) + wall, 4 * dt);
    const begun = performance.now();
    let steps = 0, simulated = 0;
    while (this.owed >= dt && performance.now() - begun < kStepBudgetMs) {
      this.check(this.fluid._fluid_step(dt));
      this.owed -= dt;
      simulated += dt;
      steps++;
    }
    if (performance.now() - begun >= kStepBudgetMs) this.owed = 0;  // what is left is not caught up
    if (steps) this.stats.stepMs = (performance.now() - begun) / steps;
    this.simulated.push([now, simulated, wall]);
    while (now - this.simulated[0][0] > 1000) this.simulated.shift();
    const totals = this.simulated.reduce((s, [, sim, w]) => [s[0] + sim, s[1] + w], [0, 0]);
    this.stats.speed = totals[1] > 0 ? totals[0] / totals[1] : 1;
  }
}
