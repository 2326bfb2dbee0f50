# Unity builds for the targets of many source files (the library layers, the command line, the reference solver):
# CMake compiles each target's files in batches, one translation unit per batch, so that the templates their
# headers instantiate (nlohmann/json, CLHPP, toml++, CLI11, the standard library) are compiled once per batch
# rather than once per file. Measured in clean builds on 2 cores (AMD EPYC, 2026-12-07): the Release tree with the
# tests 549 -> 413 CPU s (280 -> 212 s wall); the sanitizer tree's `algray_sanitize_tests algray_fuzzers`, clang
# -O0, 316 CPU s (167 s wall) with it.
# The files of a batch share one translation unit, anonymous namespaces included: a name a file keeps to itself
# must not be declared in another file of its target (the scene readers' token types are PovToken and SurfToken,
# and the expression parser's Token, for that reason). -DALGRAY_UNITY_BUILD=OFF compiles file by file, which also
# checks that each file includes what it uses.
option(ALGRAY_UNITY_BUILD "Compile the library layers and the command line in batches of files (faster builds)" ON)

# algray_unity_build(TARGETS...): each target compiles its files in batches, when ALGRAY_UNITY_BUILD is on.
function(algray_unity_build)
  if(ALGRAY_UNITY_BUILD)
    set_target_properties(${ARGN} PROPERTIES UNITY_BUILD ON)
  endif()
endfunction()
