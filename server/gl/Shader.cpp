#include "gl/Shader.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "core/EmbeddedFiles.h"
#include "core/Error.h"

namespace gis::gl {

std::string readShaderFile(const std::string& path) {
    if (const char* dir = std::getenv("GI_SHADER_DIR"); dir && *dir) {
        std::ifstream in(std::string(dir) + "/" + path, std::ios::binary);
        if (in) {
            std::ostringstream s;
            s << in.rdbuf();
            return s.str();
        }
    }
    if (auto embedded = findEmbedded(embedded::shaders(), path)) return std::string(*embedded);
    throw Error("gl: shader file 'shaders/" + path + "' not found");
}

namespace {

void expandInto(const std::string& path, ExpandedSource& out, std::set<std::string>& included,
                std::ostringstream& text, bool isRoot,
                const std::vector<std::pair<std::string, std::string>>& defines) {
    const int fileIndex = static_cast<int>(out.files.size());
    out.files.push_back(path);
    std::istringstream in(readShaderFile(path));
    static const std::regex includeRe(R"(^\s*#\s*include\s+\"([^\"]+)\"\s*$)");
    static const std::regex pragmaOnceRe(R"(^\s*#\s*pragma\s+once\s*$)");
    std::string line;
    int lineNo = 0;
    bool versionSeen = !isRoot;
    if (!isRoot) text << "#line 1 " << fileIndex << "\n";
    while (std::getline(in, line)) {
        ++lineNo;
        std::smatch m;
        if (!versionSeen && line.rfind("#version", 0) == 0) {
            versionSeen = true;
            text << line << "\n";
            for (const auto& [name, value] : defines) text << "#define " << name << " " << value << "\n";
            text << "#line " << lineNo + 1 << " " << fileIndex << "\n";
            continue;
        }
        if (std::regex_match(line, m, includeRe)) {
            std::string inc = m[1];
            if (included.insert(inc).second) expandInto(inc, out, included, text, false, defines);
            text << "#line " << lineNo + 1 << " " << fileIndex << "\n";
            continue;
        }
        if (std::regex_match(line, pragmaOnceRe)) {
            text << "\n";
            continue;
        }
        text << line << "\n";
    }
    if (isRoot && !versionSeen) throw Error("gl: shader 'shaders/" + path + "' has no #version line");
}

// The names of plain uniforms the source declares (before preprocessing, so a declaration inside an
// #if counts): optionalLocation refuses names no stage declares, which catches misspellings of
// uniforms that a define or the linker may legitimately remove.
void collectDeclaredUniforms(const std::string& text, std::set<std::string>& out) {
    static const std::regex declRe(
        R"(\buniform\s+(?:(?:readonly|writeonly|coherent|restrict|volatile|highp|mediump|lowp)\s+)*\w+\s+(\w+)\s*[;\[=])");
    for (auto it = std::sregex_iterator(text.begin(), text.end(), declRe); it != std::sregex_iterator(); ++it)
        out.insert((*it)[1].str());
}

GLuint compileStage(const ShaderStage& stage, const std::vector<std::pair<std::string, std::string>>& defines,
                    std::set<std::string>& declared) {
    ExpandedSource src = expandShader(stage.path, defines);
    collectDeclaredUniforms(src.text, declared);
    GLuint shader = glCreateShader(stage.type);
    const char* text = src.text.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &len);
        std::string log(static_cast<size_t>(std::max(len, 1)), '\0');
        glGetShaderInfoLog(shader, len, nullptr, log.data());
        glDeleteShader(shader);
        throw Error("gl: failed to compile shaders/" + stage.path + ":\n" + mapShaderLog(log, src.files));
    }
    return shader;
}

} // namespace

ExpandedSource expandShader(const std::string& path,
                            const std::vector<std::pair<std::string, std::string>>& defines) {
    ExpandedSource out;
    std::set<std::string> included;
    std::ostringstream text;
    expandInto(path, out, included, text, true, defines);
    out.text = text.str();
    return out;
}

std::string mapShaderLog(const std::string& log, const std::vector<std::string>& files) {
    static const std::regex locRe(R"((^|\n)(\d+):(\d+)\((\d+)\))");
    std::string out;
    auto begin = log.cbegin();
    std::smatch m;
    while (std::regex_search(begin, log.cend(), m, locRe)) {
        out.append(begin, m[0].first);
        size_t index = std::stoul(m[2]);
        std::string file = index < files.size() ? "shaders/" + files[index] : "source " + m[2].str();
        out += m[1].str() + file + ":" + m[3].str() + "(" + m[4].str() + ")";
        begin = m[0].second;
    }
    out.append(begin, log.cend());
    return out;
}

