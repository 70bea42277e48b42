# Generates our OpenGL entry-point loader from the system's GL/glcorearb.h (libgl-dev): one function
# pointer per GLAPI entry, with macros so code calls glFoo as usual. The binary links no libGL, so
# the same code runs under EGL (eglGetProcAddress) and OSMesa (OSMesaGetProcAddress); core functions
# up to GL 4.5 are marked required and checked at load time.
# Usage: gis_generate_gl_loader(<header path> <output dir>)
function(gis_generate_gl_loader header outdir)
    file(STRINGS "${header}" _lines REGEX "^(#ifndef GL_[A-Za-z0-9_]+$|GLAPI .*APIENTRY gl[A-Za-z0-9_]+ \\()")
    set(_section "")
    set(_decl "")
    set(_def "")
    set(_table "")
    set(_count 0)
    foreach(_line IN LISTS _lines)
        if(_line MATCHES "^#ifndef (GL_[A-Za-z0-9_]+)$")
            set(_section "${CMAKE_MATCH_1}")
            continue()
        endif()
        string(REGEX MATCH "APIENTRY (gl[A-Za-z0-9_]+) \\(" _m "${_line}")
        set(_name "${CMAKE_MATCH_1}")
        string(TOUPPER "${_name}" _upper)
        set(_pfn "PFN${_upper}PROC")
        set(_required 0)
        if(_section MATCHES "^GL_VERSION_([0-9])_([0-9])$")
            math(EXPR _ver "${CMAKE_MATCH_1} * 10 + ${CMAKE_MATCH_2}")
            if(_ver LESS_EQUAL 45)
                set(_required 1)
            endif()
        endif()
        string(APPEND _decl "extern ${_pfn} gis_${_name};\n#define ${_name} gis_${_name}\n")
        string(APPEND _def "${_pfn} gis_${_name} = nullptr;\n")
        string(APPEND _table "    {\"${_name}\", reinterpret_cast<GlProc*>(&gis_${_name}), ${_required}},\n")
        math(EXPR _count "${_count} + 1")
    endforeach()
    file(WRITE "${outdir}/gl/GlApi.h.tmp"
"// Generated from ${header} by cmake/GenGlLoader.cmake: do not edit.
#pragma once
#include <GL/glcorearb.h>

namespace gis::gl {
using GlProc = void (*)();
using GetProcFn = GlProc (*)(const char* name);
struct GlEntry { const char* name; GlProc* slot; int requiredCore45; };
/// Fills every entry point through getProc. Returns the names of required (core <= 4.5) entry points
/// that came back null, comma-separated; empty on success.
const char* loadGlEntryPoints(GetProcFn getProc);
int glEntryPointCount();
} // namespace gis::gl

extern \"C++\" {
${_decl}}
")
    file(WRITE "${outdir}/gl/GlApi.cpp.tmp"
"// Generated from ${header} by cmake/GenGlLoader.cmake: do not edit.
#include \"gl/GlApi.h\"
#include <string>

${_def}
namespace gis::gl {
namespace {
GlEntry kEntries[] = {
${_table}};
std::string gMissing;
} // namespace

const char* loadGlEntryPoints(GetProcFn getProc) {
    gMissing.clear();
    for (auto& e : kEntries) {
        *e.slot = getProc(e.name);
        if (!*e.slot && e.requiredCore45) gMissing += (gMissing.empty() ? \"\" : \", \") + std::string(e.name);
    }
    return gMissing.c_str();
}
int glEntryPointCount() { return ${_count}; }
} // namespace gis::gl
")
    file(COPY_FILE "${outdir}/gl/GlApi.h.tmp" "${outdir}/gl/GlApi.h" ONLY_IF_DIFFERENT)
    file(COPY_FILE "${outdir}/gl/GlApi.cpp.tmp" "${outdir}/gl/GlApi.cpp" ONLY_IF_DIFFERENT)
endfunction()
