// The solver's parameter block, written once per step into a device buffer; mirrored by SimParams
// in core/sim/gpu/gpu_sim_params.h, whose offsets are checked at compile time. Every pass of the
// solvers receives it, with the substep's timing, in its push constants (SimPass).
#define SOLVER_PBF 0u
#define SOLVER_SPH 1u
#define MAX_COLLIDERS 16

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SimParams {
  // Particle state in the order of the latest sort (w unused).
  Vec4s position;
  Vec4s velocity;
  Uints id;
  // The same, moved into this substep's sorted order (reorder.comp).
  Vec4s sorted_position;
  Vec4s sorted_velocity;
  Uints sorted_id;
  Vec4s predicted;     // PBF: predicted positions in state order (the sort key)
  Vec4s iterate;       // PBF: predicted positions in sorted order, corrected by each iteration
  Vec4s iterate_scalar;  // PBF: positions with, in w, what the next pass gathers beside them
                         //   (one load a neighbour): λ for the correction, |ω| for the confinement
  Vec4s vorticity;     // PBF: ω, and |ω| in w
  Vec2s density;       // SPH: density and pressure
  Vec4s acceleration;  // SPH
  Uints order;         // the grid: sorted slot → particle
  Uints cell_start;    // the grid: first sorted slot of each cell, and one past the last
  Uints sorted_cell;   // the grid: the cell each sorted slot was sorted into
  Uints cell_of;       // the grid: each particle's cell, from the count (PBF's prediction's)
  Uints rank;          // the grid: each particle's place in its cell, from the count
  Uints stats;         // [0] bits of the largest |v|², [1] of the largest |a|, [2..3] PBF: the
                       // compression summed, 64 bits in units of 2^-20, [4] PBF: bits of the
                       // largest wall approach (StatsSlot in gpu_sim_params.h)
  Floats density_ratio;  // ρ/ρ0 per particle in state order, from the last solver pass (render)
  Uvec4s neighbours;     // this substep's neighbours of sorted slot k, four to an element: entries
                         //   4g..4g + 3 at k + g · particle_count (sim_kernels.glsl, neighbour_group)
  Uints neighbour_count; //   below neighbour_count.v[k] (at most max_neighbours)

  vec4 wall_fluid_min; // the walls' fluid at rest lies outside this box: the tank grown by the
  vec4 wall_fluid_max; //   wall offset (FluidConstants::wall_offset)
  vec4 inner_min;      // the tank shrunk by a particle radius: where centres may be
  vec4 inner_max;
  vec4 gravity;
  ivec4 grid_dims;
  vec4 grid_origin;    // the grid: xyz its origin, w 1 / cell size

  uint solver;
  uint particle_count;
  uint collider_count;
  float h;
  float h2;
  float poly6;         // kernel constants, as in Kernels
  float spiky;
  float viscosity_laplacian;
  float mass;
  float rest_density;
  float inv_rest_density;
  float rest_volume;
  float particle_radius;
  float relaxation_epsilon;  // PBF: ε, scaled as the CPU solver does
  float scorr_scale;
  float inv_w_dq;
  float scorr_exponent;
  float vorticity_epsilon;
  float xsph;
  float tait_stiffness;      // SPH
  float tait_exponent;
  float sph_viscosity;
  float artificial_viscosity;  // 2 α h c, as the CPU solver's prefactor
  float softening;
  float substep_travel;  // PBF: most a particle moves in a substep, m (pbf_travel · h)
  uint max_candidates;   // neighbour candidates examined per particle (FluidConstants)
  float max_acceleration;  // PBF: most the corrections may accelerate a particle, m/s²
  uint max_neighbours;   // neighbours listed per particle, at most (FluidConstants)
  float wall_reach;      // PBF: how far ahead, s, a particle closing on a wall counts (wall_approach)
  float stiffness_share;  // PBF: the share of its corrections a step applies (stiffness_share)
  float pressed_from;     // PBF: from this compression up a particle's λ takes more, all of it
  float pressed_span;     // this much above it (particle_stiffness_share)
  float max_speed;        // m/s: kMaxSpeed, to which every particle is held (held_to_max_speed)

  vec4 collider_sphere[MAX_COLLIDERS];    // centre at the step's start, radius in w
  vec4 collider_velocity[MAX_COLLIDERS];
};

layout(push_constant, std430) uniform SimPass {
  SimParams params;
  float dt;              // this substep's length, s
  float time_into_step;  // where the colliders are: seconds into the step
  uint last_substep;        // PBF, a step's last substep: the sums pass (XSPH, the curl, the
                            // compression added up in P.stats.v[2..3]) and the finish run; on
                            // the others the last correction pass ends the substep
  float correction_weight;  // PBF correction pass: share of Δp applied (pbf_correction_weight)
  uint write_velocity;      // PBF correction pass: the last iteration's, which sets the velocity
} pass;

#define P pass.params