namespace {

bool isImage(GLenum type) {
    switch (type) {
    case GL_IMAGE_2D:
    case GL_IMAGE_2D_ARRAY:
    case GL_IMAGE_3D:
    case GL_IMAGE_CUBE:
    case GL_INT_IMAGE_2D:
    case GL_UNSIGNED_INT_IMAGE_2D:
    case GL_IMAGE_BUFFER:
        return true;
    default:
        return false;
    }
}

bool isSamplerOrImage(GLenum type) {
    switch (type) {
    case GL_SAMPLER_1D:
    case GL_SAMPLER_2D:
    case GL_SAMPLER_3D:
    case GL_SAMPLER_CUBE:
    case GL_SAMPLER_2D_SHADOW:
    case GL_SAMPLER_2D_ARRAY:
    case GL_SAMPLER_2D_ARRAY_SHADOW:
    case GL_SAMPLER_CUBE_SHADOW:
    case GL_SAMPLER_CUBE_MAP_ARRAY:
    case GL_SAMPLER_BUFFER:
    case GL_INT_SAMPLER_2D:
    case GL_UNSIGNED_INT_SAMPLER_2D:
    case GL_INT_SAMPLER_BUFFER:
    case GL_UNSIGNED_INT_SAMPLER_BUFFER:
    case GL_IMAGE_2D:
    case GL_IMAGE_2D_ARRAY:
    case GL_IMAGE_3D:
    case GL_IMAGE_CUBE:
    case GL_INT_IMAGE_2D:
    case GL_UNSIGNED_INT_IMAGE_2D:
    case GL_IMAGE_BUFFER:
        return true;
    default:
        return false;
    }
}

} // namespace

std::vector<Program::Active> Program::activeUniforms(GLuint program) {
    std::vector<Active> out;
    GLint count = 0;
    glGetProgramInterfaceiv(program, GL_UNIFORM, GL_ACTIVE_RESOURCES, &count);
    const GLenum props[] = {GL_NAME_LENGTH, GL_TYPE, GL_LOCATION, GL_BLOCK_INDEX};
    for (GLint i = 0; i < count; ++i) {
        GLint values[4] = {};
        glGetProgramResourceiv(program, GL_UNIFORM, static_cast<GLuint>(i), 4, props, 4, nullptr, values);
        if (values[3] != -1) continue; // a member of a uniform block: set through the block
        std::string name(static_cast<std::size_t>(std::max(values[0], 1)), '\0');
        glGetProgramResourceName(program, GL_UNIFORM, static_cast<GLuint>(i), values[0], nullptr,
                                 name.data());
        name.resize(std::strlen(name.c_str()));
        if (name.size() > 3 && name.compare(name.size() - 3, 3, "[0]") == 0) name.resize(name.size() - 3);
        Active a{name, values[2], static_cast<GLenum>(values[1]), -1};
        if (isSamplerOrImage(a.type) && a.location >= 0) glGetUniformiv(program, a.location, &a.unit);
        out.push_back(std::move(a));
    }
    return out;
}

std::vector<Program::Block> Program::activeBlocks(GLuint program) {
    std::vector<Block> out;
    for (GLenum iface : {GL_SHADER_STORAGE_BLOCK, GL_UNIFORM_BLOCK}) {
        GLint count = 0;
        glGetProgramInterfaceiv(program, iface, GL_ACTIVE_RESOURCES, &count);
        const GLenum props[] = {GL_NAME_LENGTH, GL_BUFFER_BINDING};
        for (GLint i = 0; i < count; ++i) {
            GLint values[2] = {};
            glGetProgramResourceiv(program, iface, static_cast<GLuint>(i), 2, props, 2, nullptr, values);
            std::string name(static_cast<std::size_t>(std::max(values[0], 1)), '\0');
            glGetProgramResourceName(program, iface, static_cast<GLuint>(i), values[0], nullptr, name.data());
            name.resize(std::strlen(name.c_str()));
            const GLenum target =
                iface == GL_SHADER_STORAGE_BLOCK ? GL_SHADER_STORAGE_BUFFER : GL_UNIFORM_BUFFER;
            out.push_back({name, {target, static_cast<GLuint>(std::max(values[1], 0))}});
        }
    }
    return out;
}

