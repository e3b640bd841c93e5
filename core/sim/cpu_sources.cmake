# The simulation's CPU part (scenes, parameters, the neighbour grid, the CPU solvers), relative to
# core/sim: in fluidcast_sim here, and compiled to WebAssembly for the page (client/wasm).
set(FLUIDCAST_SIM_CPU_SOURCES
  finger_collider.cpp
  fluid_constants.cpp
  fork_join_pool.cpp
  neighbour_grid.cpp
  neighbour_list.cpp
  param_error.cpp
  pbf_constants.cpp
  scene.cpp
  solver.cpp
  solver_params.cpp
  substeps.cpp
  statistics.cpp
  cpu/cpu_solver.cpp
  cpu/make_cpu_solver.cpp
  cpu/pbf_solver.cpp
  cpu/sph_solver.cpp)
