# Turns files (OpenCL C kernels, the default scene) into a C++ source holding them as chunked raw string literals.

# algray_embed_files(FUNCTION OUTPUT_CPP FILES...) registers a custom command generating OUTPUT_CPP, which defines
# algray::FUNCTION() returning the files by name. Kernels stay plain .cl/.h files on disk, compiled by the
# OpenCL runtime, never stringified by macros.
function(algray_embed_files function output_cpp)
  add_custom_command(
    OUTPUT ${output_cpp}
    COMMAND ${CMAKE_COMMAND} -DOUTPUT=${output_cpp} -DFUNCTION=${function} "-DFILES=${ARGN}"
            -P ${PROJECT_SOURCE_DIR}/cmake/embed_files.cmake
    DEPENDS ${ARGN} ${PROJECT_SOURCE_DIR}/cmake/embed_files.cmake
    COMMENT "Embedding files for ${function}()"
    VERBATIM)
endfunction()
