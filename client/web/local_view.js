// Draws the page's local fluid with WebGL2 in the look of the server's Screen-Space Fluid
// Rendering, as far as a phone allows: each particle a sphere whose surface depth and thickness
// go to float targets, the depth smoothed by a bilateral filter whose radius is a length in the
// scene (so the surface looks the same near and far), then shaded — normals from the smoothed
// depth, Fresnel reflection of the sky, Beer–Lambert absorption by thickness, a specular
// highlight — over the tank's floor and walls, which are ray-cast as the server's are.
'use strict';

// An orbit camera as the server's (core/render/camera.h): yaw about +y from looking along −z,
// pitch above the horizon, a distance from the target; fitted so the whole tank is in view.
class LocalCamera {
  constructor() {
    this.yaw = 30; this.pitch = 20; this.distance = 2.5; this.target = [0.8, 0.2, 0.15];
    this.fov = 45;
  }

  eye() {
    const yaw = this.yaw * Math.PI / 180, pitch = this.pitch * Math.PI / 180;
    const back = [Math.sin(yaw) * Math.cos(pitch), Math.sin(pitch), Math.cos(yaw) * Math.cos(pitch)];
    return this.target.map((t, k) => t + this.distance * back[k]);
  }

  // The view's axes in the world: right, up, back (towards the eye).
  axes() {
    const eye = this.eye();
    const back = normalise(eye.map((e, k) => e - this.target[k]));
    const right = normalise(cross([0, 1, 0], back));
    return { right, up: cross(back, right), back, eye };
  }

  view() {
    const { right, up, back, eye } = this.axes();
    const t = (axis) => -dot(axis, eye);
    return [right[0], up[0], back[0], 0, right[1], up[1], back[1], 0,
            right[2], up[2], back[2], 0, t(right), t(up), t(back), 1];
  }

  projection(aspect) {
    const near = Math.max(0.01, 0.05 * this.distance), far = 20 * this.distance + 10;
    const f = 1 / Math.tan(this.fov * Math.PI / 360);
    return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) / (near - far), -1,
            0, 0, 2 * far * near / (near - far), 0];
  }

  // The whole tank in the frame at this aspect, with a margin (OrbitCamera::fit).
  fit(tank, aspect) {
    this.target = [0, 1, 2].map((k) => 0.5 * (tank[k] + tank[k + 3]));
    const tanY = Math.tan(this.fov * Math.PI / 360), tanX = tanY * aspect;
    this.distance = 1;
    const { right, up, back } = this.axes();
    let needed = 0;
    for (let corner = 0; corner < 8; corner++) {
      const p = [corner & 1 ? tank[3] : tank[0], corner & 2 ? tank[4] : tank[1],
                 corner & 4 ? tank[5] : tank[2]].map((v, k) => v - this.target[k]);
      const x = dot(p, right), y = dot(p, up), z = dot(p, back);
      needed = Math.max(needed, z + Math.abs(x) * 1.08 / tanX, z + Math.abs(y) * 1.08 / tanY);
    }
    this.distance = needed;
    this.clamp(tank);  // a sliver of a frame would need the camera kilometres back
  }

  // Outside the tank, within 16 of its radii, pitch 0 to 89° (orbit_limits).
  limits(tank) {
    const radius = 0.5 * Math.hypot(tank[3] - tank[0], tank[4] - tank[1], tank[5] - tank[2]);
    return { minDistance: 1.05 * radius, maxDistance: 16 * radius };
  }

  clamp(tank) {
    const { minDistance, maxDistance } = this.limits(tank);
    this.distance = Math.min(maxDistance, Math.max(minDistance, this.distance));
    this.pitch = Math.min(89, Math.max(0, this.pitch));
  }

  // The ray through a point of the frame, x and y from 0 to 1 (y down): origin and direction.
  ray(x, y, aspect) {
    const { right, up, back, eye } = this.axes();
    const tanY = Math.tan(this.fov * Math.PI / 360);
    const u = (2 * x - 1) * tanY * aspect, v = (1 - 2 * y) * tanY;
    return { origin: eye, direction: normalise([0, 1, 2].map((k) => u * right[k] + v * up[k] - back[k])) };
  }
}

function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
function cross(a, b) {
  return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
}
function normalise(a) { const l = Math.hypot(...a) || 1; return a.map((v) => v / l); }