Program Program::build(const std::vector<ShaderStage>& stages,
                       const std::vector<std::pair<std::string, std::string>>& defines,
                       const std::vector<std::string>& feedbackVaryings) {
    GLuint program = glCreateProgram();
    std::vector<GLuint> shaders;
    std::set<std::string> declared;
    try {
        for (const auto& stage : stages) {
            shaders.push_back(compileStage(stage, defines, declared));
            glAttachShader(program, shaders.back());
        }
    } catch (...) {
        for (GLuint s : shaders) glDeleteShader(s);
        glDeleteProgram(program);
        throw;
    }
    if (!feedbackVaryings.empty()) {
        std::vector<const char*> names;
        for (const auto& v : feedbackVaryings) names.push_back(v.c_str());
        glTransformFeedbackVaryings(program, static_cast<GLsizei>(names.size()), names.data(),
                                    GL_INTERLEAVED_ATTRIBS);
    }
    glLinkProgram(program);
    for (GLuint s : shaders) glDeleteShader(s);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetProgramiv(program, GL_INFO_LOG_LENGTH, &len);
        std::string log(static_cast<size_t>(std::max(len, 1)), '\0');
        glGetProgramInfoLog(program, len, nullptr, log.data());
        glDeleteProgram(program);
        std::string names;
        for (const auto& s : stages) names += " shaders/" + s.path;
        throw Error("gl: failed to link" + names + ":\n" + log);
    }
    std::string label;
    for (const auto& s : stages) label += " shaders/" + s.path;
    return Program(program, activeUniforms(program), activeBlocks(program), std::move(declared), label);
}

const Program::Active* Program::find(std::string_view name) const {
    for (const Active& a : mActive)
        if (a.name == name) return &a;
    return nullptr;
}

bool Program::has(std::string_view name) const {
    return find(name) != nullptr;
}

UniformLocation Program::optionalLocation(std::string_view name) const {
    if (!mDeclared.count(std::string(name)))
        throw Error("gl: no stage of" + mLabel + " declares the uniform '" + std::string(name) +
                    "' (misspelt?)");
    const Active* a = find(name);
    return {a ? a->location : -1};
}

TextureUnit Program::optionalTextureUnit(std::string_view name) const {
    if (!mDeclared.count(std::string(name)))
        throw Error("gl: no stage of" + mLabel + " declares the sampler '" + std::string(name) +
                    "' (misspelt?)");
    const Active* a = find(name);
    return {a && a->unit >= 0 && !isImage(a->type) ? static_cast<GLuint>(a->unit) : kNoUnit};
}

UniformLocation Program::location(std::string_view name) const {
    const Active* a = find(name);
    if (!a || a->location < 0)
        throw Error("gl: the program of" + mLabel + " has no active uniform '" + std::string(name) +
                    "' (misspelt, or unused in the shader and removed by the linker)");
    return {a->location};
}

TextureUnit Program::textureUnit(std::string_view name) const {
    const Active* a = find(name);
    if (!a || a->unit < 0 || isImage(a->type))
        throw Error("gl: the program of" + mLabel + " has no active sampler '" + std::string(name) + "'");
    return {static_cast<GLuint>(a->unit)};
}

ImageUnit Program::imageUnit(std::string_view name) const {
    const Active* a = find(name);
    if (!a || a->unit < 0 || !isImage(a->type))
        throw Error("gl: the program of" + mLabel + " has no active image '" + std::string(name) + "'");
    return {static_cast<GLuint>(a->unit)};
}

BlockBinding Program::block(std::string_view name, GLenum target) const {
    for (const Block& b : mBlocks)
        if (b.name == name && b.binding.target == target) return b.binding;
    throw Error("gl: the program of" + mLabel + " has no active " +
                (target == GL_SHADER_STORAGE_BUFFER ? "storage" : "uniform") + " block '" +
                std::string(name) + "'");
}

BlockBinding Program::storageBlock(std::string_view name) const {
    return block(name, GL_SHADER_STORAGE_BUFFER);
}

BlockBinding Program::optionalStorageBlock(std::string_view name) const {
    for (const Block& b : mBlocks)
        if (b.name == name && b.binding.target == GL_SHADER_STORAGE_BUFFER) return b.binding;
    return {GL_SHADER_STORAGE_BUFFER, kNoUnit};
}

BlockBinding Program::uniformBlock(std::string_view name) const {
    return block(name, GL_UNIFORM_BUFFER);
}

} // namespace gis::gl
