// The local fluid's own thread: the project's solver in WebAssembly (wasm/local_fluid.js) steps
// here, in real time where it can and in slow motion where it cannot, while the page's thread only
// draws. The page asks for positions and gets the newest once a step has made them (one answer in
// flight at most: nothing queues when either side is slow).
//
// In a Web Worker this script runs itself. A page opened from a file cannot start workers, so it
// runs runLocalFluid on its own thread through a MessageChannel: the same messages either way.
//
// Messages from the page: { op, id, ... }, each answered { reply: id, value } or
// { reply: id, error: 'a sentence' }. Sent unasked, once asked for with { op: 'more' }:
// { frame: { positions (Float32Array, transferred), particles, time, stepMs, speed } }.
'use strict';

// Serves one page on `port` with `fluid`, a created module.
function runLocalFluid(port, fluid) {
  let created = false, paused = false;
  let wanted = false, fresh = false;  // the page asked for positions; a step made new ones
  let owed = 0, last = 0;             // simulated seconds the wall clock asks for; its last reading
  let stepMs = 0;
  let simulated = [];                 // [wall time, simulated s, wall s] over the last second
  let ticking = false;

  const check = (error) => {
    if (error) throw new Error(fluid.UTF8ToString(error));
  };
  const floats = (pointer, count) => new Float32Array(fluid.HEAPF32.buffer, pointer, count).slice();
  const described = () => ({
    particles: fluid._fluid_count(), tank: Array.from(floats(fluid._fluid_tank(), 6)),
    spacing: fluid._fluid_spacing(),
  });

  // A task per step, so that the page's messages are handled between steps.
  const next = new MessageChannel();
  next.port1.onmessage = () => tick();
  const tickSoon = (ms) => {
    if (ticking) return;
    ticking = true;
    const go = () => { ticking = false; next.port2.postMessage(0); };
    if (ms > 0) setTimeout(go, ms); else go();
  };

  function tick() {
    if (!created) return;
    const now = performance.now();
    const elapsed = last ? (now - last) / 1000 : 0;  // the fingers' spheres see all of it
    const wall = Math.min(0.1, elapsed);
    last = now;
    const dt = fluid._fluid_time_step();
    let stepped = 0;
    if (!paused) {
      owed = Math.min(owed + wall, 4 * dt);  // beyond that, slow motion rather than catching up
      if (owed >= dt) {
        check(fluid._fluid_step(dt, elapsed));
        stepMs = performance.now() - now;
        owed -= dt;
        stepped = dt;
        fresh = true;
      }
    }
    if (!stepped) check(fluid._fluid_wait(elapsed));
    simulated.push([now, stepped, wall]);
    while (now - simulated[0][0] > 1000) simulated.shift();
    send();
    tickSoon(paused || owed >= dt ? (paused ? 50 : 0) : 1000 * (dt - owed));
  }

  function send() {
    if (!wanted || !fresh) return;
    const totals = simulated.reduce((s, [, sim, w]) => [s[0] + sim, s[1] + w], [0, 0]);
    const positions = floats(fluid._fluid_positions(), 3 * fluid._fluid_count());
    port.postMessage({ frame: { positions, particles: positions.length / 3, time: fluid._fluid_time(),
                                stepMs, speed: totals[1] > 0 ? totals[0] / totals[1] : 1 } },
                     [positions.buffer]);
    wanted = fresh = false;
  }

  const started = () => {
    created = true;
    fresh = true;  // the new fluid's first positions, before any step
    owed = 0;
    last = 0;
    simulated = [];
    send();
    tickSoon(0);
    return described();
  };

  const ops = {
    more: () => { wanted = true; send(); },
    stop: () => { created = false; },  // a solver on the page's thread, no longer needed
    iterations: ({ iterations }) => fluid._fluid_use_iterations(iterations),
    create: ({ scene, solver, particles }) => {
      const error = fluid.ccall('fluid_create', 'string', ['string', 'string', 'number'],
                                [scene, solver, particles]);
      if (error) throw new Error(error);
      return started();
    },
    load: ({ scene, solver, positions, velocities, time, gravity }) => {
      const count = positions.length / 3;
      const bytes = 4 * positions.length;
      const p = fluid._malloc(bytes), v = fluid._malloc(bytes);
      try {
        fluid.HEAPF32.set(positions, p / 4);
        fluid.HEAPF32.set(velocities, v / 4);
        // Built under the state's gravity, so that PBF's substeps start from its weight along it.
        const error = fluid.ccall('fluid_load', 'string',
          ['string', 'string', 'number', 'number', 'number', 'number', 'number', 'number', 'number',
            'number'],
          [scene, solver, count, p, v, count, time, gravity.x, gravity.y, gravity.z]);
        if (error) throw new Error(error);
      } finally {
        fluid._free(p);
        fluid._free(v);
      }
      return started();
    },
    reset: () => { check(fluid._fluid_reset()); fresh = true; send(); },
    pause: ({ paused: now }) => { paused = now; last = 0; },
    gravity: ({ x, y, z }) => check(fluid._fluid_set_gravity(x, y, z)),
    finger: ({ finger, at, radius }) => check(fluid._fluid_set_finger(finger, ...at, radius)),
    lift: ({ finger }) => check(fluid._fluid_lift_finger(finger)),
    // The fluid as a Snapshot (fluidcast.proto's fields, less scene and solver, which the page
    // knows), to hand back to a server.
    export: () => {
      const count = 3 * fluid._fluid_count();
      const g = floats(fluid._fluid_gravity(), 3);
      return { time: fluid._fluid_time(), gravity: { x: g[0], y: g[1], z: g[2] },
               positions: Array.from(floats(fluid._fluid_positions(), count)),
               velocities: Array.from(floats(fluid._fluid_velocities(), count)) };
    },
  };

  port.onmessage = ({ data }) => {
    const { op, id } = data;
    try {
      if (!ops[op]) throw new Error(`no such request: ${op}`);
      const value = ops[op](data);
      if (id) port.postMessage({ reply: id, value });
    } catch (error) {
      if (id) port.postMessage({ reply: id, error: error.message });
    }
  };
}

// Run as a Web Worker: the first message names the build to load and the threads to use.
if (typeof document === 'undefined' && typeof importScripts === 'function') {
  self.onmessage = async ({ data: { source, threads } }) => {
    self.onmessage = null;
    try {
      importScripts(source);
      const url = new URL(source, self.location.href).href;
      const fluid = await createLocalFluid({
        // The threaded build's own workers load from where the build is, not from here.
        locateFile: (file) => new URL(file, url).href, mainScriptUrlOrBlob: url });
      const used = fluid._fluid_use_threads(threads);
      runLocalFluid(self, fluid);
      self.postMessage({ ready: { threads: used, scenes: fluid.UTF8ToString(fluid._fluid_scene_names()) } });
    } catch (error) {
      self.postMessage({ failed: error.message || String(error) });
    }
  };
}
