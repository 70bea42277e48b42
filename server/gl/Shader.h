// Shader programs built from files under shaders/. Sources come from the copy embedded in the
// binary, or from the directory named by GI_SHADER_DIR (edit-and-reload during development).
// `#include "path"` (relative to shaders/) is resolved here, once per file, with `#line` so that
// compile errors are reported as shaders/<file>:<line>.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gl/Objects.h"

namespace gis::gl {

/// A plain uniform of a linked program, resolved once (Program::location): setting it needs no lookup.
struct UniformLocation {
    GLint location = -1;
};
/// The texture unit of a sampler or image uniform, from its `layout(binding = N)` (Program::textureUnit).
struct TextureUnit {
    GLuint unit = 0;
};

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

    /// The active uniform `name` (not in a block), checked against what the linker kept: a missing or
    /// misspelt name throws gis::Error naming the program's files, where the program is built, so a
    /// typo never turns into a silent -1 at draw time.
    UniformLocation location(std::string_view name) const;
    /// The unit of the active sampler or image uniform `name`; throws like location().
    TextureUnit textureUnit(std::string_view name) const;
    /// Whether the linked program has the active uniform `name` (a define may compile one out).
    bool has(std::string_view name) const;
    /// location(), or location -1 (which glUniform* ignores) when the program does not use `name`:
    /// for uniforms of a shared include that some programs leave unused.
    UniformLocation optionalLocation(std::string_view name) const;

private:
    struct Active {
        std::string name;
        GLint location = -1;
        GLenum type = 0;
        GLint unit = -1; ///< samplers and images: the binding
    };
    explicit Program(GLuint id, std::vector<Active> active, std::string label)
        : Object(id), mActive(std::move(active)), mLabel(std::move(label)) {}
    static std::vector<Active> activeUniforms(GLuint program);
    const Active* find(std::string_view name) const;
    std::vector<Active> mActive; ///< read from the linked program once
    std::string mLabel;          ///< " shaders/a.vert shaders/b.frag" for errors
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
