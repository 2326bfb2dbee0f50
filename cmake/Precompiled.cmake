# Precompiled headers for the groups of many translation units that include the same heavy headers: the larger
# library layers (CLHPP, nlohmann/json, GLM, gmpxx reach most of their files through their headers) and the Catch2
# tests (every one includes catch.hpp, most also the core's headers). Each header is parsed once per group
# instead of once per file. Measured in clean 2-core builds (CPU time of the compiles): the clang -O0 sanitizer
# tree 109 -> 85 s, where parsing is most of a compile; the GCC -O3 Release tree 256 -> 241 s, where code
# generation is (GCC's precompiled headers also take 5-7 s each to write).
# Only headers from outside the project go in, and no source defines a macro before its first include, so a
# precompiled header only adds those headers' declarations ahead of a file's own includes. -DALGRAY_PCH=OFF
# builds without them, which checks that every file includes what it uses.
option(ALGRAY_PCH "Precompiled headers for the library layers and the tests (faster builds)" ON)

set(ALGRAY_PCH_COMMON_HEADERS
    <algorithm> <array> <chrono> <cmath> <cstdint> <cstdio> <cstdlib> <filesystem> <fstream> <functional> <limits>
    <map> <memory> <optional> <set> <sstream> <stdexcept> <string> <vector>
    <CL/opencl.hpp> <nlohmann/json.hpp> <glm/glm.hpp> <gmpxx.h>)

# algray_pch(TARGET HEADERS...): TARGET precompiles ALGRAY_PCH_COMMON_HEADERS and HEADERS, when ALGRAY_PCH is on.
function(algray_pch target)
  if(ALGRAY_PCH)
    target_precompile_headers(${target} PRIVATE ${ALGRAY_PCH_COMMON_HEADERS} ${ARGN})
  endif()
endfunction()

# algray_pch_reuse(TARGET FROM): TARGET compiles with FROM's precompiled header (same flags and definitions).
function(algray_pch_reuse target from)
  if(ALGRAY_PCH)
    set_target_properties(${target} PROPERTIES PRECOMPILE_HEADERS_REUSE_FROM ${from})
  endif()
endfunction()
