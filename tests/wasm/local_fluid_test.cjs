// The page's local fluid (client/wasm, the project's CPU solvers in WebAssembly, with and without
// threads) under node: it runs a dam break as the native solver does (same code, so the same
// motion within rounding),
// keeps every particle in the tank, answers gravity and a finger, continues from a loaded state,
// and says what was wrong with bad input.
//   node tests/wasm/local_fluid_test.cjs WASM_DIR FLUIDCAST_SIM
'use strict';

const { execFileSync } = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');

const [wasmDir, nativeSim] = process.argv.slice(2).map((p) => path.resolve(p));
let failures = 0;
function check(ok, what) {
  console.log((ok ? 'ok   ' : 'FAIL ') + what);
  if (!ok) failures++;
}

// The fluid's state as the native CSV reports it: centre of mass and the largest speed.
function figures(module) {
  const n = module._fluid_count();
  const p = new Float32Array(module.HEAPF32.buffer, module._fluid_positions(), 3 * n);
  const v = new Float32Array(module.HEAPF32.buffer, module._fluid_velocities(), 3 * n);
  const tank = new Float32Array(module.HEAPF32.buffer, module._fluid_tank(), 6);
  let cx = 0, cy = 0, cz = 0, maxSpeed = 0, outside = 0;
  for (let i = 0; i < n; i++) {
    const [x, y, z] = [p[3 * i], p[3 * i + 1], p[3 * i + 2]];
    cx += x; cy += y; cz += z;
    maxSpeed = Math.max(maxSpeed, Math.hypot(v[3 * i], v[3 * i + 1], v[3 * i + 2]));
    if (!(x >= tank[0] && y >= tank[1] && z >= tank[2] && x <= tank[3] && y <= tank[4] &&
          z <= tank[5])) outside++;
  }
  return { n, com: [cx / n, cy / n, cz / n], maxSpeed, outside };
}

function run(module, seconds) {
  const dt = module._fluid_time_step();
  for (let t = 0; t < seconds - 1e-6; t += dt) {
    const error = module._fluid_step(dt, dt);  // in real time
    if (error) throw new Error(module.UTF8ToString(error));
  }
}

// ccall reads a null sentence (success) as ''.
function create(module, scene, solver, particles) {
  return module.ccall('fluid_create', 'string', ['string', 'string', 'number'],
                      [scene, solver, particles]) || null;
}

// The same dam break natively with `threads` threads (the fork-join split is deterministic per
// count): its last CSV row.
function nativeDamBreak(threads) {
  const work = fs.mkdtempSync(path.join(os.tmpdir(), 'fluidcast-wasm-'));
  const csv = path.join(work, 'dam.csv');
  execFileSync(nativeSim, ['--scene', 'dam_break', '--solver', 'pbf', '--particles', '2000',
                           '--until', '0.5', '--threads', String(threads), '--stats', csv]);
  const rows = fs.readFileSync(csv, 'utf8').trim().split('\n');
  const header = rows[0].split(',');
  fs.rmSync(work, { recursive: true, force: true });
  return Object.fromEntries(rows[rows.length - 1].split(',').map((v, k) => [header[k], Number(v)]));
}

// The build with threads (Web Workers; node's worker threads here) splits the work as the native
// solver does with as many threads, and moves the fluid the same way.
async function threaded() {
  const module = await require(path.join(wasmDir, 'local_fluid_mt.js'))();
  check(module._fluid_use_threads(2) === 2 && module._fluid_use_threads(64) === 4,
        'the threaded build takes 2 threads, and at most 4');
  module._fluid_use_threads(2);
  check(create(module, 'dam_break', 'pbf', 2000) === null, 'it makes the dam break');
  const begun = Date.now();
  run(module, 0.5);
  console.log(`with 2 threads: ${((Date.now() - begun) / 60).toFixed(2)} ms a step`);
  const native = nativeDamBreak(2);
  const centre = figures(module).com;
  const apart = Math.hypot(centre[0] - native.com_x, centre[1] - native.com_y, centre[2] - native.com_z);
  check(apart < 0.01, `with 2 threads it moves as the native solver does with 2 (${(apart * 1000).toFixed(2)} mm apart)`);
}