// Each particle one point sprite as large as its sphere: one vertex a particle (instanced quads
// cost software WebGL ~40 µs an instance: 190 ms a frame at 5000 particles in headless Chromium).
const kPointVertex = `#version 300 es
in vec3 centre;
uniform mat4 view, projection;
uniform float radius, viewportHeight;
out vec3 centreView;
void main() {
  vec4 c = view * vec4(centre, 1.0);
  centreView = c.xyz;
  gl_Position = projection * c;
  gl_PointSize = radius * projection[1][1] * viewportHeight / -c.z;
}`;

// What both sphere passes share: the sphere's height over its point at this fragment (0 to 1, in
// radii, uv across the point), outside the disc discarded.
const kSphereFragment = `#version 300 es
precision highp float;
in vec3 centreView;
uniform mat4 projection;
uniform float radius;
vec2 uv;
float sphereHeight() {
  uv = vec2(gl_PointCoord.x * 2.0 - 1.0, 1.0 - gl_PointCoord.y * 2.0);
  float r2 = dot(uv, uv);
  if (r2 > 1.0) discard;
  return sqrt(1.0 - r2);
}
`;

// The sphere's front surface: its view-space depth, and the hardware depth for occlusion.
const kDepthFragment = kSphereFragment + `
out float depth;
void main() {
  float height = sphereHeight();
  vec3 p = centreView + vec3(uv, height) * radius;
  vec4 clip = projection * vec4(p, 1.0);
  gl_FragDepth = clip.z / clip.w * 0.5 + 0.5;
  depth = p.z;
}`;

// The sphere's chord, added up per pixel: how much water the pixel looks through.
const kThicknessFragment = kSphereFragment + `
out float thickness;
void main() { thickness = 2.0 * radius * sphereHeight(); }`;

const kFullScreenVertex = `#version 300 es
out vec2 screen;
void main() {
  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  screen = p * 0.5 + 0.5;
  gl_Position = vec4(p, 0.0, 1.0);
}`;

// One direction of the separable bilateral filter: a radius of `smoothing` metres at each pixel's
// depth, samples across a jump in depth of more than `range` ignored.
const kBlurFragment = `#version 300 es
precision highp float;
in vec2 screen;
uniform sampler2D depths;
uniform vec2 direction;
uniform float smoothing, range, focal;
out float depth;
void main() {
  ivec2 size = textureSize(depths, 0);
  ivec2 at = ivec2(screen * vec2(size));
  float z = texelFetch(depths, at, 0).r;
  if (z == 0.0) { depth = 0.0; return; }
  float pixels = min(24.0, smoothing * focal * float(size.y) * 0.5 / -z);
  float sigma = max(pixels * 0.5, 0.5);
  // The loop ends at the radius (a loop over all 49 places costs software WebGL every one of them),
  // takes both sides of the pixel at once, and has its Gaussian weights exp(−k²/2σ²) by recurrence,
  // without an exp a sample: 23 → 28 fps at 5000 particles in headless Chromium, same picture.
  float step = exp(-0.5 / (sigma * sigma)), ratio = step * step;
  float w = 1.0, sum = z, weights = 1.0;
  ivec2 along = ivec2(direction);
  int reach = int(pixels);
  for (int k = 1; k <= reach; ++k) {
    w *= step;
    step *= ratio;
    float a = texelFetch(depths, clamp(at + along * k, ivec2(0), size - 1), 0).r;
    float b = texelFetch(depths, clamp(at - along * k, ivec2(0), size - 1), 0).r;
    if (a != 0.0 && abs(a - z) <= range) { sum += a * w; weights += w; }
    if (b != 0.0 && abs(b - z) <= range) { sum += b * w; weights += w; }
  }
  depth = sum / weights;
}`;

