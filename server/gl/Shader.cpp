#include "gl/Shader.h"

#include <cstdlib>
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

GLuint compileStage(const ShaderStage& stage,
                    const std::vector<std::pair<std::string, std::string>>& defines) {
    ExpandedSource src = expandShader(stage.path, defines);
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

Program Program::build(const std::vector<ShaderStage>& stages,
                       const std::vector<std::pair<std::string, std::string>>& defines,
                       const std::vector<std::string>& feedbackVaryings) {
    GLuint program = glCreateProgram();
    std::vector<GLuint> shaders;
    try {
        for (const auto& stage : stages) {
            shaders.push_back(compileStage(stage, defines));
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
    return Program(program);
}

} // namespace gis::gl
