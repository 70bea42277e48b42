// Shader programs built from files under shaders/. Sources come from the copy embedded in the
// binary, or from the directory named by GI_SHADER_DIR (edit-and-reload during development).
// `#include "path"` (relative to shaders/) is resolved here, once per file, with `#line` so that
// compile errors are reported as shaders/<file>:<line>.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "gl/Objects.h"

namespace gis::gl {

struct ShaderStage {
    GLenum type;      ///< GL_VERTEX_SHADER, GL_GEOMETRY_SHADER, GL_FRAGMENT_SHADER, GL_COMPUTE_SHADER
    std::string path; ///< relative to shaders/, e.g. "render/fullscreen.vert"
};

class Program : public Object<ProgramTraits> {
public:
    Program() = default;
    /// Compiles and links; `defines` become `#define NAME VALUE` lines after #version;
    /// `feedbackVaryings` are captured interleaved by transform feedback ("gl_NextBuffer" starts
    /// the next buffer). Throws gis::Error with file:line diagnostics.
    static Program build(const std::vector<ShaderStage>& stages,
                         const std::vector<std::pair<std::string, std::string>>& defines = {},
                         const std::vector<std::string>& feedbackVaryings = {});
    GLint uniform(const char* name) const { return glGetUniformLocation(id(), name); }

private:
    using Object::Object;
};

/// The fully expanded source of one stage, and the file table its #line numbers refer to.
struct ExpandedSource {
    std::string text;
    std::vector<std::string> files; ///< index = the source-string number used in #line
};

/// Reads a file under shaders/ (GI_SHADER_DIR first, then the embedded copy); throws if missing.
std::string readShaderFile(const std::string& path);
ExpandedSource expandShader(const std::string& path,
                            const std::vector<std::pair<std::string, std::string>>& defines);
/// Rewrites driver messages "N:LINE(COL)" into "shaders/<file>:LINE(COL)".
std::string mapShaderLog(const std::string& log, const std::vector<std::string>& files);

} // namespace gis::gl