// The scene behind the fluid ray-cast (sky, the floor's tiles, the tank's floor), and the fluid
// over it where the smoothed depth says there is some.
const kShadeFragment = `#version 300 es
precision highp float;
in vec2 screen;
uniform sampler2D depths, thicknesses;
uniform mat4 inverseView;
uniform vec2 tanHalf;
uniform vec3 tankMin, tankMax;
out vec4 colour;
const vec3 kLight = normalize(vec3(0.4, 1.0, 0.5));
vec3 sky(vec3 d) { return mix(vec3(0.62, 0.66, 0.72), vec3(0.28, 0.42, 0.62), clamp(d.y * 1.5, 0.0, 1.0)); }
vec3 scene(vec3 origin, vec3 d) {
  if (d.y >= -1e-4) return sky(d);
  vec3 p = origin + d * (-origin.y / d.y);
  bool inTank = all(greaterThanEqual(p.xz, tankMin.xz)) && all(lessThanEqual(p.xz, tankMax.xz));
  float tile = inTank ? 0.05 : 0.5;
  vec2 cell = floor(p.xz / tile);
  float checker = mod(cell.x + cell.y, 2.0);
  vec3 floorColour = inTank ? mix(vec3(0.55, 0.52, 0.47), vec3(0.9, 0.88, 0.84), checker)
                            : mix(vec3(0.25), vec3(0.33), checker);
  float haze = clamp(length(p - origin) / 40.0, 0.0, 1.0);
  return mix(floorColour, sky(vec3(d.x, 0.0, d.z)), haze);
}
vec3 viewPosition(vec2 s, float z) {
  return vec3((s * 2.0 - 1.0) * tanHalf * -z, z);
}
void main() {
  vec3 eye = (inverseView * vec4(0.0, 0.0, 0.0, 1.0)).xyz;
  vec3 rayView = normalize(vec3((screen * 2.0 - 1.0) * tanHalf, -1.0));
  vec3 ray = normalize(mat3(inverseView) * rayView);
  vec3 behind = scene(eye, ray);
  ivec2 size = textureSize(depths, 0);
  ivec2 at = ivec2(screen * vec2(size));
  float z = texelFetch(depths, at, 0).r;
  if (z == 0.0) { colour = vec4(behind, 1.0); return; }
  vec2 texel = 1.0 / vec2(size);
  vec3 p = viewPosition(screen, z);
  // Normals from the smaller of the two one-sided differences: no bleeding across silhouettes.
  vec3 dx, dy;
  float zr = texelFetch(depths, at + ivec2(1, 0), 0).r, zl = texelFetch(depths, at - ivec2(1, 0), 0).r;
  float zu = texelFetch(depths, at + ivec2(0, 1), 0).r, zd = texelFetch(depths, at - ivec2(0, 1), 0).r;
  vec3 pr = viewPosition(screen + vec2(texel.x, 0.0), zr), pl = viewPosition(screen - vec2(texel.x, 0.0), zl);
  vec3 pu = viewPosition(screen + vec2(0.0, texel.y), zu), pd = viewPosition(screen - vec2(0.0, texel.y), zd);
  dx = (zl == 0.0 || (zr != 0.0 && abs(zr - z) < abs(z - zl))) ? pr - p : p - pl;
  dy = (zd == 0.0 || (zu != 0.0 && abs(zu - z) < abs(z - zd))) ? pu - p : p - pd;
  vec3 normalView = normalize(cross(dx, dy));
  vec3 normal = normalize(mat3(inverseView) * normalView);
  vec3 toEye = -ray;
  float fresnel = 0.02 + 0.98 * pow(1.0 - max(dot(normal, toEye), 0.0), 5.0);
  float thickness = texelFetch(thicknesses, at, 0).r;
  vec3 absorbed = exp(-thickness * vec3(4.0, 1.6, 0.9));
  vec3 refracted = scene(eye, normalize(ray - 0.2 * normal)) * absorbed + vec3(0.02, 0.10, 0.16) * (1.0 - absorbed);
  vec3 reflected = sky(reflect(ray, normal));
  float specular = pow(max(dot(normal, normalize(kLight + toEye)), 0.0), 120.0);
  colour = vec4(mix(refracted, reflected, fresnel) + specular * 0.8, 1.0);
}`;

// The tank's twelve edges.
const kLineVertex = `#version 300 es
in vec3 position;
uniform mat4 view, projection;
void main() { gl_Position = projection * view * vec4(position, 1.0); }`;
const kLineFragment = `#version 300 es
precision mediump float;
out vec4 colour;
void main() { colour = vec4(0.85, 0.9, 0.95, 0.5); }`;

class LocalView {
  // Throws an Error saying what this browser lacks.
  constructor(canvas) {
    this.canvas = canvas;
    const gl = canvas.getContext('webgl2', { antialias: false, preserveDrawingBuffer: true });
    if (!gl) throw new Error('this browser has no WebGL2');
    if (!gl.getExtension('EXT_color_buffer_float')) {
      throw new Error('this browser cannot draw into float images (EXT_color_buffer_float)');
    }
    this.gl = gl;
    this.depthProgram = this.program(kPointVertex, kDepthFragment);
    this.thicknessProgram = this.program(kPointVertex, kThicknessFragment);
    this.blurProgram = this.program(kFullScreenVertex, kBlurFragment);
    this.shadeProgram = this.program(kFullScreenVertex, kShadeFragment);
    this.lineProgram = this.program(kLineVertex, kLineFragment);
    this.centres = gl.createBuffer();
    this.edges = gl.createBuffer();
    this.empty = gl.createVertexArray();  // the full-screen triangle needs no attributes
    this.size = [0, 0];
  }

