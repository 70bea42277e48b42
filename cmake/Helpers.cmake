# gis_add_library(NAME SOURCES ... DEPS ...): one static library per server layer.
function(gis_add_library name)
    cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
    add_library(gis_${name} STATIC ${ARG_SOURCES})
    add_library(gis::${name} ALIAS gis_${name})
    target_include_directories(gis_${name} PUBLIC ${GIS_SOURCE_ROOT}/server ${GIS_SOURCE_ROOT})
    target_link_libraries(gis_${name} PUBLIC ${ARG_DEPS} PRIVATE gis_warnings gis_sanitize ${ARG_PRIVATE_DEPS})
    target_link_libraries(gis_${name} INTERFACE gis_sanitize)
endfunction()

# gis_add_executable(NAME SOURCES ... DEPS ...)
function(gis_add_executable name)
    cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
    add_executable(${name} ${ARG_SOURCES})
    target_link_libraries(${name} PRIVATE ${ARG_DEPS} gis_warnings gis_sanitize)
    set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin)
endfunction()

# gis_embed_files(TARGET NAME BASE GLOBS ...): compiles every file matching GLOBS (relative to BASE)
# into TARGET, reachable at run time as gis::embedded::NAME() (core/EmbeddedFiles.h). Shaders and
# protocol schemas ship inside the binaries this way; GI_SHADER_DIR can still override at run time.
function(gis_embed_files target name base)
    set(_globs ${ARGN})
    list(TRANSFORM _globs PREPEND "${base}/")
    file(GLOB_RECURSE _files CONFIGURE_DEPENDS ${_globs})
    list(SORT _files)
    set(_list "${CMAKE_CURRENT_BINARY_DIR}/${name}.files")
    string(REPLACE ";" "\n" _lines "${_files}")
    file(WRITE "${_list}.tmp" "${_lines}\n")
    file(COPY_FILE "${_list}.tmp" "${_list}" ONLY_IF_DIFFERENT)
    set(_out "${CMAKE_CURRENT_BINARY_DIR}/${name}.cpp")
    add_custom_command(OUTPUT "${_out}"
        COMMAND ${CMAKE_COMMAND} -DOUT=${_out} -DNAME=${name} -DBASE=${base} -DLIST=${_list}
                -P ${GIS_SOURCE_ROOT}/cmake/EmbedFiles.cmake
        DEPENDS ${_files} "${_list}" ${GIS_SOURCE_ROOT}/cmake/EmbedFiles.cmake
        COMMENT "Embedding ${name}")
    target_sources(${target} PRIVATE "${_out}")
endfunction()
