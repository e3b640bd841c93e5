// The sky, seen by the background pass and reflected by the water in the SSFR shading.
vec3 sky(vec3 direction) {
  return mix(vec3(0.55, 0.60, 0.66), vec3(0.18, 0.32, 0.55), clamp(direction.y * 1.5, 0.0, 1.0));
}