  program(vertexSource, fragmentSource) {
    const gl = this.gl;
    const shader = (type, source) => {
      const s = gl.createShader(type);
      gl.shaderSource(s, source);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
      return s;
    };
    const p = gl.createProgram();
    const stages = [shader(gl.VERTEX_SHADER, vertexSource), shader(gl.FRAGMENT_SHADER, fragmentSource)];
    for (const stage of stages) gl.attachShader(p, stage);
    gl.linkProgram(p);
    // Attached, they go when the program goes.
    for (const stage of stages) gl.deleteShader(stage);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    const uniforms = {};
    for (let k = 0; k < gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS); k++) {
      const name = gl.getActiveUniform(p, k).name;
      uniforms[name] = gl.getUniformLocation(p, name);
    }
    return { program: p, uniforms,
             centre: gl.getAttribLocation(p, 'centre'), position: gl.getAttribLocation(p, 'position') };
  }

  // The float targets, made again when the canvas changes size.
  targets(width, height) {
    if (this.size[0] === width && this.size[1] === height) return;
    const gl = this.gl;
    const image = (format) => {
      const t = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, t);
      gl.texStorage2D(gl.TEXTURE_2D, 1, format, width, height);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
      return t;
    };
    const framebuffer = (texture, depth) => {
      const f = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, f);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, texture, 0);
      if (depth) {
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth);
      }
      return f;
    };
    this.releaseTargets();
    this.depthBuffer = gl.createRenderbuffer();
    gl.bindRenderbuffer(gl.RENDERBUFFER, this.depthBuffer);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, width, height);
    // Half-float thickness: WebGL2 blends it where it draws into it, unlike 32-bit floats.
    this.textures = [image(gl.R32F), image(gl.R32F), image(gl.R32F), image(gl.R16F)];
    this.framebuffers = [framebuffer(this.textures[0], this.depthBuffer),
                         framebuffer(this.textures[1]), framebuffer(this.textures[2]),
                         framebuffer(this.textures[3])];
    this.size = [width, height];
  }

  releaseTargets() {
    const gl = this.gl;
    for (const t of this.textures || []) gl.deleteTexture(t);
    for (const f of this.framebuffers || []) gl.deleteFramebuffer(f);
    if (this.depthBuffer) gl.deleteRenderbuffer(this.depthBuffer);
    this.textures = this.framebuffers = this.depthBuffer = null;
    this.size = [0, 0];
  }

  // Gives back every WebGL object it made: a canvas keeps one context for good, and each local
  // fluid (a handoff after each drop) draws on the same canvas with a view of its own.
  release() {
    const gl = this.gl;
    this.releaseTargets();
    for (const program of [this.depthProgram, this.thicknessProgram, this.blurProgram,
                           this.shadeProgram, this.lineProgram]) {
      gl.deleteProgram(program.program);
    }
    gl.deleteBuffer(this.centres);
    gl.deleteBuffer(this.edges);
    gl.deleteVertexArray(this.empty);
  }

  // Draws `count` particles (positions: x, y, z each, metres) of radius `radius` in `tank`
  // (min x, y, z, max x, y, z) seen by `camera`.
  draw(positions, count, radius, tank, camera) {
    const gl = this.gl;
    const width = this.canvas.width, height = this.canvas.height;
    this.targets(width, height);
    const aspect = width / height;
    const view = camera.view(), projection = camera.projection(aspect);
    gl.viewport(0, 0, width, height);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.centres);
    gl.bufferData(gl.ARRAY_BUFFER, positions.subarray(0, 3 * count), gl.STREAM_DRAW);
    this.drawSpheres(count, radius, view, projection, height);
    this.smoothDepth(radius, projection);
    this.shade(tank, camera, aspect);
    this.drawTank(tank, view, projection);
  }

  // The particles as spheres: the surface's depth (the nearest, by the depth test), then the
  // thickness (added up).
  drawSpheres(count, radius, view, projection, height) {
    const gl = this.gl;
    const spheres = (p) => {
      gl.useProgram(p.program);
      gl.uniformMatrix4fv(p.uniforms.view, false, view);
      gl.uniformMatrix4fv(p.uniforms.projection, false, projection);
      gl.uniform1f(p.uniforms.radius, radius);
      gl.uniform1f(p.uniforms.viewportHeight, height);
      gl.bindBuffer(gl.ARRAY_BUFFER, this.centres);
      gl.enableVertexAttribArray(p.centre);
      gl.vertexAttribPointer(p.centre, 3, gl.FLOAT, false, 0, 0);
      gl.drawArrays(gl.POINTS, 0, count);
      gl.disableVertexAttribArray(p.centre);
    };
    // Surface depth, nearest first by the depth test.
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffers[0]);
    gl.clearBufferfv(gl.COLOR, 0, [0, 0, 0, 0]);
    gl.clearBufferfv(gl.DEPTH, 0, [1]);
    gl.enable(gl.DEPTH_TEST);
    spheres(this.depthProgram);
    gl.disable(gl.DEPTH_TEST);
    // Thickness, added up.
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffers[3]);
    gl.clearBufferfv(gl.COLOR, 0, [0, 0, 0, 0]);
    gl.enable(gl.BLEND);
    gl.blendFunc(gl.ONE, gl.ONE);
    spheres(this.thicknessProgram);
    gl.disable(gl.BLEND);
  }

  // The depth smoothed across x, then y, twice: 5 particle radii, jumps over 6 radii kept.
  smoothDepth(radius, projection) {
    const gl = this.gl;
    gl.bindVertexArray(this.empty);
    const blur = this.blurProgram;
    gl.useProgram(blur.program);
    gl.uniform1f(blur.uniforms.smoothing, 5 * radius);
    gl.uniform1f(blur.uniforms.range, 6 * radius);
    gl.uniform1f(blur.uniforms.focal, projection[5]);
    gl.uniform1i(blur.uniforms.depths, 0);
    gl.activeTexture(gl.TEXTURE0);
    const passes = [[0, 1, [1, 0]], [1, 2, [0, 1]], [2, 1, [1, 0]], [1, 2, [0, 1]]];
    for (const [from, to, direction] of passes) {
      gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffers[to]);
      gl.bindTexture(gl.TEXTURE_2D, this.textures[from]);
      gl.uniform2fv(blur.uniforms.direction, direction);
      gl.drawArrays(gl.TRIANGLES, 0, 3);
    }
  }

  // Shading into the canvas, the scene behind the water ray-cast from `tank`.
  shade(tank, camera, aspect) {
    const gl = this.gl;
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    const shade = this.shadeProgram;
    gl.useProgram(shade.program);
    const { right, up, back, eye } = camera.axes();
    gl.uniformMatrix4fv(shade.uniforms.inverseView, false,
                        [...right, 0, ...up, 0, ...back, 0, ...eye, 1]);
    const tanY = Math.tan(camera.fov * Math.PI / 360);
    gl.uniform2fv(shade.uniforms.tanHalf, [tanY * aspect, tanY]);
    gl.uniform3fv(shade.uniforms.tankMin, tank.subarray(0, 3));
    gl.uniform3fv(shade.uniforms.tankMax, tank.subarray(3, 6));
    gl.uniform1i(shade.uniforms.depths, 0);
    gl.uniform1i(shade.uniforms.thicknesses, 1);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, this.textures[2]);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D, this.textures[3]);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindVertexArray(null);
  }

  // The tank's edges over it, uploaded when the tank changes.
  drawTank(tank, view, projection) {
    const gl = this.gl;
    const lines = this.lineProgram;
    gl.useProgram(lines.program);
    gl.uniformMatrix4fv(lines.uniforms.view, false, view);
    gl.uniformMatrix4fv(lines.uniforms.projection, false, projection);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.edges);
    if (this.edgesTank !== tank.join()) {
      const [x0, y0, z0, x1, y1, z1] = tank;
      const c = (i) => [i & 1 ? x1 : x0, i & 2 ? y1 : y0, i & 4 ? z1 : z0];
      const edges = [];
      for (let i = 0; i < 8; i++) {
        for (const bit of [1, 2, 4]) if (!(i & bit)) edges.push(...c(i), ...c(i | bit));
      }
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(edges), gl.STATIC_DRAW);
      this.edgesTank = tank.join();
    }
    gl.enableVertexAttribArray(lines.position);
    gl.vertexAttribPointer(lines.position, 3, gl.FLOAT, false, 0, 0);
    gl.enable(gl.BLEND);
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
    gl.drawArrays(gl.LINES, 0, 24);  // 12 edges
    gl.disable(gl.BLEND);
    gl.disableVertexAttribArray(lines.position);
  }
}
