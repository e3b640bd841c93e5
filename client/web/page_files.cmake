# The page as the server serves it, each file relative to the page's folder (FLUIDCAST_WEB_DIR):
# client/CMakeLists.txt stages them there, and the server routes exactly these (index.html at /
# too). Included by both.
# From client/web:
set(FLUIDCAST_PAGE_SOURCES index.html app.js controls.js local_mode.js local_view.js local_worker.js style.css
  manifest.webmanifest)
# Built by Emscripten (client/wasm), served from wasm/:
set(FLUIDCAST_PAGE_WASM local_fluid.js local_fluid_mt.js local_fluid_mt.worker.js)
set(FLUIDCAST_PAGE_FILES ${FLUIDCAST_PAGE_SOURCES} fluidcast.proto vendor/protobuf.min.js)
foreach(file ${FLUIDCAST_PAGE_WASM})
  list(APPEND FLUIDCAST_PAGE_FILES wasm/${file})
endforeach()
