// Shader programs built from files under shaders/. Sources come from the copy embedded in the
// binary, or from the directory named by GI_SHADER_DIR (edit-and-reload during development).
// `#include "path"` (relative to shaders/) is resolved here, once per file, with `#line` so that
// compile errors are reported as shaders/<file>:<line>.
#pragma once

#include <set>
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
/// The texture unit of a sampler uniform, from its `layout(binding = N)` (Program::textureUnit).
struct TextureUnit {
    GLuint unit = 0;
};
/// A TextureUnit for a sampler the program does not use: binding to it is skipped by gl::Pass.
inline constexpr GLuint kNoUnit = ~0u;
/// The image unit of an image uniform, from its `layout(binding = N)` (Program::imageUnit).
struct ImageUnit {
    GLuint unit = 0;
};
/// The binding point of a shader storage or uniform block, from its `layout(binding = N)`
/// (Program::storageBlock, Program::uniformBlock).
struct BlockBinding {
    GLenum target = GL_SHADER_STORAGE_BUFFER;
    GLuint index = 0;
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

    /// The active uniform `name` (not in a block), checked against what the linker kept: a missing or
    /// misspelt name throws gis::Error naming the program's files, where the program is built, so a
    /// typo never turns into a silent -1 at draw time.
    UniformLocation location(std::string_view name) const;
    /// The unit of the active sampler uniform `name`; throws like location().
    TextureUnit textureUnit(std::string_view name) const;
    /// The unit of the active image uniform `name`; throws like location().
    ImageUnit imageUnit(std::string_view name) const;
    /// The binding of the active shader storage block `name` (the block's name, not its instance's).
    BlockBinding storageBlock(std::string_view name) const;
    /// The binding of the active uniform block `name`.
    BlockBinding uniformBlock(std::string_view name) const;
    /// storageBlock(), or a binding gl::Pass skips (index kNoUnit) when the program does not use the
    /// block (a define compiled out its reads).
    BlockBinding optionalStorageBlock(std::string_view name) const;
    /// Whether the linked program has the active uniform `name` (a define may compile one out).
    bool has(std::string_view name) const;
    /// location(), or location -1 (which glUniform* ignores) when the program does not use `name`:
    /// for uniforms of a shared include that some programs leave unused. `name` must still be
    /// declared by one of the program's sources (else it throws: a misspelling).
    UniformLocation optionalLocation(std::string_view name) const;
    /// Whether one of the program's sources declares the plain uniform `name` (used or not).
    bool declares(std::string_view name) const { return mDeclared.count(std::string(name)) > 0; }
    /// textureUnit(), or kNoUnit when the program does not use the declared sampler `name`.
    TextureUnit optionalTextureUnit(std::string_view name) const;

private:
    struct Active {
        std::string name;
        GLint location = -1;
        GLenum type = 0;
        GLint unit = -1; ///< samplers and images: the binding
    };
    struct Block {
        std::string name;
        BlockBinding binding;
    };
    explicit Program(GLuint id, std::vector<Active> active, std::vector<Block> blocks,
                     std::set<std::string> declared, std::string label)
        : Object(id), mActive(std::move(active)), mBlocks(std::move(blocks)), mDeclared(std::move(declared)),
          mLabel(std::move(label)) {}
    static std::vector<Active> activeUniforms(GLuint program);
    static std::vector<Block> activeBlocks(GLuint program);
    const Active* find(std::string_view name) const;
    BlockBinding block(std::string_view name, GLenum target) const;
    std::vector<Active> mActive; ///< read from the linked program once
    std::vector<Block> mBlocks;
    std::set<std::string> mDeclared; ///< plain uniforms the sources declare (optionalLocation)
    std::string mLabel;              ///< " shaders/a.vert shaders/b.frag" for errors
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
