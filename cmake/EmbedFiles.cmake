# Turns files (OpenCL C kernels, the default scene) into a C++ source holding them as chunked raw string literals.

# algray_embed_files(FUNCTION OUTPUT_CPP [BASE_DIR DIR] FILES...) registers a custom command generating OUTPUT_CPP,
# which defines algray::FUNCTION() returning the files by name: their paths under DIR, or without it their file
# names. Kernels stay plain .cl/.h files on disk, compiled by the OpenCL runtime, never stringified by macros.
function(algray_embed_files function output_cpp)
  cmake_parse_arguments(PARSE_ARGV 2 embed "" "BASE_DIR" "")
  set(files ${embed_UNPARSED_ARGUMENTS})
  add_custom_command(
    OUTPUT ${output_cpp}
    COMMAND ${CMAKE_COMMAND} -DOUTPUT=${output_cpp} -DFUNCTION=${function} "-DFILES=${files}"
            "-DBASE_DIR=${embed_BASE_DIR}" -P ${PROJECT_SOURCE_DIR}/cmake/embed_files.cmake
    DEPENDS ${files} ${PROJECT_SOURCE_DIR}/cmake/embed_files.cmake
    COMMENT "Embedding files for ${function}()"
    VERBATIM)
endfunction()
