# The library's layers, lowest first: one static library mcrewave_<layer> per folder
# of src/ (with its public headers in include/mcrewave/<layer>/). A layer uses only
# itself and the layers listed in MCREWAVE_LAYER_DEPS_<layer>; optim/ uses core/ alone,
# so that the optimisers know nothing of the MCRE.
if(CMAKE_SCRIPT_MODE_FILE)
  cmake_minimum_required(VERSION 3.18)
endif()

set(MCREWAVE_LAYERS core linalg data model optim mcre least_squares identification app)
set(MCREWAVE_LAYER_DEPS_core "")
set(MCREWAVE_LAYER_DEPS_linalg core)
set(MCREWAVE_LAYER_DEPS_data core)
set(MCREWAVE_LAYER_DEPS_model core linalg data)
set(MCREWAVE_LAYER_DEPS_optim core)
set(MCREWAVE_LAYER_DEPS_mcre core linalg data model optim)
set(MCREWAVE_LAYER_DEPS_least_squares core linalg data model optim mcre)
set(MCREWAVE_LAYER_DEPS_identification core linalg data model optim mcre least_squares)
set(MCREWAVE_LAYER_DEPS_app core linalg data model optim mcre least_squares identification)

# Fails with a message naming the file and the include when a source or header of a
# layer includes a header of a layer it may not use: "mcrewave/<folder>/..." (public
# headers) or "<folder>/..." (private headers of src/).
function(mcrewave_check_layers source_dir)
  foreach(layer ${MCREWAVE_LAYERS})
    file(GLOB files ${source_dir}/src/${layer}/* ${source_dir}/include/mcrewave/${layer}/*)
    set(allowed ${layer} ${MCREWAVE_LAYER_DEPS_${layer}})
    foreach(file ${files})
      file(STRINGS ${file} includes REGEX "^#include \"")
      foreach(line ${includes})
        if(line MATCHES "^#include \"(mcrewave/)?([a-z_]+)/")
          set(used ${CMAKE_MATCH_2})
          if(NOT used IN_LIST allowed)
            file(RELATIVE_PATH relative ${source_dir} ${file})
            string(REPLACE ";" ", " allowed_text "${allowed}")
            # NOTICE keeps the line whole (FATAL_ERROR wraps it); then stop.
            message(NOTICE "${relative}: ${line} reaches up from ${layer}/ to ${used}/; ${layer}/ "
                           "may include only ${allowed_text} (MCREWAVE_LAYER_DEPS_${layer})")
            message(FATAL_ERROR "An include crosses the layers of cmake/layers.cmake")
          endif()
        endif()
      endforeach()
    endforeach()
  endforeach()
endfunction()

# Script mode, run by every build and by ctest:
#   cmake -DMCREWAVE_SOURCE_DIR=<checkout> -P cmake/layers.cmake
if(CMAKE_SCRIPT_MODE_FILE)
  mcrewave_check_layers(${MCREWAVE_SOURCE_DIR})
endif()
