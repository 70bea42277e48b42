// Builds a test's compute probe from GLSL source that #includes the shipped shader files: the source
// is written to a temporary GI_SHADER_DIR (includes the directory lacks fall back to the copies
// embedded in the binary), so a probe always tests the real functions. Shared by the GL tests and
// the stability harness. Needs a current GL context.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "gl/Shader.h"

namespace gis::test {

/// Compiles `source` as the compute shader `probe/<name>.comp`; GI_SHADER_DIR is restored after.
inline gl::Program buildComputeProbe(const std::string& name, const std::string& source) {
    const auto dir =
        std::filesystem::temp_directory_path() / ("gis_probe_" + name + "_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir / "probe");
    std::ofstream(dir / "probe" / (name + ".comp")) << source;
    const char* previous = std::getenv("GI_SHADER_DIR");
    const std::string saved = previous ? previous : "";
    ::setenv("GI_SHADER_DIR", dir.c_str(), 1);
    auto restore = [&] {
        if (previous)
            ::setenv("GI_SHADER_DIR", saved.c_str(), 1);
        else
            ::unsetenv("GI_SHADER_DIR");
        std::filesystem::remove_all(dir);
    };
    gl::Program program;
    try {
        program = gl::Program::build({{GL_COMPUTE_SHADER, "probe/" + name + ".comp"}});
    } catch (...) {
        restore();
        throw;
    }
    restore();
    return program;
}

} // namespace gis::test