async function main() {
  const createLocalFluid = require(path.join(wasmDir, 'local_fluid.js'));
  const module = await createLocalFluid();

  const last = nativeDamBreak(1);

  check(create(module, 'dam_break', 'pbf', 2000) === null, 'a 2000-particle dam break is made');
  const start = figures(module);
  const begun = Date.now();
  run(module, 0.5);
  const msPerStep = (Date.now() - begun) / 60;
  const end = figures(module);
  console.log(`0.5 s of PBF at 2000 particles: ${msPerStep.toFixed(2)} ms a step (node, one thread)`);
  check(end.n === 2000 && end.outside === 0, `every particle stays in the tank (${end.outside} out)`);
  check(end.com[1] < start.com[1] - 0.05 && end.com[0] > start.com[0] + 0.05,
        `the column falls and spreads (centre ${start.com.map((c) => c.toFixed(3))} → ` +
        `${end.com.map((c) => c.toFixed(3))})`);
  const native = [last.com_x, last.com_y, last.com_z];
  const apart = Math.hypot(...end.com.map((c, k) => c - native[k]));
  check(Math.abs(module._fluid_time() - last.t) < 1e-6 && apart < 0.01,
        `it moves as the native solver does: centres ${(apart * 1000).toFixed(2)} mm apart at ` +
        `t = ${last.t} s (native ${native.map((c) => c.toFixed(4))})`);

  // Tilted: gravity along +x carries the water that way.
  check(module._fluid_set_gravity(9.81, 0, 0) === 0, 'gravity along +x is taken');
  const beforeTilt = figures(module).com[0];
  run(module, 0.3);
  check(figures(module).com[0] > beforeTilt + 0.02,
        `tilted gravity moves the water along x (${beforeTilt.toFixed(3)} → ` +
        `${figures(module).com[0].toFixed(3)})`);
  module._fluid_set_gravity(0, -9.81, 0);

  // A finger swept through a pool (3 m/s) stirs it: the same 0.2 s from the same start, with it
  // and without.
  const kinetic = () => {
    const n = module._fluid_count();
    const v = new Float32Array(module.HEAPF32.buffer, module._fluid_velocities(), 3 * n);
    return v.reduce((sum, c) => sum + c * c, 0) / n;
  };
  // `slowdown`: wall seconds a simulated one (slow motion: the hand moves the same in wall time);
  // `reach`: how far the hand moves.
  const sweep = (finger, slowdown = 1, reach = 0.6) => {
    if (create(module, 'pool', 'pbf', 2000) !== null) throw new Error('pool');
    run(module, 0.2);
    const dt = 1 / 120;
    for (let k = 0; k < 24; k++) {
      const x = 0.05 + reach * k / 24;
      if (finger && module._fluid_set_finger(0, x, 0.1, 0.15, 0.06) !== 0) throw new Error('finger');
      const error = module._fluid_step(dt, slowdown * dt);
      if (error) throw new Error(module.UTF8ToString(error));
    }
    return kinetic();
  };
  const unstirred = sweep(false), stirred = sweep(true);
  const held = sweep(true, 1, 0), slowly = sweep(true, 10);
  check(stirred > 10 * unstirred,
        `a finger stirs the fluid (mean v² ${unstirred.toFixed(4)} → ${stirred.toFixed(4)} m²/s²)`);
  // Its sphere grows in (FingerCollider::kGrowSeconds): appearing whole in the water it threw out
  // what it displaced, a splash of a quarter of the sweep's (mean v² 0.038 held still).
  check(held - unstirred < 0.1 * (stirred - unstirred),
        `a finger put down and held stirs little (mean v² ${held.toFixed(4)})`);
  // At a tenth of real time the sphere moves at the hand's 3 m/s of wall time, 0.3 m/s simulated:
  // it stirs little more than a finger held still.
  check(slowly - held < 0.2 * (stirred - held),
        `in slow motion the finger is slow too (mean v² ${slowly.toFixed(4)} at a tenth of real ` +
        `time, ${held.toFixed(4)} held still)`);
  check(module._fluid_lift_finger(0) === 0, 'the finger lifts');
  // Lifted in slow motion, its sphere (6 cm along a 60 cm stroke) goes on to where the finger
  // was: half a second later the pool is stirred as much as at the lift (dropped at the lift, it
  // had calmed to a seventh).
  for (let k = 0; k < 60; k++) {
    const error = module._fluid_step(1 / 120, 10 / 120);
    if (error) throw new Error(module.UTF8ToString(error));
  }
  check(kinetic() > 0.5 * slowly,
        `a lifted finger's sphere finishes the stroke (mean v² ${kinetic().toFixed(4)} 0.5 s on)`);
  // Between steps (slow motion, a pause) the page waits; a finger that moved meanwhile pushes only
  // at the next step, and in slow motion its sphere moves no faster than the hand did.
  const before = module._fluid_time();
  check(module._fluid_set_finger(1, 0.1, 0.1, 0.15, 0.06) === 0 && module._fluid_wait(0.05) === 0 &&
        module._fluid_set_finger(1, 0.2, 0.1, 0.15, 0.06) === 0 && module._fluid_wait(0.05) === 0 &&
        module._fluid_time() === before, 'waiting does not step');
  check(module._fluid_step(1 / 120, 0.1) === 0 && module._fluid_time() > before,
        'a step in slow motion (more wall time than simulated)');
  module._fluid_lift_finger(1);
  check(create(module, 'dam_break', 'pbf', 2000) === null, 'the dam break again');
  run(module, 0.4);

  // Continued from a state (as from a server's snapshot): same particles, same clock.
  const n = module._fluid_count();
  const bytes = 12 * n;
  const positions = module._malloc(bytes), velocities = module._malloc(bytes);
  module.HEAPU8.copyWithin(positions, module._fluid_positions(), module._fluid_positions() + bytes);
  module.HEAPU8.copyWithin(velocities, module._fluid_velocities(), module._fluid_velocities() + bytes);
  const time = module._fluid_time();
  const centre = figures(module).com;
  const load = (gravity, {count = n, at = time, from = positions, moving = velocities} = {}) =>
    module.ccall('fluid_load', 'string',
      ['string', 'string', 'number', 'number', 'number', 'number', 'number', 'number', 'number',
        'number'],
      ['dam_break', 'pbf', 2000, from, moving, count, at, ...gravity]) || null;
  const refused = load([0, -3000, 0]);
  check(refused !== null && refused.includes('gravity') && module._fluid_count() === n,
        `a state under too strong a gravity is refused, the fluid kept: "${refused}"`);
  // What a state may not be, each refused with the fluid kept as it was (its clock too).
  const fast = module._malloc(bytes), heaped = module._malloc(bytes);
  module.HEAPU8.copyWithin(fast, velocities, velocities + bytes);
  module.HEAPF32[fast / 4] = 1e36;  // SPH's viscosity made it NaN
  for (let k = 0; k < 3 * n; ++k) module.HEAPF32[heaped / 4 + k] = module.HEAPF32[positions / 4 + k % 3];
  const clock = module._fluid_time();
  for (const [what, error, word] of [
    ['a count other than the scene\'s', load([0, -9.81, 0], {count: n - 1}), 'particles given'],
    ['a negative time', load([0, -9.81, 0], {at: -1}), 'time'],
    ['a velocity past the limit', load([0, -9.81, 0], {moving: fast}), 'velocity'],
    ['every particle in one place', load([0, -9.81, 0], {from: heaped}), 'rest density']]) {
    check(error !== null && error.includes(word) && module._fluid_count() === n &&
          module._fluid_time() === clock, `${what} is refused, the fluid kept: "${error}"`);
  }
  module._free(fast);
  module._free(heaped);
  const loaded = load([3, -9, 0]);
  module._free(positions);
  module._free(velocities);
  const g = new Float32Array(module.HEAPF32.buffer, module._fluid_gravity(), 3);
  check(loaded === null && module._fluid_count() === n && module._fluid_time() === time &&
        Math.hypot(...figures(module).com.map((c, k) => c - centre[k])) < 1e-6,
        `a loaded state goes on where it was (t = ${time.toFixed(3)} s, ${n} particles)`);
  check(g[0] === 3 && g[1] === -9 && g[2] === 0, `a loaded state falls under its gravity: ${[...g]}`);
  // Reset goes back to the scene's start, not to the state it was loaded from.
  module._fluid_reset();
  check(module._fluid_time() === 0 &&
        Math.hypot(...figures(module).com.map((c, k) => c - start.com[k])) < 1e-6,
        'reset after a load starts the scene again');

  // Bad input: a sentence naming it, and the fluid as it was.
  const unknown = create(module, 'lake', 'pbf', 100);
  check(unknown !== null && unknown.includes('lake') && unknown.includes('dam_break'),
        `an unknown scene is named, with the known ones: "${unknown}"`);
  const said = (error) => (error ? module.UTF8ToString(error) : '');
  for (const [what, call, word] of [
    ['a finger id of 16', () => module._fluid_set_finger(16, 0.1, 0.1, 0.1, 0.05), 'id'],
    ['a finger not at a number', () => module._fluid_set_finger(0, NaN, 0.1, 0.1, 0.05), 'finite'],
    ['a finger of radius 0', () => module._fluid_set_finger(0, 0.1, 0.1, 0.1, 0), 'radius'],
    ['a step of no time', () => module._fluid_step(0, 0.01), 'seconds'],
    ['a step after negative wall time', () => module._fluid_step(0.005, -1), 'wall_seconds'],
    ['a wait of wall time that is not a number', () => module._fluid_wait(NaN), 'wall_seconds']]) {
    const error = said(call());  // the sentence lasts until the next call
    check(error.includes(word) && module._fluid_count() === n, `${what} is refused: "${error}"`);
  }
  const badGravity = module._fluid_set_gravity(NaN, 0, 0);
  check(badGravity !== 0 && module._fluid_count() === n,
        `gravity that is not finite is refused: "${module.UTF8ToString(badGravity)}"`);
  check(create(module, 'pool', 'sph', 1000) === null && module._fluid_count() === 1000,
        'SPH runs too');
  run(module, 0.1);
  check(figures(module).outside === 0, 'SPH keeps its particles in the tank');

  await threaded();
  if (failures) process.exit(1);
  console.log('the local fluid behaves');
  process.exit(0);  // the threaded build's workers would keep node running
}

main().catch((e) => { console.error(e); process.exit(1); });
