# Include views: how a layer's headers become visible to the layers above it and to nothing below.

# algray_include_view(TARGET NAME PATH) makes PATH (a folder or one header) includable as "NAME/..." by TARGET
# and by everything that links it, through a folder of symbolic links under the build tree that holds PATH
# alone. A target links only the layers below it, so a file that includes a header of a higher layer fails to
# compile ("algray/render/renderer.h: No such file or directory") instead of creating a cycle nobody sees.
function(algray_include_view target name path)
  set(root ${PROJECT_BINARY_DIR}/include_views/${target})
  get_filename_component(parent ${root}/${name} DIRECTORY)
  file(MAKE_DIRECTORY ${parent})
  if(NOT IS_SYMLINK ${root}/${name})
    file(CREATE_LINK ${path} ${root}/${name} SYMBOLIC)
  endif()
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "INTERFACE_LIBRARY")
    target_include_directories(${target} INTERFACE $<BUILD_INTERFACE:${root}>)
  else()
    target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${root}>)
  endif()
endfunction()
